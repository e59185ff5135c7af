"""The road metrics' definitions (ISO 7401, ISO 4138) against closed forms: a first-order lag's
response time, a second-order system's overshoot, the first harmonic's gain and phase, and the
45° bandwidth of a first-order lag."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vsim_analysis.road_metrics import bandwidth_hz, first_harmonic, step_response


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
    assert r["overshoot_pct"] == pytest.approx(0.0, abs=1e-3)     # a first-order lag does not overshoot
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
