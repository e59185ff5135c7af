"""Bench displacement programmes (spec §5): the thesis's test signals, sampled for a bushing bank.

A programme mapping (from a bench YAML file, in mm and s) is validated and converted to SI once,
by :func:`parse_programme`. Time-series programmes become a :class:`TimeSeries` (time [s] and
deflection [m] on a uniform grid of step dt_s, starting at rest at e = 0); a frequency ``sweep``
becomes a :class:`Sweep` of (amplitude, frequency) pairs, each analysed by
:mod:`elastokin.bushings.frequency`. A sine may carry ``static_mm``: it is then played about that static
offset, reached and left by 1 mm/s ramps (the standard campaign's static-offset sines).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from elastokin.core.documents import Document, Fields, KeyPath, check_number
from elastokin.core import units
from elastokin.core.tables import read_csv_columns
from elastokin.core.units import MM

#: Fewest samples per period of the fastest sine component that a bench accepts.
MIN_SAMPLES_PER_PERIOD = 20
#: Most samples a programme may take (each an 8-byte number per channel): beyond, it is a typing error.
MAX_SAMPLES = 10_000_000
#: Largest value a programme key may take, in its unit: a bushing deflects tens of millimetres, a
#: bench shakes at most a few kHz; beyond, it is a unit or typing error.
LIMITS = {"amplitude_mm": (100.0, "mm"), "step_mm": (100.0, "mm"), "static_mm": (100.0, "mm"),
          "amplitudes_mm": (100.0, "mm"), "speed_mm_s": (1e4, "mm/s"), "frequency_hz": (1e4, "Hz"),
          "frequencies_hz": (1e4, "Hz"), "hold_s": (1e6, "s"), "rise_time_s": (1e6, "s"), "duration_s": (1e6, "s")}
#: Largest magnitude of each column of a bench CSV record (``t_s,e_mm,F_N``): beyond any bushing on a
#: bench, below what a typing error gives.
RECORD_LIMITS = {"t_s": units.plausible("s"), "e_mm": units.plausible("mm"), "F_N": units.plausible("N")}
#: Speed of the ramps to and from a sine's static offset [mm/s], and the rest before the sine [s].
STATIC_RAMP_MM_S, STATIC_REST_S = 1.0, 1.0


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


def sine_about(static_m: float, ramp_s: float, amplitude_m: float, frequency_hz: float, cycles: int,
               dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """A sine A·sin(2π f t) of ``cycles`` periods about a static offset: a ramp from 0 to the offset in
    ``ramp_s``, a rest of :data:`STATIC_REST_S`, the sine, and a ramp back to 0 in ``ramp_s``.
    Returns time [s] and deflection [m]."""
    ramp = ramp_s
    t_ramp, e_ramp = piecewise_linear([0.0, ramp, ramp + STATIC_REST_S], [0.0, static_m, static_m], dt_s)
    ts, es = sine(amplitude_m, frequency_hz, cycles, dt_s)
    tb, eb = piecewise_linear([0.0, ramp], [static_m, 0.0], dt_s)
    t0 = t_ramp[-1] + dt_s
    t1 = t0 + ts[-1] + dt_s
    return np.r_[t_ramp, t0 + ts, t1 + tb], np.r_[e_ramp, static_m + es, eb]


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
    cols = read_csv_columns(path, ("t_s", "e_mm"), min_rows=2, limits=RECORD_LIMITS)
    return cols["t_s"], cols["e_mm"] * MM


# Accepted keys per programme type and their defaults (None: optional without default).
_REQUIRED = object()
_KEYS: dict[str, dict[str, Any]] = {
    "triangle": {"amplitude_mm": _REQUIRED, "speed_mm_s": _REQUIRED, "cycles": 3},
    "sine": {"amplitude_mm": _REQUIRED, "frequency_hz": _REQUIRED, "cycles": 5, "static_mm": None},
    "bisine": {"components": _REQUIRED, "cycles": 3, "duration_s": None},
    "step": {"amplitude_mm": _REQUIRED, "rise_time_s": _REQUIRED, "hold_s": _REQUIRED},
    "firtree": {"amplitude_mm": 3.0, "speed_mm_s": 10.0, "step_mm": 1.0, "hold_s": 60.0, "cycles": 1},
    "sweep": {"amplitudes_mm": _REQUIRED, "frequencies_hz": _REQUIRED, "cycles": 5, "points_per_cycle": 400},
    "csv": {"path": _REQUIRED},
}


def parse_programme(data: Any, dt_s: float, source: str, base_dir: Path | None = None) -> TimeSeries | Sweep:
    """Validate a ``programme`` mapping (mm, s, Hz) written in code or a file named ``source`` and
    build it in SI, sampled at dt_s (see :func:`read_programme`)."""
    return read_programme(Document.of_data({"programme": data}, source), ("programme",), dt_s, base_dir)


def read_programme(doc: Document, path: KeyPath, dt_s: float, base_dir: Path | None = None) -> TimeSeries | Sweep:
    """The programme mapping at ``path`` of ``doc`` (mm, s, Hz) built in SI, sampled at dt_s.

    ``base_dir`` resolves a relative csv ``path`` (the bench file's folder). Raises InputError
    naming the file and the offending key for an unknown type or key, a missing key, a value of the
    wrong sign or kind, a sine too coarsely sampled by dt_s, or more than :data:`MAX_SAMPLES`.
    """
    data = doc.data
    for part in path:
        data = data[part]
    if not isinstance(data, Mapping):
        raise doc.error(path, f"expected a mapping with a type key, got {data!r}")
    kind = data.get("type")
    if not isinstance(kind, str) or kind not in _KEYS:
        raise doc.error(path + ("type",), f"unknown programme type {kind!r}; expected one of {', '.join(_KEYS)}")
    allowed = _KEYS[kind]
    f = Fields(doc, {k: (v, path + (k,)) for k, v in data.items()}, path)
    f.check_keys(("type", *allowed), f" for a {kind} programme")
    missing = [k for k, v in allowed.items() if v is _REQUIRED and k not in data]
    if missing:
        raise f.fail(missing[0], f"missing key for a {kind} programme")

    def number(key: str, **kind_of: bool) -> float:
        return _limited(f, key, allowed[key], **(kind_of or {"positive": True}))

    def affordable(samples: float) -> None:
        if not samples <= MAX_SAMPLES:
            raise doc.error(path, f"{samples:.3g} samples at dt_s = {dt_s:g} s; expected at most {MAX_SAMPLES:g} "
                                  f"(shorten the programme or raise dt_s)")

    if kind == "sweep":
        sweep = Sweep(np.unique(_numbers(f, "amplitudes_mm")) * MM, np.unique(_numbers(f, "frequencies_hz")),
                      int(number("cycles", positive=True, integer=True)),
                      int(number("points_per_cycle", positive=True, integer=True)))
        per_cycle = max(sweep.points_per_cycle, 1.0 / (sweep.frequencies_hz.min() * dt_s))
        affordable(per_cycle * sweep.cycles * sweep.amplitudes_m.size * sweep.frequencies_hz.size)
        return sweep
    if kind == "csv":
        if not isinstance(data["path"], str):
            raise f.fail("path", f"expected a file path, got {data['path']!r}")
        csv = Path(data["path"])
        t, e = read_csv_record(csv if csv.is_absolute() or base_dir is None else base_dir / csv)
        affordable((t[-1] - t[0]) / dt_s)
        return TimeSeries(kind, *piecewise_linear(t, e, dt_s))
    if kind == "triangle":
        amplitude, speed = number("amplitude_mm"), number("speed_mm_s")
        cycles = number("cycles", positive=True, integer=True)
        affordable(4.0 * amplitude / speed * cycles / dt_s)
        t, e = triangle(amplitude * MM, speed * MM, int(cycles), dt_s)
    elif kind == "sine":
        frequency = number("frequency_hz")
        _check_sampling(f, "frequency_hz", frequency, dt_s)
        amplitude, cycles = number("amplitude_mm") * MM, int(number("cycles", positive=True, integer=True))
        static_mm = _limited(f, "static_mm") if f.has("static_mm") else 0.0
        affordable((cycles / frequency + 2.0 * abs(static_mm) / STATIC_RAMP_MM_S + STATIC_REST_S) / dt_s)
        if f.has("static_mm"):
            t, e = sine_about(static_mm * MM, abs(static_mm) / STATIC_RAMP_MM_S, amplitude, frequency, cycles, dt_s)
        else:
            t, e = sine(amplitude, frequency, cycles, dt_s)
    elif kind == "bisine":
        amplitudes, frequencies = _components(f)
        _check_sampling(f, "components", max(frequencies), dt_s)
        if f.has("duration_s") and f.has("cycles"):
            raise f.fail("duration_s", "give either cycles (of the slowest component) or duration_s, not both")
        duration = (number("duration_s") if f.has("duration_s")
                    else number("cycles", positive=True, integer=True) / min(frequencies))
        affordable(duration / dt_s)
        t, e = multisine(amplitudes, frequencies, duration, dt_s)
    elif kind == "step":
        rise, hold = number("rise_time_s", nonneg=True), number("hold_s")
        affordable((rise + hold) / dt_s)
        t, e = step(number("amplitude_mm", nonzero=True) * MM, rise, hold, dt_s)
    else:
        amplitude, level = number("amplitude_mm"), number("step_mm")
        if abs(amplitude / level - round(amplitude / level)) > 1e-9:
            raise f.fail("step_mm", f"expected amplitude_mm ({amplitude}) to be a whole multiple of step_mm ({level})")
        speed, hold = number("speed_mm_s"), number("hold_s", nonneg=True)
        cycles = number("cycles", positive=True, integer=True)
        affordable(cycles * 4.0 * amplitude / level * (level / speed + hold) / dt_s)
        t, e = firtree(amplitude * MM, speed * MM, level * MM, hold, int(cycles), dt_s)
    return TimeSeries(kind, t, e)


def _limited(f: Fields, key: str, default: Any = ..., **kind_of: bool) -> float:
    """The number at ``key`` of ``f``, within its :data:`LIMITS` (if it has one)."""
    at_most, unit = LIMITS.get(key, (math.inf, ""))
    return f.number(key, default, at_most=at_most, unit=unit, **kind_of)


def _numbers(f: Fields, key: str) -> np.ndarray:
    raw = f.raw(key)
    if not isinstance(raw, list) or not raw:
        raise f.fail(key, f"expected a non-empty list of positive numbers, got {raw!r}")
    at_most, unit = LIMITS[key]
    return np.array([check_number(f.doc, f.path(key) + (i,), v, positive=True, at_most=at_most, unit=unit)
                     for i, v in enumerate(raw)])


def _components(f: Fields) -> tuple[list[float], list[float]]:
    raw = f.raw("components")
    if not isinstance(raw, list) or not raw or not all(isinstance(c, Mapping) for c in raw):
        raise f.fail("components", f"expected a list of {{amplitude_mm, frequency_hz}} mappings, got {raw!r}")
    amplitudes, frequencies = [], []
    for i, c in enumerate(raw):
        if set(c) != {"amplitude_mm", "frequency_hz"}:
            raise f.fail("components", f"expected exactly the keys amplitude_mm and frequency_hz, got {dict(c)!r}")
        item = Fields.of(f.doc, f.path("components") + (i,), c, ("amplitude_mm", "frequency_hz"))
        amplitudes.append(_limited(item, "amplitude_mm", positive=True) * MM)
        frequencies.append(_limited(item, "frequency_hz", positive=True))
    return amplitudes, frequencies


def _check_sampling(f: Fields, key: str, frequency_hz: float, dt_s: float) -> None:
    if frequency_hz * dt_s * MIN_SAMPLES_PER_PERIOD > 1.0 + 1e-9:
        raise f.fail(key, f"{frequency_hz} Hz is sampled by fewer than {MIN_SAMPLES_PER_PERIOD} points per period "
                          f"at dt_s = {dt_s}; expected dt_s <= {1.0 / (MIN_SAMPLES_PER_PERIOD * frequency_hz):.3g}")
