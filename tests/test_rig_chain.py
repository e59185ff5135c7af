"""The virtual K&C rig's measurement chain (issue 53 item 1): each element against its closed form
on synthetic signals, and a truth's chain measured on the rig where it says, and nowhere else."""

from __future__ import annotations

import math
import shutil
from dataclasses import replace

import numpy as np
import pytest

from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.diagnosis.rig_chain import (CROSSTALK, DRAWN, GRADES, GROUPS, RIG_DRAWN, ChannelChain, draw_chain,
                                          draw_rig, parse_chain, servoed)
from elastokin.diagnosis.virtual_kc_rig import MEASUREMENT_DEFAULTS, measure_kc, parse_kc_truth, sensor
from elastokin.recordings.kc_dataset import read_kc_dataset
from elastokin.recordings.recorder import simulate
from elastokin.recordings.rig_recordings import measured_channels
from elastokin.vehicle.scenarios.channels import INPUT_CHANNELS, channel_quantity
from tests.test_virtual_kc_rig import PUMPING

RATE_HZ = 50.0
T = np.arange(0.0, 400.0, 1.0 / RATE_HZ)


def test_a_gain_scales_the_reading_and_nothing_else():
    x = np.sin(0.3 * T)
    y = ChannelChain(gain=0.015).apply(T, x, np.random.default_rng(0))
    np.testing.assert_allclose(y, 1.015 * x, rtol=0, atol=1e-15)


@pytest.mark.parametrize("cutoff_hz, delay_ms", [(9.0, 0.0), (9.0, 15.0), (20.0, 3.0), (0.0, 12.0)])
def test_filter_and_delay_lag_a_ramp_by_their_closed_forms(cutoff_hz, delay_ms):
    """A ramp through the analogue 2nd-order Butterworth lags by sqrt(2)/(2π f_c), its group delay at
    low frequency (which its bilinear transform, pre-warped to f_c at 8 × the rate, keeps), plus the
    pure delay; the slope is kept (unit DC gain). The same at another sampling rate: the filter is
    the rig's, before the sampling, not the recording's."""
    x = 2.0 * T
    y = ChannelChain(low_pass_hz=cutoff_hz, delay_ms=delay_ms).apply(T, x, np.random.default_rng(0))
    filter_lag = math.sqrt(2.0) / (2.0 * math.pi * cutoff_hz) if cutoff_hz else 0.0
    settled = T > 5.0
    lag = (x - y)[settled] / 2.0
    assert lag.mean() == pytest.approx(filter_lag + 1e-3 * delay_ms, rel=1e-3)
    assert np.ptp(lag) < 1e-9 + 0.002 * lag.mean()
    assert y[0] == x[0]                                  # started at rest on the first sample
    fast = np.arange(0.0, 20.0, 1.0 / 200.0)
    z = ChannelChain(low_pass_hz=cutoff_hz, delay_ms=delay_ms).apply(fast, 2.0 * fast, np.random.default_rng(0))
    assert ((2.0 * fast - z)[fast > 5.0] / 2.0).mean() == pytest.approx(filter_lag + 1e-3 * delay_ms, rel=1e-3)


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


#: The white noise of each measured quantity on the virtual rig, the scale of a drawn chain's noises.
WHITE = {channel_quantity(n): sensor(u, MEASUREMENT_DEFAULTS)[0] for n, u in measured_channels().items()}


def _within(value: float, bounds: tuple[float, float], scale: float = 1.0, slack: float = 1e-5) -> bool:
    return bounds[0] * scale - slack <= value <= bounds[1] * scale + slack


@pytest.mark.parametrize("grade", GRADES)
@pytest.mark.parametrize("elements", [DRAWN, ("delay",), ("gain",), ("ar1", "drift"), ("crosstalk", "pink"),
                                      ("input_gain",)])
def test_drawn_chains_sit_in_their_grades_ranges_and_parse_as_a_truths(grade, elements):
    ranges = GRADES[grade]
    draw = draw_chain(np.random.default_rng(8), grade, WHITE, elements)
    assert draw == draw_chain(np.random.default_rng(8), grade, WHITE, elements)   # from the seed alone
    assert draw != draw_chain(np.random.default_rng(9), grade, WHITE, elements)
    chains = parse_chain(draw, measured_channels(), INPUT_CHANNELS, "drawn")
    measured = [n for n in measured_channels() if n not in INPUT_CHANNELS]
    inputs = [n for n in measured_channels() if n in INPUT_CHANNELS]
    only_inputs = elements == ("input_gain",)
    assert set(chains) == (set() if only_inputs else set(measured)) | (set(inputs) if "input_gain" in elements
                                                                     else set())
    for name in inputs:   # a servoed input: a gain alone, each transducer its own
        assert (_within(abs(chains[name].gain), ranges["gain"]) and chains[name] == ChannelChain(gain=chains[name].gain)
                if "input_gain" in elements else name not in chains)
    if only_inputs:
        return
    for group, stems in GROUPS.items():
        for name in (n for n in measured if channel_quantity(n) in stems):
            c, white = chains[name], WHITE[channel_quantity(name)]
            checks = {"delay": (c.delay_ms, ranges["delay_ms"][group], 1.0),
                      "low_pass": (c.low_pass_hz, ranges["low_pass_hz"][group], 1.0),
                      "gain": (abs(c.gain), ranges["gain"], 1.0), "ar1": (c.ar1_sigma, ranges["ar1"], white),
                      "pink": (c.pink_sigma, ranges["pink"], white), "drift": (c.drift_per_min, ranges["drift"], white)}
            for element, (value, bounds, scale) in checks.items():
                assert _within(value, bounds, scale, 0.01) if element in elements else value == 0.0, (name, element)
            source = CROSSTALK.get(channel_quantity(name))
            if "crosstalk" in elements and source:
                (seen_q, coefficient), = c.crosstalk
                assert seen_q == source and _within(abs(coefficient), ranges["crosstalk"])
            else:
                assert c.crosstalk == ()
        lags = {chains[n].delay_ms for n in measured if channel_quantity(n) in stems}
        assert len(lags) == 1                            # one acquisition path per group
    if "gain" in elements:
        gains = [chains[n].gain for n in measured]
        assert min(gains) < 0.0 < max(gains) and len(set(gains)) > len(gains) // 2   # each transducer its own


def test_crosstalk_adds_the_other_quantitys_true_signal_times_its_coefficient():
    x, camber = np.sin(0.3 * T), 0.7 * np.cos(0.11 * T)
    chain = ChannelChain(gain=0.01, crosstalk=(("camber", -0.02),))
    y = chain.apply(T, x, np.random.default_rng(0), {"camber": camber})
    np.testing.assert_allclose(y, 1.01 * x - 0.02 * camber, rtol=0, atol=1e-15)


def test_pink_noise_has_its_expected_variance_and_a_one_over_f_spectrum():
    """Averaged over records, the mean square is the stated σ² and the periodogram falls as 1/f (a
    log-log slope of −1 over three decades); one record's mean is zero (no DC)."""
    sigma, n, records = 0.003, 4096, 300
    t = np.arange(n) / RATE_HZ
    rng = np.random.default_rng(11)
    draws = np.array([ChannelChain(pink_sigma=sigma).apply(t, np.zeros(n), rng) for _ in range(records)])
    assert np.abs(draws.mean(axis=1)).max() < 1e-15
    assert np.mean(draws ** 2) == pytest.approx(sigma ** 2, rel=0.05)
    power = np.mean(np.abs(np.fft.rfft(draws, axis=1)[:, 1:]) ** 2, axis=0)
    k = np.arange(1, n // 2 + 1)
    slope = np.polyfit(np.log(k[:-1]), np.log(power[:-1]), 1)[0]
    assert slope == pytest.approx(-1.0, abs=0.02)


def test_a_servoed_inputs_gain_gives_the_car_the_command_over_one_plus_it(tmp_path):
    """A pad-travel transducer reading 2 % high at the front left: the recording holds the command
    (the servo makes the reading follow it), the car is the simulation of that pad moved by the
    command / 1.02, and every other input is as commanded."""
    (tmp_path / "pumping.yaml").write_text(PUMPING)
    shutil.copy(DEFAULT_VEHICLE, tmp_path / "car.yaml")
    exact = {k: 0.0 for k in MEASUREMENT_DEFAULTS}
    base = {"level": "kc", "scenarios": ["pumping.yaml"], "duration_scale": 0.2, "measurement": exact, "seed": 4}
    truth = parse_kc_truth({**base, "chain": {"pad_z_fl": {"gain": 0.02}}}, "t.yaml", tmp_path)
    run = read_kc_dataset(measure_kc(truth, tmp_path / "servoed")).tests[0].run
    commanded = simulate(replace(truth.scenarios[0], bushing_model=None), truth.vehicle, duration_scale=0.2)
    played = simulate(replace(servoed(truth.scenarios[0], truth.chain), bushing_model=None), truth.vehicle,
                      duration_scale=0.2)
    np.testing.assert_allclose(played.signals["pad_z_fl"], commanded.signals["pad_z_fl"] / 1.02, atol=1e-12)
    for name in measured_channels():
        expected = commanded if name in INPUT_CHANNELS else played
        np.testing.assert_allclose(run.signals[name], expected.signals[name], rtol=1e-12, atol=1e-12, err_msg=name)
    travel = commanded.signals["wheel_travel_fl"]
    # the car saw the pad's travel / 1.02: so, nearly, does its wheel (the tyre's and the rest's share alike)
    assert np.abs(run.signals["wheel_travel_fl"]).max() == pytest.approx(np.abs(travel).max() / 1.02, rel=3e-3)


@pytest.mark.parametrize("grade", GRADES)
def test_drawn_rigs_sit_in_their_grades_ranges_and_parse_as_a_truths(grade):
    """Each element of the rig's mechanics drawn alone and together within its grade's range, the
    others ideal, from the seed alone, read as a truth's ``rig``; an element not known refused."""
    ranges = GRADES[grade]["rig"]
    for elements in [(e,) for e in RIG_DRAWN] + [DRAWN, ("delay", "gain")]:
        draw = draw_rig(np.random.default_rng(3), grade, elements)
        assert draw == draw_rig(np.random.default_rng(3), grade, elements)
        drawn = {key for e in elements if e in RIG_DRAWN for key in RIG_DRAWN[e]}
        assert set(draw) == drawn and all(_within(draw[k], ranges[k]) for k in drawn)
        rig = parse_kc_truth({"level": "kc", "rig": draw}, "drawn.yaml").rig
        assert rig.ideal == (not drawn)
    with pytest.raises(ValueError, match="unknown chain element 'clamps'"):
        draw_rig(np.random.default_rng(3), grade, ("clamps",))
