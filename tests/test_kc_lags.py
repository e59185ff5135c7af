"""The K&C diagnosis's model of a rig's acquisition (issue 53 item 2): each path's filter against
its closed form, and on synthetic tests measured through the virtual rig's chain (written apart,
elastokin/diagnosis/rig_chain.py) the paths' lags recovered, the residual at the noise, and a car's
own effect left for the causes."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.kc_lags import Response, paths
from elastokin.diagnosis import kc_layout
from elastokin.diagnosis.kc_transducers import drift_columns

from elastokin.diagnosis.rig_chain import ChannelChain, ar1

RATE_HZ = 50.0
CHANNELS = ["wheel_travel_fl", "camber_fl", "toe_fl", "pad_fz_fl", "pad_height_fl"]
#: Each channel's gain on the test's input, and its noise (channel units).
GAINS = np.array([0.9, -0.02, 0.01, 120.0, 1.0])
NOISE = np.array([0.02, 0.003, 0.003, 5.0, 0.02])


def _triangle(t: np.ndarray, amplitude: float, period_s: float) -> np.ndarray:
    return amplitude * (2.0 / math.pi) * np.arcsin(np.sin(2.0 * math.pi * t / period_s))


def _layout(chains: dict[int, ChannelChain], seed: int, effect: np.ndarray | None = None) -> tuple[kc_layout.Layout, np.ndarray]:
    """Four tests (triangles of 30 and 60 mm, two speeds), each its own recording, measured through
    ``chains`` (channel index -> chain) with white noise; the simulated rows are the true ones
    (plus ``effect`` (C,) × the input in the measurement: a car's own error)."""
    rng = np.random.default_rng(seed)
    true, measured, times, tests, start = [], [], [], [], 0
    for k, (amplitude, period) in enumerate([(30.0, 10.0), (60.0, 10.0), (30.0, 4.0), (60.0, 4.0)]):
        t = np.arange(0.0, 2.0 * period + 1e-9, 1.0 / RATE_HZ)
        x = _triangle(t, amplitude, period)
        rows = x[:, None] * GAINS[None, :]
        seen = rows * (1.0 + (effect if effect is not None else 0.0))
        cols = [chains[c].apply(t, seen[:, c], rng) if c in chains else seen[:, c] for c in range(len(CHANNELS))]
        measured.append(np.column_stack(cols) + rng.normal(0.0, NOISE, rows.shape))
        true.append(rows)
        times.append(t)
        tests.append(kc_layout.Test(f"test {k}", None, np.arange(start, start + len(t)), np.arange(len(t)), True,
                                    int(round(period * RATE_HZ))))
        start += len(t)
    recording = np.concatenate([np.full(len(t.rows), k) for k, t in enumerate(tests)])
    layout = kc_layout.Layout(CHANNELS, np.vstack(measured), np.concatenate(times), recording, recording.copy(), tests)
    return layout, np.vstack(true)


def test_the_paths_filter_lags_a_ramp_by_its_closed_form():
    """The continuous 2nd-order Butterworth at f_c, discretised for a signal linear between samples,
    delays a ramp by √2/(2π f_c) exactly, plus the path's delay."""
    layout, _ = _layout({}, 0)
    response = Response(layout, paths(CHANNELS))
    ramp = np.tile(layout.input_time[:, None], (1, len(CHANNELS)))
    out = response.apply(ramp, np.array([9.0, 20.0]), np.array([0.013, 0.002]))
    rows = layout.tests[0].rows[100:400]
    lag = (ramp - out)[rows]
    assert lag[:, 0] == pytest.approx(math.sqrt(2.0) / (2.0 * math.pi * 9.0) + 0.013, abs=1e-9)
    assert lag[:, 3] == pytest.approx(math.sqrt(2.0) / (2.0 * math.pi * 20.0) + 0.002, abs=1e-9)


@pytest.mark.parametrize("seed", [1])
def test_the_rigs_lags_are_recovered_and_the_residual_is_the_noise(seed):
    """Wheel sensors 13 ms late behind a 9 Hz filter, pads 2 ms behind 20 Hz (the virtual rig's
    digital filters): each path's lag at low frequency within 0.5 ms, the perfect model's error at
    the noise; without a chain, no lag."""
    rng = np.random.default_rng(seed)
    wheel = ChannelChain(low_pass_hz=9.0, delay_ms=float(rng.uniform(10.0, 16.0)))
    pad = ChannelChain(low_pass_hz=20.0, delay_ms=2.0)
    layout, true = _layout({0: wheel, 1: wheel, 2: wheel, 3: pad, 4: pad}, seed)
    heldout = np.array([False, True, False, True])
    scorer = Scorer(layout, true, heldout)
    lags = {r.path: r.lag_s for r in scorer.responses(true)}
    truth = lambda c: math.sqrt(2.0) / (2.0 * math.pi * c.low_pass_hz) + 1e-3 * c.delay_ms
    assert lags["wheel sensors"] == pytest.approx(truth(wheel), abs=5e-4)
    assert lags["pad sensors"] == pytest.approx(truth(pad), abs=5e-4)
    assert scorer.heldout_error(true) == pytest.approx(1.0, abs=0.05)
    plain, true = _layout({}, seed)
    scorer = Scorer(plain, true, heldout)
    assert all(abs(r.lag_s) < max(4.0 * r.std_s, 1e-4) for r in scorer.responses(true))
    assert scorer.heldout_error(true) == pytest.approx(1.0, abs=0.05)


def test_a_change_of_the_prediction_lowers_the_raw_residual_by_its_delivered_self():
    """Through a chain's filters and delays the residual is affine in the prediction: the raw residual
    of a prediction less that of the prediction plus a change is the change as the acquisition
    delivers it (:meth:`Scorer.seen`), to rounding; a raw residual is handed out read-only, the same
    one again for the same prediction."""
    wheel, pad = ChannelChain(low_pass_hz=9.0, delay_ms=13.0), ChannelChain(low_pass_hz=20.0, delay_ms=2.0)
    layout, true = _layout({0: wheel, 1: wheel, 2: wheel, 3: pad, 4: pad}, 4)
    scorer = Scorer(layout, true, np.array([False, True, False, True]))
    train = ~scorer.held_rows
    change = np.random.default_rng(4).standard_normal(true.shape) * NOISE
    base = scorer.raw(true, train)
    assert scorer.raw(true, train) is base and not base.flags.writeable
    seen = scorer.seen(change, train)
    assert np.sqrt(np.mean(seen ** 2)) > 0.3   # a change the residual sees, in noise units
    np.testing.assert_allclose(base - scorer.raw(true + change, train), seen, rtol=0.0, atol=1e-9)


def test_a_cars_own_error_is_left_for_the_causes():
    """The toe 3 % and the pad load 2 % off their model (a car's error, not the rig's), measured
    through the same chain: the comparison still shows them, tens of times the noise."""
    wheel, pad = ChannelChain(low_pass_hz=9.0, delay_ms=13.0), ChannelChain(low_pass_hz=20.0, delay_ms=2.0)
    chains = {0: wheel, 1: wheel, 2: wheel, 3: pad, 4: pad}
    layout, true = _layout(chains, 3, effect=np.array([0.0, 0.0, 0.03, 0.02, 0.0]))
    scorer = Scorer(layout, true, np.array([False, True, False, True]))
    every = np.ones(len(true), dtype=bool)
    errors = np.sqrt(np.mean(scorer.residual(true, every) ** 2, axis=0))
    # the effect's own size in the noise's units as estimated, each recording's mean out (as the zero errors are)
    effect = true * np.array([0.0, 0.0, 0.03, 0.02, 0.0])
    for k in range(4):
        effect[layout.recording == k] -= effect[layout.recording == k].mean(axis=0)
    size = np.sqrt(np.mean((effect / scorer.noise) ** 2, axis=0))
    assert size[2] > 2.0 and size[3] > 2.0
    for c in (2, 3):   # all of it still there: the chain's model took none of it
        assert math.sqrt(errors[c] ** 2 - 1.0) == pytest.approx(size[c], rel=0.1)
    assert errors[0] == pytest.approx(1.0, abs=0.1) and errors[1] == pytest.approx(1.0, abs=0.1)


@pytest.mark.parametrize("seed", [2, 3])
def test_coloured_noise_and_a_drifting_zero_are_noise_not_a_model_error(seed):
    """Each channel through AR(1) noise of twice its white noise (correlation time 0.5 s) and a zero
    drifting by up to twice it per minute (the virtual rig's chain): the noise estimated from the
    residual is the white and the coloured noise together (the channels' median within 15 %; each
    channel is its own quantity here, estimated alone), so the perfect model's error is the noise
    (within 0.1), where the white noise alone would make it 2."""
    chains = {c: ChannelChain(ar1_sigma=2.0 * NOISE[c], ar1_time_constant_s=0.5, drift_per_min=2.0 * NOISE[c])
              for c in range(len(CHANNELS))}
    layout, true = _layout(chains, seed)
    scorer = Scorer(layout, true, np.array([False, True, False, True]))
    assert np.median(scorer.noise / NOISE) == pytest.approx(math.sqrt(5.0), rel=0.15)
    assert scorer.heldout_error(true) == pytest.approx(1.0, abs=0.1)


def test_a_fits_uncertainty_holds_for_coloured_noise():
    """A smooth effect's coefficient fitted on residuals of AR(1) noise (correlation time 0.5 s at
    50 Hz: φ = 0.96, n samples worth n(1 − φ)/(1 + φ)): the standard uncertainty the scorer gives
    is the scatter of the coefficient over 200 draws (within 25 %), where white noise's formula
    claims seven times less."""
    layout, true = _layout({}, 0)
    scorer = Scorer(layout, true, np.array([False, True, False, True]))
    every = np.ones(len(true), dtype=bool)
    column = true / NOISE                      # an effect proportional to the input, in noise units
    rng = np.random.default_rng(4)
    phi = math.exp(-1.0 / (RATE_HZ * 0.5))
    fitted, claimed = [], []
    for _ in range(200):
        white = rng.standard_normal(true.shape)
        noise = np.vstack([np.column_stack([ar1(white[t.rows, c], 1.0, phi) for c in range(len(CHANNELS))])
                           for t in layout.tests])
        coef = float(np.sum(column * noise) / np.sum(column * column))
        fitted.append(coef)
        claimed.append(math.sqrt(scorer.variances(noise - coef * column, [column], every)[0]))
    scatter = float(np.std(fitted))
    assert np.median(claimed) == pytest.approx(scatter, rel=0.25)
    assert 1.0 / math.sqrt(float(np.sum(column * column))) < scatter / 5.0


def test_a_slow_coloured_noise_is_counted_whole_and_in_the_uncertainties():
    """AR(1) noise of twice the white noise correlated over 4 s, longer than the shorter tests'
    period (differences a period apart tell its drift rate, not its correlation time): the noise the
    scorer counts is what a recording's zero leaves of it (√(1 + 4 × 0.59), within 20 %), so the perfect
    model's error is the noise, no stretch of it a misfit; an effect proportional to the input and
    a drift through each recording, fitted on such noise, get an uncertainty of their scatter over
    100 draws (within 30 %; 0.97 and 1.19 × it: the noise's covariance counted whole, as a column
    centred in its recording takes it, where what the recording's zero leaves of it gave 0.76 and 0.53)."""
    from elastokin.diagnosis.kc_misfits import located_misfits
    tau = 4.0
    chains = {c: ChannelChain(ar1_sigma=2.0 * NOISE[c], ar1_time_constant_s=tau) for c in range(len(CHANNELS))}
    layout, true = _layout(chains, 5)
    scorer = Scorer(layout, true, np.array([False, True, False, True]))
    assert np.median(scorer.noise / NOISE) == pytest.approx(math.sqrt(1.0 + 4.0 * 0.59), rel=0.2)
    assert scorer.heldout_error(true) == pytest.approx(1.0, abs=0.15)
    assert located_misfits(layout, scorer, true) == []
    every = np.ones(len(true), dtype=bool)
    ramp = layout.input_time.copy()
    for t in layout.tests:
        ramp[t.rows] -= ramp[t.rows].mean()
    columns = {"effect": true / scorer.noise, "drift": np.where(np.arange(len(CHANNELS)) == 2, ramp[:, None], 0.0)}
    rng = np.random.default_rng(6)
    fitted, claimed = {k: [] for k in columns}, {k: [] for k in columns}
    for _ in range(100):
        noise = np.vstack([np.column_stack([ChannelChain(ar1_sigma=2.0 * NOISE[c], ar1_time_constant_s=tau).apply(
            layout.input_time[t.rows], np.zeros(len(t.rows)), rng) + rng.normal(0.0, NOISE[c], len(t.rows))
            for c in range(len(CHANNELS))]) for t in layout.tests]) / scorer.noise
        for t in layout.tests:   # each recording's zero out, as the scorer's residuals have it
            noise[t.rows] -= noise[t.rows].mean(axis=0)
        for k, column in columns.items():
            coef = float(np.sum(column * noise) / np.sum(column * column))
            fitted[k].append(coef)
            claimed[k].append(math.sqrt(scorer.variances(noise - coef * column, [column], every)[0]))
    for k in columns:
        assert np.median(claimed[k]) == pytest.approx(float(np.std(fitted[k])), rel=0.3), k


def test_a_zero_drifting_through_each_recording_is_read_and_leaves_the_cars_effect():
    """Each channel's zero drifting through each recording at its own rate (up to 30 × its noise per
    minute: up to 10 × it over the longer tests), white noise on top: with the drift columns
    (:func:`drift_columns`) each rate is read within a tenth of that range and 3 of its standard
    uncertainty, the true model's error is the noise where without them the drift is a mismatch, and
    a car's effect (toe 3 % and pad load 2 % off) fitted beside them keeps its size; a recording of a
    held input (no repeat) gets no drift, the car's slow response there being the drift's twin."""
    layout, true = _layout({}, 7)
    rng = np.random.default_rng(8)
    rates = rng.uniform(-1.0, 1.0, (4, len(CHANNELS))) * 30.0 * NOISE   # [unit / min]
    effect = np.array([0.0, 0.0, 0.03, 0.02, 0.0])
    drifted = replace(layout, units=("mm", "deg", "deg", "N", "mm"),
                      measured=layout.measured + true * effect + rates[layout.recording] * layout.input_time[:, None] / 60.0)
    heldout = np.array([False, True, False, True])
    scorer = Scorer(drifted, true * (1.0 + effect), heldout, drift_columns(drifted))
    readings = scorer.rig_errors(true * (1.0 + effect))
    off = np.array([(g.value - rates[int(g.source.split()[-1]), CHANNELS.index(g.channel)])
                    / NOISE[CHANNELS.index(g.channel)] for g in readings])
    assert len(readings) == rates.size and np.abs(off).max() < 0.1 * 30.0
    assert all(abs(g.value - rates[int(g.source.split()[-1]), CHANNELS.index(g.channel)]) < 3.0 * g.std for g in readings)
    assert scorer.heldout_error(true * (1.0 + effect)) == pytest.approx(1.0, abs=0.05)
    assert Scorer(drifted, true * (1.0 + effect), heldout).heldout_error(true * (1.0 + effect)) > 1.25
    toe = next(g for g in readings if g.channel == "toe_fl" and g.source == "recording 0")
    assert toe.label == "toe_fl's zero drifts through recording 0" and toe.text.endswith(" deg/min") and toe.unit == "deg"
    train = ~scorer.held_rows
    (coef,), left, (column,) = scorer.fit_effects(true, [true * effect], train, np.array([(-np.inf, np.inf)]))
    std = math.sqrt(scorer.variances(left, [column], train)[0])
    assert coef == pytest.approx(1.0, abs=max(3.0 * std, 0.01))
    held = replace(drifted, tests=[replace(drifted.tests[0], period=0), *drifted.tests[1:]])
    assert {k[2] for k in drift_columns(held)} == {"recording 1", "recording 2", "recording 3"}


def test_a_drift_runs_through_its_recording_by_the_recordings_clock():
    """Two repeated tests in one recording, the second starting 30 s after the first: with the
    recording's clock a channel's one drift runs through both (its column the minutes since the
    recording started, across the gap); without the clock each test is its own recording, as the
    noise's covariance takes it (:meth:`kc_layout.Layout.clock`), with its own drift on its input
    time."""
    t = np.arange(0.0, 10.0, 0.1)
    tests = [kc_layout.Test(f"test {k}", None, np.arange(k * len(t), (k + 1) * len(t)), np.arange(len(t)), True, 20)
             for k in range(2)]
    one = np.zeros(2 * len(t), dtype=int)
    bare = kc_layout.Layout(["toe_fl"], np.zeros((2 * len(t), 1)), np.tile(t, 2), one, np.repeat([0, 1], len(t)), tests)
    timed = replace(bare, recording_time_s=np.r_[t, t + 30.0], recordings=("session",))
    (column,) = drift_columns(timed).values()
    assert list(drift_columns(timed)) == [("drift", "toe_fl", "session")]
    np.testing.assert_allclose(column.values, np.r_[t, t + 30.0] / 60.0)
    own = drift_columns(bare)
    assert [k[2] for k in own] == ["recording 0", "recording 1"]
    np.testing.assert_allclose(sum(c.values for c in own.values()), np.tile(t, 2) / 60.0)
    np.testing.assert_allclose(own[("drift", "toe_fl", "recording 1")].values, np.r_[0.0 * t, t] / 60.0)


@pytest.mark.parametrize("seed", range(9, 15))
def test_a_slow_noise_is_not_read_as_a_drift(seed):
    """AR(1) noise correlated over 0.1 s and 1/f noise, each of twice the white noise, and no drift
    (the virtual rig's chain), the channels four wheels of one quantity: no drift is said. The
    noise's model (white and AR(1)) takes the short correlation and misses the 1/f noise's wander
    over a recording, which its uncertainty alone would read as drifts in most of these draws; each
    drift's uncertainty counts its quantity's spread (:func:`drift_spread`)."""
    wheels = ["toe_fl", "toe_fr", "toe_rl", "toe_rr"]
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 20.0 + 1e-9, 1.0 / RATE_HZ)
    chain = ChannelChain(pink_sigma=2.0 * NOISE[2], ar1_sigma=2.0 * NOISE[2], ar1_time_constant_s=0.1)
    true = np.tile(_triangle(t, 30.0, 10.0)[:, None] * GAINS[2], (4, len(wheels)))
    measured = true + np.vstack([np.column_stack([chain.apply(t, np.zeros(len(t)), rng) for _ in wheels])
                                 for _ in range(4)]) + rng.normal(0.0, NOISE[2], true.shape)
    rows = [np.arange(k * len(t), (k + 1) * len(t)) for k in range(4)]
    tests = [kc_layout.Test(f"test {k}", None, r, np.arange(len(t)), True, int(10.0 * RATE_HZ)) for k, r in enumerate(rows)]
    recording = np.repeat(np.arange(4), len(t))
    layout = kc_layout.Layout(wheels, measured, np.tile(t, 4), recording, recording.copy(), tests, units=("deg",) * 4)
    readings = Scorer(layout, true, np.array([False, True, False, True]), drift_columns(layout)).rig_errors(true)
    assert len(readings) == 16 and not any(g.said for g in readings)
