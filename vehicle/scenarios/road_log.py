"""A test car's logged run (a CSV of time, steering-wheel angle, speed and the measured responses,
as a data logger exports it), read as a ``measured_steer`` case declares it and resampled once.

Resampling (the stated filter): the log is interpolated linearly onto a uniform grid at its own
median sampling interval, filtered forwards and backwards by a 2nd-order Butterworth low-pass at
``filter_hz`` (zero phase: no lag between channels), then interpolated onto the output grid at the
scenario's output rate, from the log's first sample (time 0 of the case's input) to its last
whole output interval. The filter must lie below 0.4 × both rates (it is the anti-alias filter of
the output grid).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from elastokin.core import units
from elastokin.core.csv_channels import TIME_KEYS, Column, declared_columns, time_column
from elastokin.core.documents import Fields
from elastokin.core.errors import InputError
from elastokin.core.files import is_file, read_text
from elastokin.core.tables import read_csv_columns, read_csv_header

#: What a road log may hold: channel → the unit it is kept in (a road run's recorded unit).
LOG_CHANNELS = {"steering_wheel": "deg", "speed": "km/h", "yaw_rate": "deg/s", "lateral_acceleration": "m/s²",
                "longitudinal_acceleration": "m/s²", "roll": "deg", "pitch": "deg", "sideslip": "deg"}
#: The columns of a log written in the project's convention (units in the names), read when a case
#: declares none: header name → (channel, unit).
DEFAULT_COLUMNS = {"steering_wheel_deg": ("steering_wheel", "deg"), "speed_kmh": ("speed", "km/h"),
                   "yaw_rate_deg_per_s": ("yaw_rate", "deg/s"),
                   "lateral_acceleration_mps2": ("lateral_acceleration", "m/s²"),
                   "longitudinal_acceleration_mps2": ("longitudinal_acceleration", "m/s²"),
                   "roll_deg": ("roll", "deg"), "pitch_deg": ("pitch", "deg"), "sideslip_deg": ("sideslip", "deg")}
DEFAULT_TIME = "t_s"
#: Cut-off of the log's low-pass filter when a case does not give one [Hz]: the handling band is
#: below 5 Hz; ISO 7401 filters its responses no lower.
DEFAULT_FILTER_HZ = 10.0
#: The filter's cut-off at most this fraction of the log's and of the output's sampling rate.
FILTER_RATE_FRACTION = 0.4
#: A time step longer than this many median steps is a gap in the log.
MAX_STEP_RATIO = 1.5
#: Keys a case gives about its log.
LOG_KEYS = ("path", "time", "columns", "filter_hz")


@dataclass(frozen=True)
class RoadLog:
    """A log resampled at the output rate: time from the log's first sample and each channel, in
    :data:`LOG_CHANNELS` units."""

    file: str                          #: the CSV as the case names it
    text: str                          #: the CSV as read (a recording carries it)
    filter_hz: float
    rate_hz: float                     #: the output rate resampled to [Hz]
    log_rate_hz: float                 #: the log's own (median) sampling rate [Hz]
    t_s: np.ndarray = field(repr=False, compare=False)                  #: (N,) uniform, from 0 [s]
    channels: dict[str, np.ndarray] = field(repr=False, compare=False)  #: channel → (N,)


def _columns(f: Fields, header: list[str]) -> tuple[Column, list[Column]]:
    """The time column and the channel columns the case declares (or the default convention's)."""
    if f.has("time") or f.has("columns"):
        time = time_column(f.fields("time", TIME_KEYS, {"column": DEFAULT_TIME, "unit": "s"}))
        expected = f"a channel of a road log: {', '.join(LOG_CHANNELS)}"
        return time, declared_columns(f.doc, f.path("columns"), f.raw("columns"), time, LOG_CHANNELS, expected)
    time = Column(DEFAULT_TIME, "t_s", 1.0, 0.0, units.plausible("s"))
    return time, [Column(name, channel, 1.0, 0.0, units.plausible(unit)) for name, (channel, unit) in DEFAULT_COLUMNS.items()
                  if name in header]


def _low_pass(t: np.ndarray, y: np.ndarray, interval_s: float, filter_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """``y`` at times ``t`` on a uniform grid of ``interval_s`` from ``t[0]``, zero-phase low-passed."""
    from scipy.signal import butter, filtfilt   # here: 0.4 s to import, and only a measured case needs it

    grid = t[0] + interval_s * np.arange(int(math.floor(round((t[-1] - t[0]) / interval_s, 6))) + 1)
    uniform = np.interp(grid, t, y)
    b, a = butter(2, filter_hz, fs=1.0 / interval_s)
    return grid, filtfilt(b, a, uniform, padlen=min(3 * len(a), len(uniform) - 1))


def read_road_log(f: Fields, base_dir: Path, rate_hz: float) -> RoadLog:
    """The log of the case ``f`` (keys :data:`LOG_KEYS`, paths from ``base_dir``) resampled at
    ``rate_hz`` [Hz] (module docstring). InputError naming the file, line and column (a missing
    column, a non-number, a time that does not increase, a gap beyond 1.5 × the median step) or the
    case's key (an unknown channel or unit, a filter too
    close to either rate)."""
    name = f.text("path")
    path = Path(name) if Path(name).is_absolute() else base_dir / name
    if not is_file(path):
        raise f.fail("path", f"no such CSV file {str(path)!r}")
    time, columns = _columns(f, read_csv_header(path))
    header = [time.name, *(c.name for c in columns)]
    values = read_csv_columns(path, header, min_rows=2, limits={c.name: c.limit for c in (time, *columns)})
    t = time.convert(values[time.name])
    steps = np.diff(t)
    median = float(np.median(steps))
    gap = int(np.argmax(steps))
    if steps[gap] > MAX_STEP_RATIO * median:
        raise InputError(f"a gap in the log: {steps[gap]:.6g} s between samples, {steps[gap] / median:.3g} × the "
                         f"median {median:.6g} s; expected a steady sampling rate", source=str(path),
                         key=f"line {gap + 3}, column {time.name}")
    filter_hz = f.number("filter_hz", DEFAULT_FILTER_HZ, positive=True, unit="Hz")
    slowest = min(1.0 / median, rate_hz)
    if filter_hz > FILTER_RATE_FRACTION * slowest:
        raise f.fail("filter_hz", f"a {filter_hz:g} Hz filter needs sampling above {filter_hz / FILTER_RATE_FRACTION:g}"
                                  f" Hz; the log samples at {1.0 / median:.6g} Hz and the output at {rate_hz:g} Hz "
                                  f"(expected at most {FILTER_RATE_FRACTION:g} × the slower)")
    out_t = np.arange(int(math.floor(round((t[-1] - t[0]) * rate_hz, 6))) + 1) / rate_hz
    channels = {}
    for c in columns:
        grid, filtered = _low_pass(t, c.convert(values[c.name]), median, filter_hz)
        channels[c.channel] = np.interp(t[0] + out_t, grid, filtered)
    return RoadLog(name, read_text(path), filter_hz, rate_hz, 1.0 / median, out_t, channels)
