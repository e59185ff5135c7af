"""Bench displacement programmes (spec §5): the thesis's test signals, sampled for a bushing bank.

A programme mapping (from a bench YAML file, in mm and s) is validated and converted to SI once,
by :func:`parse_programme`. Time-series programmes become a :class:`TimeSeries` (time [s] and
deflection [m] on a uniform grid of step dt_s, starting at rest at e = 0); a frequency ``sweep``
becomes a :class:`Sweep` of (amplitude, frequency) pairs, each analysed by
:mod:`bushings.frequency`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from vsim_core.errors import InputError
from bushings.bench.records import read_csv_columns

MM = 1e-3  #: metres per millimetre
#: Fewest samples per period of the fastest sine component that a bench accepts.
MIN_SAMPLES_PER_PERIOD = 20


@dataclass(frozen=True)
class TimeSeries:
    """An imposed deflection history on a uniform time grid."""

    kind: str            #: programme type (triangle, sine, bisine, step, firtree, csv)
    t_s: np.ndarray      #: time [s], uniform step
    e_m: np.ndarray      #: deflection [m]


@dataclass(frozen=True)
class Sweep:
    """A grid of sine tests: every amplitude at every frequency (both sorted), each run until stabilised."""

    amplitudes_m: np.ndarray      #: sine amplitudes [m]
    frequencies_hz: np.ndarray    #: sine frequencies [Hz]
    cycles: int                   #: cycles simulated per pair (the last one is analysed)
    points_per_cycle: int         #: minimum time steps per cycle

    kind = "sweep"


def piecewise_linear(times_s: Sequence[float], values_m: Sequence[float], dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Sample the piecewise-linear path through (times_s, values_m) every dt_s from times_s[0] to
    the last waypoint (the last sample is clamped to the last value)."""
    times = np.asarray(times_s, dtype=float)
    n = math.ceil((times[-1] - times[0]) / dt_s - 1e-9)
    t = times[0] + dt_s * np.arange(n + 1)
    return t, np.interp(t, times, np.asarray(values_m, dtype=float))


def triangle(amplitude_m: float, speed_m_s: float, cycles: int, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Symmetric triangle 0 → +A → −A → 0 at constant speed, ``cycles`` times.

    Returns time [s] and deflection [m]; the period is 4·A/speed.
    """
    quarter = amplitude_m / speed_m_s
    times = [0.0] + [quarter * (4 * c + k) for c in range(cycles) for k in (1, 3, 4)]
    values = [0.0] + [amplitude_m, -amplitude_m, 0.0] * cycles
    return piecewise_linear(times, values, dt_s)


def multisine(amplitudes_m: Sequence[float], frequencies_hz: Sequence[float], duration_s: float,
              dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Sum of sines e = Σ A_k·sin(2π f_k t) over [0, duration_s]; returns time [s], deflection [m]."""
    t = dt_s * np.arange(math.ceil(duration_s / dt_s - 1e-9) + 1)
    e = sum(a * np.sin(2.0 * math.pi * f * t) for a, f in zip(amplitudes_m, frequencies_hz))
    return t, np.asarray(e, dtype=float)


def sine(amplitude_m: float, frequency_hz: float, cycles: int, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """e = A·sin(2π f t) for ``cycles`` periods; returns time [s] and deflection [m]."""
    return multisine([amplitude_m], [frequency_hz], cycles / frequency_hz, dt_s)


def step(height_m: float, rise_time_s: float, hold_s: float, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Relaxation step: a ramp from 0 to ``height_m`` over ``rise_time_s`` (at least one time step),
    then held for ``hold_s``; returns time [s] (0 at the start of the ramp) and deflection [m]."""
    rise = max(rise_time_s, dt_s)
    return piecewise_linear([0.0, rise, rise + hold_s], [0.0, height_m, height_m], dt_s)


def firtree(amplitude_m: float, speed_m_s: float, level_step_m: float, hold_s: float, cycles: int,
            dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """The thesis's "fir-tree" (sapin, épi) test (annex B): triangle cycles 0 → +A → −A → 0 at
    constant speed that stop for ``hold_s`` at every multiple of ``level_step_m`` (tips and zero
    crossings included, not the final return to 0). ``amplitude_m`` must be a whole multiple of
    ``level_step_m``. Returns time [s] and deflection [m]."""
    n = round(amplitude_m / level_step_m)
    levels = [*range(1, n + 1), *range(n - 1, -n - 1, -1), *range(-n + 1, 1)] * cycles
    travel = level_step_m / speed_m_s
    times, values, t = [0.0], [0.0], 0.0
    for i, level in enumerate(levels):
        t += travel
        times.append(t)
        values.append(level * level_step_m)
        if i < len(levels) - 1:
            t += hold_s
            times.append(t)
            values.append(level * level_step_m)
    return piecewise_linear(times, values, dt_s)


def read_csv_record(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Read a ``t_s,e_mm`` record (other columns ignored); returns time [s] and deflection [m].

    Raises InputError naming the file, line and column for a missing column, a non-number, a
    NaN, or a time that does not increase strictly.
    """
    cols = read_csv_columns(path, ("t_s", "e_mm"), min_rows=2)
    return cols["t_s"], cols["e_mm"] * MM


# Accepted keys per programme type and their defaults (None: optional without default).
_REQUIRED = object()
_KEYS: dict[str, dict[str, Any]] = {
    "triangle": {"amplitude_mm": _REQUIRED, "speed_mm_s": _REQUIRED, "cycles": 3},
    "sine": {"amplitude_mm": _REQUIRED, "frequency_hz": _REQUIRED, "cycles": 5},
    "bisine": {"components": _REQUIRED, "cycles": 3, "duration_s": None},
    "step": {"amplitude_mm": _REQUIRED, "rise_time_s": _REQUIRED, "hold_s": _REQUIRED},
    "firtree": {"amplitude_mm": 3.0, "speed_mm_s": 10.0, "step_mm": 1.0, "hold_s": 60.0, "cycles": 1},
    "sweep": {"amplitudes_mm": _REQUIRED, "frequencies_hz": _REQUIRED, "cycles": 5, "points_per_cycle": 400},
    "csv": {"path": _REQUIRED},
}
_UNSET = object()


class _Reader:
    """Typed access to a programme mapping; errors name the file and ``programme.<key>``."""

    def __init__(self, data: Mapping[str, Any], kind: str, source: str):
        self.data, self.kind, self.source = data, kind, source

    def fail(self, key: str, message: str) -> InputError:
        return InputError(message, source=self.source, key=f"programme.{key}")

    def number(self, key: str, *, positive: bool = True, nonzero: bool = True, integer: bool = False,
               value: Any = _UNSET) -> float:
        raw = self.data.get(key, _KEYS[self.kind][key]) if value is _UNSET else value
        if isinstance(raw, bool) or not isinstance(raw, (int, float)) or not math.isfinite(raw):
            raise self.fail(key, f"expected a finite number, got {raw!r}")
        if integer and raw != int(raw):
            raise self.fail(key, f"expected a whole number, got {raw!r}")
        if (positive and raw < 0) or (nonzero and raw == 0):
            raise self.fail(key, f"expected a {'positive' if positive else 'non-zero'} number, got {raw!r}")
        return float(raw)

    def numbers(self, key: str) -> np.ndarray:
        raw = self.data[key]
        if not isinstance(raw, list) or not raw:
            raise self.fail(key, f"expected a non-empty list of positive numbers, got {raw!r}")
        return np.array([self.number(key, value=v) for v in raw])


def parse_programme(data: Any, dt_s: float, source: str, base_dir: Path | None = None) -> TimeSeries | Sweep:
    """Validate a bench ``programme`` mapping (mm, s, Hz) and build it in SI, sampled at dt_s.

    ``base_dir`` resolves a relative csv ``path`` (the bench file's folder). Raises InputError
    naming ``source`` and the offending key for an unknown type or key, a missing key, a value
    of the wrong sign or kind, or a sine too coarsely sampled by dt_s.
    """
    if not isinstance(data, Mapping):
        raise InputError(f"expected a mapping with a type key, got {data!r}", source=source, key="programme")
    kind = data.get("type")
    if kind not in _KEYS:
        raise InputError(f"unknown programme type {kind!r}; expected one of {', '.join(_KEYS)}",
                         source=source, key="programme.type")
    allowed = _KEYS[kind]
    unknown = sorted(set(data) - set(allowed) - {"type"})
    if unknown:
        raise InputError(f"unknown key {unknown[0]!r} for a {kind} programme; expected {', '.join(allowed)}",
                         source=source, key=f"programme.{unknown[0]}")
    missing = [k for k, v in allowed.items() if v is _REQUIRED and k not in data]
    if missing:
        raise InputError(f"missing key for a {kind} programme", source=source, key=f"programme.{missing[0]}")
    r = _Reader(data, kind, source)
    if kind == "sweep":
        return Sweep(np.unique(r.numbers("amplitudes_mm")) * MM, np.unique(r.numbers("frequencies_hz")),
                     int(r.number("cycles", integer=True)), int(r.number("points_per_cycle", integer=True)))
    if kind == "csv":
        if not isinstance(data["path"], str):
            raise r.fail("path", f"expected a file path, got {data['path']!r}")
        path = Path(data["path"])
        t, e = read_csv_record(path if path.is_absolute() or base_dir is None else base_dir / path)
        return TimeSeries(kind, *piecewise_linear(t, e, dt_s))
    if kind == "triangle":
        t, e = triangle(r.number("amplitude_mm") * MM, r.number("speed_mm_s") * MM,
                        int(r.number("cycles", integer=True)), dt_s)
    elif kind == "sine":
        frequency = r.number("frequency_hz")
        _check_sampling(r, "frequency_hz", frequency, dt_s)
        t, e = sine(r.number("amplitude_mm") * MM, frequency, int(r.number("cycles", integer=True)), dt_s)
    elif kind == "bisine":
        amplitudes, frequencies = _components(r)
        _check_sampling(r, "components", max(frequencies), dt_s)
        if "duration_s" in data and "cycles" in data:
            raise r.fail("duration_s", "give either cycles (of the slowest component) or duration_s, not both")
        duration = (r.number("duration_s") if "duration_s" in data
                    else r.number("cycles", integer=True) / min(frequencies))
        t, e = multisine(amplitudes, frequencies, duration, dt_s)
    elif kind == "step":
        t, e = step(r.number("amplitude_mm", positive=False) * MM, r.number("rise_time_s", nonzero=False),
                    r.number("hold_s"), dt_s)
    else:
        amplitude, level = r.number("amplitude_mm"), r.number("step_mm")
        if abs(amplitude / level - round(amplitude / level)) > 1e-9:
            raise r.fail("step_mm", f"expected amplitude_mm ({amplitude}) to be a whole multiple of step_mm ({level})")
        t, e = firtree(amplitude * MM, r.number("speed_mm_s") * MM, level * MM, r.number("hold_s", nonzero=False),
                       int(r.number("cycles", integer=True)), dt_s)
    return TimeSeries(kind, t, e)


def _components(r: _Reader) -> tuple[list[float], list[float]]:
    raw = r.data["components"]
    if not isinstance(raw, list) or not raw or not all(isinstance(c, Mapping) for c in raw):
        raise r.fail("components", f"expected a list of {{amplitude_mm, frequency_hz}} mappings, got {raw!r}")
    amplitudes, frequencies = [], []
    for c in raw:
        if set(c) != {"amplitude_mm", "frequency_hz"}:
            raise r.fail("components", f"expected exactly the keys amplitude_mm and frequency_hz, got {dict(c)!r}")
        amplitudes.append(r.number("components", value=c["amplitude_mm"]) * MM)
        frequencies.append(r.number("components", value=c["frequency_hz"]))
    return amplitudes, frequencies


def _check_sampling(r: _Reader, key: str, frequency_hz: float, dt_s: float) -> None:
    if frequency_hz * dt_s * MIN_SAMPLES_PER_PERIOD > 1.0 + 1e-9:
        raise r.fail(key, f"{frequency_hz} Hz is sampled by fewer than {MIN_SAMPLES_PER_PERIOD} points per period "
                          f"at dt_s = {dt_s}; expected dt_s <= {1.0 / (MIN_SAMPLES_PER_PERIOD * frequency_hz):.3g}")
