"""The response of a K&C rig's acquisition paths to what they measure, a nuisance the diagnosis
estimates beside the causes (issue 53 item 2). Written from what a rig is known to do, apart from
the virtual rig's own chain (:mod:`elastokin.diagnosis.rig_chain`, the truth side):

- the rig inputs (pad travel and forces, rack) are the time base: the simulation is driven by the
  recorded inputs' scenario (a servo's tracking is checked on import);
- the channels of one acquisition path (:data:`PATHS`: the wheel-position heads' angles, wheel
  travel and wheel-centre positions; the pads' load cells and heights; each wheel alike) pass one
  anti-alias low-pass filter and one delay (buffering, a sensor head's processing). The filter is
  taken as the commonest, a 2nd-order Butterworth, in continuous time (the analogue filter before
  the sampling) discretised exactly for a signal linear between samples; its cut-off is fitted,
  or no filter.

The prediction passes the paths' response before it is compared (linear in the prediction, so a
hypothesis's effect stays proportional to its magnitude in the fits). The response is estimated
on the baseline; what is left of it to first order (a delay, a filter of another shape: the
baseline's response shifted by a sample or two, :data:`TAPS`) is projected out of every residual,
so that each cause is fitted jointly with the path's response, as the zero errors are.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy import signal as sps
from scipy.linalg import expm

from elastokin.diagnosis.kc_layout import Layout
from elastokin.vehicle.scenarios.channels import channel_quantity

#: Acquisition paths: channels (without their wheel) that share a filter and a delay.
PATHS = {"wheel sensors": ("wheel_travel", "camber", "toe", "half_track", "steer", "wheel_centre_x",
                           "wheel_centre_y", "wheel_centre_z"),
         "pad sensors": ("pad_height", "pad_fz")}
#: Cut-offs [Hz] tried for a path's filter (0: none), each then refined between its neighbours;
#: those at or above 0.45 × the highest sampling rate are not tried (the filter would be its own aliasing).
CUTOFFS_HZ = (0.0, 40.0, 25.0, 18.0, 13.0, 10.0, 8.0, 6.0, 4.5, 3.0)
#: Golden-section steps refining a cut-off (on its logarithm), and Gauss-Newton steps of a delay.
REFINE_STEPS, DELAY_STEPS = 10, 4
#: Delays beyond this [s] are not a rig's acquisition: the estimate is held within ± it.
MAX_DELAY_S = 0.25
#: The samples by which a path's response, shifted, spans what a filter of another shape than the
#: one fitted leaves (any linear filter's difference within ± two samples, to first order).
TAPS = (-2, -1, 1, 2)


@dataclass(frozen=True)
class PathResponse:
    """One acquisition path's response as fitted beside a model."""

    path: str
    channels: tuple[str, ...]
    cutoff_hz: float     #: its low-pass filter's cut-off [Hz]; 0: none found
    delay_s: float       #: its delay after the filter [s]
    std_s: float         #: the delay's standard uncertainty [s]

    @property
    def lag_s(self) -> float:
        """The whole lag at low frequency [s]: the filter's, √2/(2π f_c), and the delay."""
        return self.delay_s + (math.sqrt(2.0) / (2.0 * math.pi * self.cutoff_hz) if self.cutoff_hz else 0.0)


def paths(channels: list[str]) -> dict[str, np.ndarray]:
    """The compared ``channels``' indices per acquisition path that has any (:data:`PATHS`)."""
    out = {name: np.array([i for i, c in enumerate(channels) if channel_quantity(c) in members], dtype=int)
           for name, members in PATHS.items()}
    return {name: idx for name, idx in out.items() if idx.size}


@functools.lru_cache(maxsize=256)
def _butterworth(cutoff_hz: float, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The 2nd-order Butterworth low-pass at ``cutoff_hz``, discretised at step ``dt`` [s] for an
    input linear between samples (its ramp lag √2/(2π f_c) exact): x' = A x + B u over a step with
    u linear is x⁺ = Φ x + Γ₁ u + Γ₂ (u⁺ − u), from the exponential of one block matrix. Returns
    its numerator, denominator and the initial state of a unit input at rest."""
    w = 2.0 * math.pi * cutoff_hz
    a = np.array([[0.0, 1.0], [-w * w, -math.sqrt(2.0) * w]])
    m = np.zeros((4, 4))
    m[:2, :2], m[1, 2], m[2, 3] = a * dt, w * w * dt, 1.0
    e = expm(m)
    phi, g1, g2 = e[:2, :2], e[:2, 2], e[:2, 3]
    c = np.array([1.0, 0.0])
    # in the state ξ = x − Γ₂ u: ξ⁺ = Φ ξ + (Φ Γ₂ + Γ₁ − Γ₂) u, y = c ξ + c Γ₂ u
    b, den = sps.ss2tf(phi, (phi @ g2 + g1 - g2)[:, None], c[None, :], np.array([[c @ g2]]))
    b, den = np.ravel(b), np.ravel(den)
    return b, den, sps.lfilter_zi(b, den)


class Response:
    """Rows (N, C) of a layout as each path's filter and delay deliver them, test by test: filtered
    from rest at the test's first row, then late by the delay (a row before the test's first is
    the first: the car is at rest before the input starts); and their rates."""

    def __init__(self, layout: Layout, groups: dict[str, np.ndarray]):
        self.layout, self.groups = layout, groups
        self._spans = [slice(int(t.rows[0]), int(t.rows[-1]) + 1) for t in layout.tests]   # a test's rows follow
        self._times = [layout.input_time[span] for span in self._spans]
        #: each test's sampling interval [s] (0: a test of one sample)
        self.steps = [float(np.median(np.diff(t))) if t.size > 1 else 0.0 for t in self._times]
        self._reads: dict[tuple[int, float], tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

    def cutoffs(self) -> list[float]:
        """The cut-offs tried, for this layout's highest sampling rate (one analogue filter serves
        every test: a test sampled faster shows its shape)."""
        steps = [d for d in self.steps if d > 0.0]
        rate_hz = 1.0 / float(np.min(steps)) if steps else 0.0
        return [f for f in CUTOFFS_HZ if f < 0.45 * rate_hz] or [0.0]

    def _read(self, test: int, delay: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The rows a test's rows are read between ``delay`` [s] late, and the weight of the later."""
        key = (test, delay)
        if key not in self._reads:
            time = self._times[test]
            at = np.interp(time - delay, time, np.arange(time.size, dtype=float))
            lo = np.floor(at).astype(int)
            self._reads[key] = (lo, np.minimum(lo + 1, time.size - 1), (at - lo)[:, None])
        return self._reads[key]

    def apply(self, rows: np.ndarray, cutoffs_hz: np.ndarray, delays_s: np.ndarray) -> np.ndarray:
        """``rows`` through each path's filter (cut-off 0: none) and delay [s]."""
        out = rows.copy()
        for k, (span, dt) in enumerate(zip(self._spans, self.steps)):
            for idx, cutoff, delay in zip(self.groups.values(), cutoffs_hz, delays_s):
                block = rows[span, idx]
                if cutoff > 0.0 and dt > 0.0:
                    b, a, zi = _butterworth(float(cutoff), dt)
                    block, _ = sps.lfilter(b, a, block, axis=0, zi=zi[:, None] * block[0])
                if delay != 0.0:
                    lo, hi, w = self._read(k, float(delay))
                    block = (1.0 - w) * block[lo] + w * block[hi]
                out[span, idx] = block
        return out

    def taps(self, rows: np.ndarray) -> list[np.ndarray]:
        """Per tap k of :data:`TAPS`: ``rows`` k samples late (early for k < 0) within each test, the
        ends held, minus ``rows``."""
        out = []
        for k in TAPS:
            moved = np.empty_like(rows)
            for span in self._spans:
                x = rows[span]
                moved[span] = x[np.clip(np.arange(len(x)) - k, 0, len(x) - 1)]
            out.append(moved - rows)
        return out

    def rates(self, rows: np.ndarray) -> np.ndarray:
        """d(rows)/dt within each test [channel unit / s] (one-sided at a test's ends)."""
        out = np.zeros_like(rows)
        for span, dt, time in zip(self._spans, self.steps, self._times):
            if dt > 0.0:
                out[span] = np.gradient(rows[span], time, axis=0)
        return out


def fit_response(response: Response, measured: np.ndarray, baseline: np.ndarray,
                 zeroed: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Each path's cut-off [Hz] (0: none) and delay [s] through which ``baseline`` (N, C) fits
    ``measured`` best, ``zeroed`` making a residual what is compared (each recording's zero out, in
    noise units): the whole lag as a delay first (Gauss-Newton), then each cut-off of the grid with
    the delay that keeps that lag, refitted, the best refined between its neighbours (golden
    section on the cut-off's logarithm)."""
    n = len(response.groups)
    if n == 0:   # no channel of an acquisition path compared
        return np.zeros(0), np.zeros(0)

    def fitted(cutoffs: np.ndarray, delays: np.ndarray, steps: int) -> tuple[np.ndarray, np.ndarray]:
        """Each path's residual sum of squares through ``cutoffs``, and its delays from ``delays``
        after ``steps`` Gauss-Newton steps."""
        delays = delays.astype(float).copy()
        for _ in range(steps):
            now = response.apply(baseline, cutoffs, delays)
            r, rates = zeroed(measured - now), zeroed(response.rates(now))
            for g, idx in enumerate(response.groups.values()):
                dd = float(np.sum(rates[:, idx] ** 2))
                if dd > 0.0:   # the data x(t − delay − s) ≈ x(t − delay) − s·x'(t − delay)
                    step = float(np.sum(rates[:, idx] * r[:, idx])) / dd
                    delays[g] = np.clip(delays[g] - step, -MAX_DELAY_S, MAX_DELAY_S)
        r = zeroed(measured - response.apply(baseline, cutoffs, delays))
        return np.array([float(np.sum(r[:, idx] ** 2)) for idx in response.groups.values()]), delays

    _, total = fitted(np.zeros(n), np.zeros(n), 2 * DELAY_STEPS)

    def tried(cutoffs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lag = np.where(cutoffs > 0.0, math.sqrt(2.0) / (2.0 * math.pi * np.maximum(cutoffs, 1e-9)), 0.0)
        return fitted(cutoffs, total - lag, DELAY_STEPS)

    grid = response.cutoffs()   # 0 (none) first, then falling
    best = np.argmin([tried(np.full(n, f))[0] for f in grid], axis=0)   # per path, of the grid
    found = np.array([grid[k] > 0.0 for k in best])   # a filter, refined between its neighbours

    def bracket(k: int) -> tuple[float, float]:
        """log of the cut-offs around the k-th of the grid (beyond its ends: × or ÷ 1.5)."""
        if not grid[k]:
            return 0.0, 0.0
        below = grid[k + 1] if k + 1 < len(grid) else grid[k] / 1.5
        above = grid[k - 1] if grid[k - 1] > 0.0 else grid[k] * 1.5
        return math.log(below), math.log(above)

    lo, hi = (np.array(side) for side in zip(*(bracket(k) for k in best)))
    golden = (math.sqrt(5.0) - 1.0) / 2.0
    at = lambda x: np.where(found, np.exp(x), 0.0)
    for _ in range(REFINE_STEPS):
        a, b = hi - golden * (hi - lo), lo + golden * (hi - lo)
        lower = tried(at(a))[0] < tried(at(b))[0]
        hi, lo = np.where(lower, b, hi), np.where(lower, lo, a)
    cutoffs = at(0.5 * (lo + hi))
    return cutoffs, tried(cutoffs)[1]
