"""Metrics of sampled loops and signals, knowing nothing of runs or rigs: a loop's branches, the slope
of its centre line, its width and area, an RMS error, a relaxation, a dynamic stiffness."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from elastokin.bushings.frequency import harmonic_ratio

_EPS_S = 1e-9   #: times closer than this are the same instant (the recording's 1 ns stamps)


@dataclass(frozen=True)
class Branches:
    """A measured output against its input on the unloading (down) and loading (up) legs."""

    x_down: np.ndarray
    y_down: np.ndarray
    x_up: np.ndarray
    y_up: np.ndarray

    def on(self, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(down, up) values interpolated at ``grid`` (increasing)."""
        d, u = np.argsort(self.x_down), np.argsort(self.x_up)
        return np.interp(grid, self.x_down[d], self.y_down[d]), np.interp(grid, self.x_up[u], self.y_up[u])


def centre_slope(b: Branches, window: float) -> float:
    """Least-squares slope of the centre line (mean of the branches) over ±``window``."""
    grid = np.linspace(-window, window, 41)
    down, up = b.on(grid)
    return float(np.polyfit(grid, 0.5 * (down + up), 1)[0])


def loop_width(b: Branches, window: float) -> tuple[float, float]:
    """(width at design, largest width over ±``window``) of a loop."""
    grid = np.linspace(-window, window, 41)
    down, up = b.on(grid)
    width = np.abs(down - up)
    return float(np.interp(0.0, grid, width)), float(width.max())


def loop_area(x: np.ndarray, y: np.ndarray) -> float:
    """∮ y dx over the closed polygon of the samples (last joined to first) [y unit · x unit].

    Positive for a loop run clockwise in the (x, y) plane, where y leads x: for a force against
    its displacement, the energy dissipated per cycle.
    """
    xc, yc = np.append(x, x[:1]), np.append(y, y[:1])
    return float(np.sum(0.5 * (yc[1:] + yc[:-1]) * np.diff(xc)))


def rms_error(a: np.ndarray, b: np.ndarray) -> float:
    """Root-mean-square of ``a − b`` over samples on the same time base [their unit]."""
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2)))


def relaxation_amplitude(t_s: np.ndarray, y: np.ndarray, hold_from_s: float) -> float:
    """y(last sample) − y(first sample at or after ``hold_from_s`` [s]) [y unit]: how far y moves
    while its input is held, e.g. the toe drift after a rack step as the bushings relax."""
    held = y[t_s >= hold_from_s - _EPS_S]
    return float(held[-1] - held[0])


def dynamic_stiffness(t_s: np.ndarray, force: np.ndarray, displacement: np.ndarray, frequency_hz: float) -> complex:
    """First-harmonic ratio K* = F1/X1 over the last period (ending at the last sample) of a
    sine at ``frequency_hz`` [force unit / displacement unit, complex; |K*| the dynamic stiffness,
    Im/Re the loss factor tan δ]. The signals are resampled linearly onto a uniform grid of that
    period (the same filter on both, so their ratio keeps); ValueError if they span less than one.
    """
    period = 1.0 / frequency_hz
    step = float(np.median(np.diff(t_s)))
    start = t_s[-1] - period
    if start < t_s[0] - 0.5 * step:
        raise ValueError(f"{t_s[-1] - t_s[0]:.6g} s of samples; a first harmonic at {frequency_hz:g} Hz needs "
                         f"one period, {period:.6g} s")
    n = max(16, int(round(period / step)))
    grid = start + period * np.arange(n) / n
    return complex(harmonic_ratio(np.interp(grid, t_s, displacement), np.interp(grid, t_s, force), n))


def common_range(b: Branches) -> float:
    """Half-width of the x range that both branches cover on each side of 0 [x unit]."""
    return float(min(b.x_down.max(), b.x_up.max(), -b.x_down.min(), -b.x_up.min()))
