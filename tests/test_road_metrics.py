"""The road metrics' definitions (ISO 7401, ISO 4138) against closed forms: a first-order lag's
response time, a second-order system's overshoot, the first harmonic's gain and phase, and the
45° bandwidth of a first-order lag."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from elastokin.analysis.road_metrics import TYPE_METRICS, bandwidth_hz, first_harmonic, road_metrics, step_response
from elastokin.recordings.run_format import Run, RunMetadata


@pytest.mark.parametrize("tau, rise", [(0.05, 0.1), (0.2, 0.01), (0.13, 0.15)])
def test_a_first_order_lag_responds_in_tau_ln10_after_half_the_ramp(tau: float, rise: float) -> None:
    t = np.arange(0.0, 3.0, 1e-3)
    x = np.clip(t / rise, 0.0, 1.0) * -30.0                      # a ramp to −30 deg
    # exact response of τ·y' + y = k·x to the ramp: k·A·(t − τ(1 − e^{−t/τ}))/rise, then the hold
    k, a = 0.3, -30.0
    ramp = lambda s: k * a / rise * (s - tau * (1.0 - np.exp(-s / tau)))
    y = np.where(t <= rise, ramp(t), ramp(rise) * np.exp(-(t - rise) / tau) + k * a * (1 - np.exp(-(t - rise) / tau)))
    r = step_response(t, x, y, steady_from=2.5)
    t50 = rise / 2
    t90 = t[np.argmax(y / (k * a) >= 0.9)]
    assert r["gain"] == pytest.approx(k, rel=1e-5)   # the lag has died out to e^{-2.3/τ}
    assert r["response_time_s"] == pytest.approx(t90 - t50, abs=1.1e-3)
    assert r["overshoot_pct"] == 0.0 and "peak_response_time_s" not in r    # a first-order lag does not overshoot
    if rise < 0.1 * tau:
        assert r["response_time_s"] == pytest.approx(tau * math.log(10.0), rel=0.05)


def test_a_second_order_step_overshoots_by_its_closed_form() -> None:
    zeta, wn = 0.4, 12.0
    t = np.arange(0.0, 4.0, 2e-4)
    x = np.where(t > 0.0, 1.0, 0.0)
    wd = wn * math.sqrt(1 - zeta ** 2)
    y = 1 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta ** 2) * np.sin(wd * t))
    r = step_response(t, x, 2.0 * y, steady_from=3.5)
    assert r["overshoot_pct"] == pytest.approx(100 * math.exp(-math.pi * zeta / math.sqrt(1 - zeta ** 2)), rel=1e-3)
    assert r["peak_response_time_s"] == pytest.approx(math.pi / wd, abs=1e-3)


def test_the_first_harmonic_and_the_bandwidth_of_a_first_order_lag() -> None:
    tau = 0.1
    metrics = {}
    for k, f in enumerate((0.5, 1.0, 1.5, 2.0, 3.0)):
        w = 2 * math.pi * f
        t = np.arange(0.0, 4.0 / f, 1e-3)
        h = 0.25 / complex(1.0, w * tau)
        x = 40.0 * np.sin(w * t)
        y = 40.0 * abs(h) * np.sin(w * t + np.angle(h)) + 3.0    # with an offset the fit ignores
        ratio = first_harmonic(t, y, f) / first_harmonic(t, x, f)
        assert abs(ratio) == pytest.approx(abs(h), rel=1e-6)
        assert np.angle(ratio) == pytest.approx(-math.atan(w * tau), abs=1e-6)
        metrics[k] = {"frequency_hz": f, "yaw_rate_phase_deg": math.degrees(np.angle(ratio))}
    # 45° of lag at ω τ = 1; linear interpolation between 1.5 and 2 Hz of atan is within 2 %
    assert bandwidth_hz(metrics) == pytest.approx(1.0 / (2 * math.pi * tau), rel=0.02)
    assert bandwidth_hz({0: metrics[0]}) is None


def test_a_recorded_step_of_first_order_responses_gives_their_iso_metrics() -> None:
    """road_metrics on a recording whose responses are exact first-order lags of the steering ramp
    (no overshoot: no peak response time), with a vibration above the handling band that the
    zero-phase filter removes."""
    rate, start, rise, hold, tau = 200.0, 1.0, 0.1, 3.0, 0.08
    t = np.arange(0.0, start + rise + hold + 1e-9, 1.0 / rate)
    s = np.clip((t - start) / rise, 0.0, 1.0)
    steering = 30.0 * s
    # exact lag of the ramp: y' = (s − y)/τ, integrated finely then sampled
    fine = np.arange(0.0, t[-1] + 1e-9, 1e-5)
    lag = np.zeros_like(fine)
    ramp = np.clip((fine - start) / rise, 0.0, 1.0)
    for i in range(1, len(fine)):
        lag[i] = lag[i - 1] + (ramp[i - 1] - lag[i - 1]) * (1e-5 / tau)
    y = np.interp(t, fine, lag)
    signals = {"steering_wheel": steering, "yaw_rate": 10.0 * y + 0.2 * np.sin(2 * math.pi * 40.0 * t),
               "lateral_acceleration": 4.0 * y, "sideslip": -0.2 * y, "roll": 1.7 * y,
               "toe_fl": 0.2 - 0.05 * y, "toe_fr": 0.2 - 0.05 * y}
    case = {"case": 1, "label": "left", "parameters": {"speed_kmh": 80.0, "steering_wheel_deg": 30.0},
            "start_s": 0.0, "input_start_s": start, "end_s": float(t[-1]), "cycles": 1}
    extra = {"type": "step_steer", "duration_scale": 1.0, "output_rate_hz": rate, "cases": [case]}
    run = Run(path=Path("synthetic"), t_s=t, signals=signals, units={}, groups={}, specs=[], body_names=[],
              body_pos=np.empty((len(t), 0, 3)), body_quat_wxyz=np.empty((len(t), 0, 4)), geometry=[],
              metadata=RunMetadata(extra=extra), complete=True, reason="")
    m = road_metrics(run)[1]
    assert set(m) <= set(TYPE_METRICS["step_steer"])   # what a sweep may ask of a step steer
    t90 = fine[np.argmax(lag >= 0.9)] - (start + rise / 2)
    for name in ("yaw_rate", "lateral_acceleration"):
        assert m[f"{name}_response_time_s"] == pytest.approx(t90, abs=1e-3)
        assert m[f"{name}_overshoot_pct"] == 0.0 and f"{name}_peak_response_time_s" not in m
    assert m["yaw_rate_gain_per_s"] == pytest.approx(10.0 / 30.0, rel=1e-3)
    assert m["steady_roll_deg"] == pytest.approx(1.7, rel=1e-3) and m["front_toe_lag_s"] == pytest.approx(t90, abs=1e-3)
