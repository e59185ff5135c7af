"""The virtual K&C rig's measurement chain (issue 53 item 1): each element against its closed form
on synthetic signals, and a truth's chain measured on the rig where it says, and nowhere else."""

from __future__ import annotations

import math
import shutil
from dataclasses import replace

import numpy as np
import pytest

from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.diagnosis.rig_chain import DRAWN, GRADES, GROUPS, ChannelChain, draw_chain, parse_chain
from elastokin.diagnosis.virtual_kc_rig import MEASUREMENT_DEFAULTS, measure_kc, parse_kc_truth, sensor
from elastokin.recordings.kc_dataset import read_kc_dataset
from elastokin.recordings.recorder import simulate
from elastokin.recordings.rig_recordings import measured_channels
from elastokin.vehicle.scenarios.channels import INPUT_CHANNELS
from tests.test_virtual_kc_rig import PUMPING

RATE_HZ = 50.0
T = np.arange(0.0, 400.0, 1.0 / RATE_HZ)


def test_a_gain_scales_the_reading_and_nothing_else():
    x = np.sin(0.3 * T)
    y = ChannelChain(gain=0.015).apply(T, x, np.random.default_rng(0))
    np.testing.assert_allclose(y, 1.015 * x, rtol=0, atol=1e-15)


@pytest.mark.parametrize("cutoff_hz, delay_ms", [(9.0, 0.0), (9.0, 15.0), (20.0, 3.0), (0.0, 12.0)])
def test_filter_and_delay_lag_a_ramp_by_their_closed_forms(cutoff_hz, delay_ms):
    """A ramp through a digital 2nd-order Butterworth lags by sqrt(2)/(2π f_a), the group delay at low
    frequency of its analogue prototype at the pre-warped cut-off f_a = (f_s/π) tan(π f_c/f_s) (the
    bilinear transform keeps it at DC), plus the pure delay; the slope is kept (unit DC gain)."""
    x = 2.0 * T
    y = ChannelChain(low_pass_hz=cutoff_hz, delay_ms=delay_ms).apply(T, x, np.random.default_rng(0))
    prewarped = RATE_HZ / math.pi * math.tan(math.pi * cutoff_hz / RATE_HZ)
    filter_lag = math.sqrt(2.0) / (2.0 * math.pi * prewarped) if cutoff_hz else 0.0
    settled = T > 5.0
    lag = (x - y)[settled] / 2.0
    assert lag.mean() == pytest.approx(filter_lag + 1e-3 * delay_ms, rel=1e-3)
    assert np.ptp(lag) < 1e-9 + 0.002 * lag.mean()
    assert y[0] == x[0]                                  # started at rest on the first sample


def test_ar1_noise_has_its_variance_and_correlation_time():
    sigma, tau = 0.004, 2.0
    e = ChannelChain(ar1_sigma=sigma, ar1_time_constant_s=tau).apply(T, np.zeros_like(T), np.random.default_rng(3))
    phi = math.exp(-1.0 / (RATE_HZ * tau))
    assert e.std() == pytest.approx(sigma, rel=0.1)      # 20 000 samples, correlation time 100 samples
    lag = int(RATE_HZ * tau)                             # one correlation time: correlation 1/e
    r = np.corrcoef(e[:-lag], e[lag:])[0, 1]
    assert r == pytest.approx(phi ** lag, abs=0.06)
    assert np.corrcoef(e[:-1], e[1:])[0, 1] == pytest.approx(phi, abs=0.005)


def test_a_drift_is_a_straight_line_within_its_bound_and_differs_between_recordings():
    bound = 0.006
    rng = np.random.default_rng(5)
    rates = []
    for _ in range(20):
        d = ChannelChain(drift_per_min=bound).apply(T, np.zeros_like(T), rng)
        slope, intercept = np.polyfit(T, d, 1)
        np.testing.assert_allclose(d, slope * T + intercept, atol=1e-12)
        rates.append(slope * 60.0)
    assert np.all(np.abs(rates) <= bound) and np.ptp(rates) > bound   # drawn in ± bound


def test_a_truths_chain_acts_on_its_channels_alone(tmp_path):
    """On a perfect rig (no noise, zero or resolution), a toe chain of a 15 ms lag behind a 9 Hz
    filter and a 1 % camber gain at the front left: those channels are the simulated ones through
    the chain, every other channel is the simulation's own, and a truth without a chain measures
    as it did."""
    (tmp_path / "pumping.yaml").write_text(PUMPING)
    shutil.copy(DEFAULT_VEHICLE, tmp_path / "car.yaml")
    exact = {k: 0.0 for k in MEASUREMENT_DEFAULTS}
    chain = {"toe": {"delay_ms": 15.0, "low_pass_hz": 9.0}, "camber_fl": {"gain": 0.01}}
    base = {"level": "kc", "scenarios": ["pumping.yaml"], "duration_scale": 0.2, "measurement": exact, "seed": 4}
    truth = parse_kc_truth({**base, "chain": chain}, "t.yaml", tmp_path)
    run = read_kc_dataset(measure_kc(truth, tmp_path / "chained")).tests[0].run
    plain = read_kc_dataset(measure_kc(parse_kc_truth(base, "t.yaml", tmp_path), tmp_path / "plain")).tests[0].run
    sim = simulate(replace(truth.scenarios[0], bushing_model=None), truth.vehicle, duration_scale=0.2)
    rng = np.random.default_rng(0)
    for name in measured_channels():
        if name.startswith("toe_"):
            expected = ChannelChain(delay_ms=15.0, low_pass_hz=9.0).apply(sim.t_s, sim.signals[name], rng)
        elif name == "camber_fl":
            expected = 1.01 * sim.signals[name]
        else:
            expected = sim.signals[name]
        np.testing.assert_allclose(run.signals[name], expected, rtol=1e-12, atol=1e-12, err_msg=name)
        if not (name.startswith("toe_") or name == "camber_fl"):
            np.testing.assert_array_equal(plain.signals[name], run.signals[name])
    lagged = np.abs(run.signals["toe_fl"] - sim.signals["toe_fl"]).max()
    assert lagged > 1e-4                                 # the lag shows: the toe moves during the triangle
    assert "not stated" in read_kc_dataset(tmp_path / "chained").rig["notes"]


WHITE = {n.rsplit("_", 1)[0]: sensor(u, MEASUREMENT_DEFAULTS)[0] for n, u in measured_channels().items()}


@pytest.mark.parametrize("grade", GRADES)
@pytest.mark.parametrize("elements", [DRAWN, ("delay",), ("gain",), ("ar1", "drift")])
def test_drawn_chains_sit_in_their_grades_ranges_and_parse_as_a_truths(grade, elements):
    ranges = GRADES[grade]
    draw = draw_chain(np.random.default_rng(8), grade, WHITE, elements)
    assert draw == draw_chain(np.random.default_rng(8), grade, WHITE, elements)   # from the seed alone
    assert draw != draw_chain(np.random.default_rng(9), grade, WHITE, elements)
    chains = parse_chain(draw, measured_channels(), INPUT_CHANNELS, "drawn")
    measured = [n for n in measured_channels() if n not in INPUT_CHANNELS]
    assert set(chains) == set(measured)                  # every measured channel, no input
    for group, stems in GROUPS.items():
        for name in (n for n in measured if n.rsplit("_", 1)[0] in stems):
            c, white = chains[name], WHITE[name.rsplit("_", 1)[0]]
            low, high = ranges["delay_ms"][group]
            assert (low - 0.01 <= c.delay_ms <= high + 0.01) if "delay" in elements else c.delay_ms == 0.0
            low, high = ranges["low_pass_hz"][group]
            assert (low - 0.01 <= c.low_pass_hz <= high + 0.01) if "low_pass" in elements else c.low_pass_hz == 0.0
            low, high = ranges["gain"]
            assert (low - 1e-5 <= abs(c.gain) <= high + 1e-5) if "gain" in elements else c.gain == 0.0
            low, high = ranges["ar1"]
            assert (low * white <= c.ar1_sigma <= high * white) if "ar1" in elements else c.ar1_sigma == 0.0
            low, high = ranges["drift"]
            assert (low * white <= c.drift_per_min <= high * white) if "drift" in elements else c.drift_per_min == 0.0
        lags = {chains[n].delay_ms for n in measured if n.rsplit("_", 1)[0] in stems}
        assert len(lags) == 1                            # one acquisition path per group
    if "gain" in elements:
        gains = [chains[n].gain for n in measured]
        assert min(gains) < 0.0 < max(gains) and len(set(gains)) > len(gains) // 2   # each transducer its own
