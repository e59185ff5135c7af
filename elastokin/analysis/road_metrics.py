"""Metrics of a road run with the standards' definitions and signs (ISO 8855 axes, left positive):
ISO 7401 for the step and sinusoidal steering inputs, ISO 4138 for steady-state circular driving.

* Step (``step_steer``, each step of a ``double_step_steer``): time zero is when the steering-wheel
  angle has made 50 % of its step; a response's **response time** is from there until it first
  reaches 90 % of its steady-state value, its **peak response time** until its extreme, its
  **overshoot** the extreme beyond the steady value in per cent of that value; steady values are
  the means over the last second of the hold (the last quarter of a shorter hold); **gains** are
  steady values per degree of steering-wheel angle. Responses are measured from their mean before
  the steering moves (has made :data:`ONSET_FRACTION` of its step): a step on top of another from
  the values just before it, a logged step from the straight running logged before it. The responses are low-pass filtered first, zero phase (2nd-order
  Butterworth forwards and backwards at :data:`RESPONSE_FILTER_HZ`, from :data:`FILTER_LEAD_S`
  before the step); an overshoot below :data:`MIN_OVERSHOOT` does not count. The instantaneous
  acceleration of the body carries the suspension's and tyres' vibrations, which would move a
  90 % crossing by milliseconds without moving the handling response.
* Sine (``sine_steer``): the responses' first harmonic at the input frequency over the cycles after
  the first; **gain** = amplitude ratio to the steering-wheel angle, **phase** = response minus
  input [deg] (a lag is negative). Over the cases, the **bandwidth** of a response is the lowest
  frequency at which its phase lag reaches 45° (linear between the cases' frequencies; None when
  it does not within them).
* Steady state (``steady_state_circular``): least-squares slopes against the lateral acceleration
  over 0.5 … 4 m/s² (the linear range) of the steering-wheel angle, of the **understeer** quantity
  δ_H / i_s − L / R (i_s the overall steering ratio, L the wheelbase, R = V / r the path radius),
  of the roll angle and of the sideslip, in deg/g; and the largest lateral acceleration reached.

A logged run (a ``measured_steer`` scenario's, simulated or imported from the road test) is read
as the manoeuvre its scenario names; the metrics of a response it does not hold (a road test
rarely logs toe or sideslip) are left out.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from elastokin.vehicle.scenarios.road_scenario import CIRCLE_STEER_IN_S, DEFAULT_RISE_TIME_S
from elastokin.recordings.run_format import Run

#: Standard gravity [m/s²] (the g of deg/g).
G = 9.80665
#: Responses measured, by recorded signal.
RESPONSES = ("yaw_rate", "lateral_acceleration")
#: The steady state's linear range of lateral acceleration [m/s²] (ISO 4138 gradients).
LINEAR_RANGE_MPS2 = (0.5, 4.0)
#: Cut-off of the zero-phase low-pass filter of the step responses [Hz] (the handling band is below
#: 5 Hz; at most 0.4 × the output rate).
RESPONSE_FILTER_HZ = 10.0
#: Smallest overshoot counted (a fraction of the steady value): below it, a response that settles
#: with numerical ripples has no peak.
MIN_OVERSHOOT = 1e-3
#: Time before a step over which its responses are filtered too [s], so that the filter's start-up
#: lies well before the step.
FILTER_LEAD_S = 0.5
#: Length of the window of steady values at the end of a hold [s].
STEADY_WINDOW_S = 1.0
#: The steering has moved once it has made this fraction of its step: a response's zero is its
#: mean before.
ONSET_FRACTION = 0.05

#: (metric, unit, meaning) of the metrics of a step steer, of a sine steer and of a circle.
STEP_METRICS = (
    ("yaw_rate_response_time_s", "s", "ISO 7401: 50 % steering to 90 % of the steady yaw rate"),
    ("yaw_rate_peak_response_time_s", "s", "ISO 7401: 50 % steering to the yaw rate's extreme"),
    ("yaw_rate_overshoot_pct", "%", "ISO 7401: yaw rate's extreme beyond its steady value"),
    ("yaw_rate_gain_per_s", "1/s", "steady yaw rate per steering-wheel angle [(deg/s)/deg]"),
    ("lateral_acceleration_response_time_s", "s", "ISO 7401: 50 % steering to 90 % of the steady ay"),
    ("lateral_acceleration_peak_response_time_s", "s", "ISO 7401: 50 % steering to ay's extreme"),
    ("lateral_acceleration_overshoot_pct", "%", "ISO 7401: ay's extreme beyond its steady value"),
    ("lateral_acceleration_gain_mps2_per_deg", "m/s²/deg", "steady ay per steering-wheel angle"),
    ("steady_lateral_acceleration_mps2", "m/s²", "steady ay after the step"),
    ("steady_sideslip_deg", "deg", "steady body sideslip after the step"),
    ("steady_roll_deg", "deg", "steady roll after the step (right side down +)"),
    ("steady_front_toe_deg", "deg", "steady mean toe-in of the front wheels relative to the body"),
    ("front_toe_lag_s", "s", "50 % steering to 90 % of the front toe change (relaxation)"),
)
SINE_METRICS = (
    ("frequency_hz", "Hz", "sine: input frequency"),
    ("yaw_rate_gain_at_frequency_per_s", "1/s", "sine: yaw-rate amplitude per steering-wheel amplitude"),
    ("yaw_rate_phase_deg", "deg", "sine: yaw rate's phase to the steering (lag negative)"),
    ("lateral_acceleration_gain_at_frequency_mps2_per_deg", "m/s²/deg", "sine: ay amplitude per steering amplitude"),
    ("lateral_acceleration_phase_deg", "deg", "sine: ay's phase to the steering (lag negative)"),
)
CIRCLE_METRICS = (
    ("steering_wheel_angle_gradient_deg_per_g", "deg/g", "ISO 4138: dδ_H/da_y"),
    ("understeer_gradient_deg_per_g", "deg/g", "ISO 4138: d(δ_H/i_s − L/R)/da_y"),
    ("roll_gradient_deg_per_g", "deg/g", "ISO 4138: dφ/da_y"),
    ("sideslip_gradient_deg_per_g", "deg/g", "ISO 4138: dβ/da_y"),
    ("max_lateral_acceleration_mps2", "m/s²", "largest |a_y| reached"),
)
#: Every road metric, for tables and the command line.
METRICS = STEP_METRICS + SINE_METRICS + CIRCLE_METRICS
#: The metrics each manoeuvre can give (a double step's second step: prefix ``second_``; a logged
#: run read as no manoeuvre, none).
TYPE_METRICS = {"step_steer": tuple(m[0] for m in STEP_METRICS),
                "double_step_steer": tuple(p + m[0] for p in ("", "second_") for m in STEP_METRICS),
                "sine_steer": tuple(m[0] for m in SINE_METRICS),
                "steady_state_circular": tuple(m[0] for m in CIRCLE_METRICS), "none": ()}


def _crossing(t: np.ndarray, y: np.ndarray, level: float) -> float | None:
    """First time at which ``y`` reaches ``level`` from below (linear between samples), or None."""
    above = np.flatnonzero(y >= level)
    if not above.size:
        return None
    i = int(above[0])
    if i == 0:
        return float(t[0])
    return float(t[i - 1] + (level - y[i - 1]) * (t[i] - t[i - 1]) / (y[i] - y[i - 1]))


def step_response(t: np.ndarray, x: np.ndarray, y: np.ndarray, steady_from: float) -> dict[str, float] | None:
    """ISO 7401 response time, peak response time, overshoot [%] and gain of ``y`` to a step of
    ``x`` (both from 0 at the start of ``t``), steady values from ``steady_from`` [s] on; None when
    the step or the response is nil or never reaches 90 %."""
    step = x[-1]
    steady = float(np.mean(y[t >= steady_from]))
    if step == 0.0 or steady == 0.0:
        return None
    sign_x, sign_y = np.sign(step), np.sign(steady)
    t50 = _crossing(t, sign_x * x, 0.5 * abs(step))
    after = t >= t50
    t90 = _crossing(t[after], sign_y * y[after], 0.9 * abs(steady))
    if t90 is None:
        return None
    out = {"response_time_s": t90 - t50, "gain": steady / step, "steady": steady, "overshoot_pct": 0.0}
    peak = _first_peak(t, sign_y * y, t90)
    if peak is not None and peak[1] > abs(steady) * (1.0 + MIN_OVERSHOOT):
        out |= {"peak_response_time_s": peak[0] - t50, "overshoot_pct": 100.0 * (peak[1] / abs(steady) - 1.0)}
    return out


def _first_peak(t: np.ndarray, y: np.ndarray, after_s: float) -> tuple[float, float] | None:
    """Time and value of the first local maximum of ``y`` after ``after_s``, refined by the parabola
    through it and its neighbours (uniform sampling) so that neither moves by whole sample
    intervals; None when ``y`` only rises."""
    start = int(np.searchsorted(t, after_s))
    falls = np.flatnonzero(np.diff(y[start:]) < 0.0)
    if not falls.size:
        return None
    k = start + int(falls[0])
    if 0 < k < len(y) - 1:
        a, b, c = y[k - 1], y[k], y[k + 1]
        curvature = a - 2.0 * b + c
        if curvature < 0.0:
            shift = 0.5 * (a - c) / curvature
            return float(t[k] + shift * (t[k + 1] - t[k])), float(b - 0.25 * (a - c) * shift)
    return float(t[k]), float(y[k])


def first_harmonic(t: np.ndarray, y: np.ndarray, frequency_hz: float) -> complex:
    """The complex amplitude of ``y`` at ``frequency_hz`` (y ≈ Re(A·e^{iωt}) + offset), least squares."""
    w = 2.0 * np.pi * frequency_hz
    basis = np.column_stack([np.cos(w * t), -np.sin(w * t), np.ones_like(t)])
    (a, b, _), *_ = np.linalg.lstsq(basis, y, rcond=None)
    return complex(a, b)


def _slope(x: np.ndarray, y: np.ndarray) -> float:
    return float(np.polyfit(x, y, 1)[0]) if x.size > 2 and np.ptp(x) > 0 else float("nan")


def _window(run: Run, start: float, end: float) -> np.ndarray:
    return (run.t_s >= start - 1e-9) & (run.t_s <= end + 1e-9)


def _front_toe(run: Run) -> np.ndarray:
    return 0.5 * (run.signals["toe_fl"] + run.signals["toe_fr"])


def _steps(run: Run, case: Mapping[str, Any]) -> list[tuple[float, float]]:
    """(start, end) [s] of each step of a step or double-step case, in file time."""
    p, start = case["parameters"], case["input_start_s"]
    scale = run.metadata.extra["duration_scale"]
    if run.metadata.extra["type"] == "double_step_steer":
        rise = p.get("rise_time_s", DEFAULT_RISE_TIME_S)
        second = start + (rise + p["rest_s"]) * scale
        return [(start, second), (second, case["end_s"])]
    return [(start, case["end_s"])]


def low_pass(y: np.ndarray, rate_hz: float) -> np.ndarray:
    """``y`` sampled at ``rate_hz`` filtered by :data:`RESPONSE_FILTER_HZ`'s zero-phase low-pass."""
    from scipy.signal import butter, filtfilt   # here: scipy.signal takes 0.4 s to import, and a rig run needs none

    b, a = butter(2, min(RESPONSE_FILTER_HZ, 0.4 * rate_hz), fs=rate_hz)
    return filtfilt(b, a, y, padlen=min(3 * len(a), len(y) - 1)) if len(y) > 1 else y


def _step_metrics(run: Run, start: float, end: float, case_start: float) -> dict[str, float]:
    # responses are filtered from FILTER_LEAD_S before the step (within its case) and measured from
    # their mean before the steering moves: a second step is measured on top of the first, a
    # logged step (whose input starts before the driver steers) from the straight running it logs
    lead = _window(run, max(start - FILTER_LEAD_S, case_start), end)
    before = max(int(np.searchsorted(run.t_s, start - 1e-9)) - 1, int(np.argmax(lead)))
    mask = _window(run, start, end)
    mask[before] = True
    inside = mask[lead]
    t = run.t_s[mask]
    x = run.signals["steering_wheel"][mask] - run.signals["steering_wheel"][before]
    moves = _crossing(t, np.sign(x[-1]) * x, ONSET_FRACTION * abs(x[-1])) if x[-1] != 0.0 else t[0]
    settled = lead & (run.t_s < max(start, moves) - 1e-9)
    settled[before] = True
    steady_from = max(t[-1] - STEADY_WINDOW_S, t[0] + 0.75 * (t[-1] - t[0]))
    rate = run.metadata.extra["output_rate_hz"]

    def zero(y: np.ndarray) -> np.ndarray:
        """The response ``y`` over the step, filtered, from its mean before the steering moves
        (unfiltered: the zero-phase filter already feels the step there)."""
        return low_pass(y[lead], rate)[inside] - float(np.mean(y[settled]))

    out: dict[str, float] = {}
    for name in RESPONSES:
        if name not in run.signals:
            continue   # a road test that did not log it
        r = step_response(t, x, zero(run.signals[name]), steady_from)
        if r is None:
            continue
        out |= {f"{name}_response_time_s": r["response_time_s"], f"{name}_overshoot_pct": r["overshoot_pct"]}
        if "peak_response_time_s" in r:     # none without an overshoot
            out[f"{name}_peak_response_time_s"] = r["peak_response_time_s"]
        out[f"{name}_gain_per_s" if name == "yaw_rate" else f"{name}_gain_mps2_per_deg"] = r["gain"]
    steady = t >= steady_from
    for name, key in (("lateral_acceleration", "steady_lateral_acceleration_mps2"), ("sideslip", "steady_sideslip_deg"),
                      ("roll", "steady_roll_deg")):
        if name in run.signals:
            out[key] = float(np.mean(run.signals[name][mask][steady]))
    if "toe_fl" in run.signals and "toe_fr" in run.signals:
        toe = _front_toe(run)
        out["steady_front_toe_deg"] = float(np.mean(toe[mask][steady]))
        lag = step_response(t, x, zero(toe), steady_from)
        if lag is not None:
            out["front_toe_lag_s"] = lag["response_time_s"]
    return out


def _sine_metrics(run: Run, case: Mapping[str, Any]) -> dict[str, float]:
    f = case["parameters"]["frequency_hz"] / run.metadata.extra["duration_scale"]
    start = case["input_start_s"] + 1.0 / f     # after the first cycle, whole cycles only
    mask = _window(run, start, case["input_start_s"] + case["cycles"] / f)
    t = run.t_s[mask] - case["input_start_s"]
    x = first_harmonic(t, run.signals["steering_wheel"][mask], f)
    out = {"frequency_hz": f}
    for name, gain_key in (("yaw_rate", "yaw_rate_gain_at_frequency_per_s"),
                           ("lateral_acceleration", "lateral_acceleration_gain_at_frequency_mps2_per_deg")):
        if name not in run.signals:
            continue
        h = first_harmonic(t, run.signals[name][mask], f) / x
        out[gain_key] = abs(h)
        out[f"{name}_phase_deg"] = float(np.degrees(np.angle(h)))
    return out


def _circle_metrics(run: Run, case: Mapping[str, Any]) -> dict[str, float]:
    extra = run.metadata.extra
    constant_steering = case["parameters"].get("method") == "constant_steering"   # a log's: constant speed
    # a constant-steering circle turns its wheel in first: its quasi-steady states come after
    start = case["input_start_s"] + (2.0 * CIRCLE_STEER_IN_S * extra["duration_scale"] if constant_steering else 0.0)
    mask = _window(run, start, case["end_s"])
    s = {k: run.signals[k][mask] for k in ("lateral_acceleration", "steering_wheel", "yaw_rate", "speed", "roll",
                                          "sideslip") if k in run.signals}
    ay = s["lateral_acceleration"]
    linear = (np.abs(ay) >= LINEAR_RANGE_MPS2[0]) & (np.abs(ay) <= LINEAR_RANGE_MPS2[1])
    g = lambda y: G * _slope(ay[linear], y[linear])
    out = {}
    if "yaw_rate" in s and "steering_ratio" in extra:   # a road test without them has no understeer
        curvature = np.radians(s["yaw_rate"]) / (s["speed"] / 3.6)                           # 1/R = r/V [1/m]
        understeer = s["steering_wheel"] / extra["steering_ratio"] - np.degrees(extra["wheelbase_m"] * curvature)
        out["understeer_gradient_deg_per_g"] = g(understeer)
    out |= {f"{name}_gradient_deg_per_g": g(s[name]) for name in ("roll", "sideslip") if name in s}
    out["max_lateral_acceleration_mps2"] = float(np.max(np.abs(ay))) if ay.size else float("nan")
    if not constant_steering:   # the angle held has no gradient
        out["steering_wheel_angle_gradient_deg_per_g"] = g(s["steering_wheel"])
    return out


def road_metrics(run: Run) -> dict[int, dict[str, float]]:
    """Every finished case's metrics (module docstring; names and units in :data:`METRICS`), by case
    number; a double step's second-step metrics carry the prefix ``second_``."""
    extra = run.metadata.extra
    kind = extra.get("manoeuvre", extra["type"])   # a logged run's is what it performs
    out: dict[int, dict[str, float]] = {}
    for case in extra["cases"]:
        if run.t_s.size == 0 or run.t_s[-1] < case["end_s"] - 1e-9:
            continue   # an incomplete run did not finish this case
        if kind == "none":
            metrics = {}
        elif kind in ("step_steer", "double_step_steer"):
            metrics: dict[str, float] = {}
            for k, (start, end) in enumerate(_steps(run, case)):
                metrics |= {("second_" if k else "") + key: v
                            for key, v in _step_metrics(run, start, end, case["start_s"]).items()}
        elif kind == "sine_steer":
            metrics = _sine_metrics(run, case)
        else:
            metrics = _circle_metrics(run, case)
        out[case["case"]] = metrics
    return out


def bandwidth_hz(metrics: Mapping[int, Mapping[str, float]], response: str = "yaw_rate") -> float | None:
    """The lowest frequency at which ``response``'s phase lag reaches 45° over sine cases'
    ``metrics`` (of one speed and amplitude; linear between their frequencies); 0 when it lags
    more already at the lowest, None when it does not within them."""
    rows = sorted((m["frequency_hz"], m[f"{response}_phase_deg"]) for m in metrics.values() if "frequency_hz" in m)
    if rows and rows[0][1] <= -45.0:
        return 0.0
    for (f0, p0), (f1, p1) in zip(rows, rows[1:]):
        if p0 > -45.0 >= p1:
            return f0 + (-45.0 - p0) * (f1 - f0) / (p1 - p0)
    return None
