"""The K&C diagnosis's nuisance algebra: the bounded least squares that holds a rig input's gain and
the rig's mechanics within their bounds, the one-channel columns held compactly, against the dense
forms they stand for; the rigs the rig mechanics' columns are run on."""

import numpy as np
import pytest
from scipy.optimize import lsq_linear

from elastokin.diagnosis.kc_columns import Columns, OneChannel
from elastokin.diagnosis import kc_layout
from elastokin.diagnosis.kc_rig_mechanics import BY_KEY, RIG, with_element
from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.kc_transducers import CALIBRATION_BOUND, INPUT_GAIN, bounded_solve, reading_columns
from elastokin.diagnosis.verdict import split
from elastokin.vehicle.model.elements import RigMechanics


@pytest.mark.parametrize("seed", range(5))
def test_the_bounded_fit_is_the_bounded_least_squares_optimum(seed):
    """On random problems with correlated columns, some bounded on one or both sides and some held
    (both bounds equal): within the bounds, and its squared error the bounded-variable least squares'
    (scipy's BVLS, written apart) to 1e-10 — where holding each out-of-bounds coefficient and refitting
    the rest once pushes another out of its bounds (columns correlated at 0.9); the same from a start
    holding a random half at one of their limits (a screening starts each fit from the last's)."""
    rng = np.random.default_rng(seed)
    for _ in range(40):
        n, k = 80, int(rng.integers(2, 14))
        a = rng.standard_normal((n, k))
        a[:, 1] = 0.9 * a[:, 0] + 0.1 * a[:, 1]
        b = 3.0 * rng.standard_normal(n)
        lo = np.where(rng.random(k) < 0.5, -np.inf, -0.3 * rng.random(k))
        hi = np.where(rng.random(k) < 0.5, np.inf, 0.3 * rng.random(k))
        held = rng.random(k) < 0.15
        lo[held] = hi[held] = 0.1
        gram, seen = a.T @ a, a.T @ b
        x = bounded_solve(gram, seen, np.column_stack([lo, hi]), np.linalg.pinv(gram))
        assert np.all(x >= lo) and np.all(x <= hi) and np.all(x[held] == 0.1)
        free = ~held
        ref = lsq_linear(a[:, free], b - a[:, held] @ x[held], bounds=(lo[free], hi[free]), method="bvls").x
        sse = lambda z: float(np.sum((a[:, free] @ z - (b - a[:, held] @ x[held])) ** 2))
        assert sse(x[free]) == pytest.approx(sse(ref), rel=1e-10)
        start = np.where(rng.random(k) < 0.5, np.where(rng.random(k) < 0.5, lo, hi), np.nan)
        y = bounded_solve(gram, seen, np.column_stack([lo, hi]), start=start)
        assert np.all(y >= lo) and np.all(y <= hi) and np.all(y[held] == 0.1)
        assert sse(y[free]) == pytest.approx(sse(ref), rel=1e-10)


def test_one_channel_columns_act_as_their_dense_forms():
    """Products with a residual, the Gram matrix and a weighted sum of dense and one-channel columns
    (two on one channel, so that their product is kept) equal the dense arrays' to 1e-12, extended by
    dense columns too (a block of their own); the dense columns on a channel, in order."""
    rng = np.random.default_rng(7)
    n, c = 50, 4
    ones = [OneChannel(2, rng.standard_normal(n)), OneChannel(0, rng.standard_normal(n)),
            OneChannel(2, rng.standard_normal(n))]
    dense = [rng.standard_normal((n, c)) for _ in range(2)]
    order = [ones[0], dense[0], ones[1], ones[2], dense[1]]
    as_dense = []
    for col in order:
        full = np.zeros((n, c))
        if isinstance(col, OneChannel):
            full[:, col.channel] = col.values
        else:
            full = col
        as_dense.append(full)
    extra = rng.standard_normal((n, c))
    stack = Columns(order, (n, c)).extended([extra])
    flat = np.array([x.ravel() for x in as_dense + [extra]])
    r = rng.standard_normal((n, c))
    coef = rng.standard_normal(len(flat))
    assert stack.products(r) == pytest.approx(flat @ r.ravel(), rel=1e-12, abs=1e-12)
    assert stack.gram() == pytest.approx(flat @ flat.T, rel=1e-12, abs=1e-12)
    assert stack.combine(coef).ravel() == pytest.approx(coef @ flat, rel=1e-12, abs=1e-12)
    assert np.array_equal(stack.on_channel(2), np.array([d[:, 2] for d in dense + [extra]]))


def test_the_pads_friction_column_runs_on_pads_with_a_compliance_in_series():
    """The pads' friction moved by 10 N over a scenario's rig: on an ideal rig's pads, a typical pad's
    3.5 mm/kN in series (the friction acts through it); on a rig stating its pads' friction, their
    compliance kept, none included; a clamp's column leaves the pads as they are (SI: N, m/N)."""
    friction, clamp = BY_KEY["pad_friction_n"], BY_KEY["clamp_lateral_mm_per_kn"]
    ideal = with_element(RigMechanics(), friction, 10.0)
    assert (ideal.pad_friction_n, ideal.pad_compliance_m_per_n) == (10.0, pytest.approx(3.5e-6, rel=1e-12))
    stated = with_element(RigMechanics(pad_friction_n=4.0, pad_compliance_m_per_n=2e-6), friction, 10.0)
    assert (stated.pad_friction_n, stated.pad_compliance_m_per_n) == (14.0, 2e-6)
    rigid = with_element(RigMechanics(pad_friction_n=4.0), friction, 10.0)
    assert (rigid.pad_friction_n, rigid.pad_compliance_m_per_n) == (14.0, 0.0)
    clamped = with_element(RigMechanics(), clamp, 0.01)
    assert clamped.clamp_lateral_m_per_n == pytest.approx(1e-8, rel=1e-12)
    assert (clamped.pad_friction_n, clamped.pad_compliance_m_per_n) == (0.0, 0.0)


def test_a_rig_element_linearised_at_a_value_reads_and_is_bounded_from_it():
    """Runs made on a rig whose pads have 20 N of friction (``rig_at``), the data on one of 12 N
    (the rows 8 × the column's change per N below the runs', in white noise): the reading is
    12 N within 3 standard uncertainties, where a scorer taking the runs' rig as none holds it at
    0; a rig without friction reads 0 N, one "below" it held at 0 N, its bound; the coefficient of
    no friction is −20 N."""
    rng = np.random.default_rng(11)
    t = np.linspace(0.0, 1.0, 2000)
    column = np.column_stack([np.sin(2 * np.pi * t), np.sign(np.cos(3 * np.pi * t))])
    tests = [kc_layout.Test(name, None, rows, np.arange(len(rows)), True)
             for name, rows in (("a", np.arange(1000)), ("b", np.arange(1000, 2000)))]
    key, base = (RIG, "pad_friction_n", None), np.zeros_like(column)

    def scorer(truth: float, rig_at: dict | None) -> Scorer:
        measured = (truth - 20.0) * column + 0.2 * rng.standard_normal(column.shape)
        layout = kc_layout.Layout(["c_x", "c_y"], measured, t, np.zeros(2000, dtype=int), np.repeat([0, 1], 1000),
                                  tests)
        return Scorer(layout, base, split(2), {key: column}, rig_at)

    at = {"pad_friction_n": 20.0}
    for truth in (12.0, 0.0):
        (friction,) = scorer(truth, at).rig_errors(base)
        assert friction.value == pytest.approx(truth, abs=3.0 * friction.std) and 0.0 < friction.std < 0.01
    assert scorer(-10.0, at).rig_errors(base)[0].value == 0.0
    assert scorer(12.0, None).rig_errors(base)[0].value == 0.0
    assert scorer(12.0, at).nuisances(np.ones(2000, dtype=bool))[3][-1] == -20.0


def _bump_steer_campaign() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[kc_layout.Test]]:
    """Four pumping-like tests (30 and 60 mm triangles of 10 and 4 s, 50 Hz): the times, each row's
    recording, the baseline's camber and toe rows (camber follows the travel; toe too, with a part
    of its own) and a cause's change of them (a progressive bump steer, as large as the baseline's
    at full travel), the tests."""
    rate_hz, tests, base, times = 50.0, [], [], []
    for k, (amplitude, period_s) in enumerate([(30.0, 10.0), (60.0, 10.0), (30.0, 4.0), (60.0, 4.0)]):
        t = np.arange(0.0, 2.0 * period_s, 1.0 / rate_hz)
        travel = amplitude * (2.0 / np.pi) * np.arcsin(np.sin(2.0 * np.pi * t / period_s))
        base.append(np.column_stack([-0.02 * travel, 0.01 * travel + 0.2 * np.sin(2.0 * np.pi * t / period_s) ** 2]))
        start = sum(len(x) for x in times)
        tests.append(kc_layout.Test(f"test {k}", None, np.arange(start, start + len(t)), np.arange(len(t)), True,
                                    int(period_s * rate_hz)))
        times.append(t)
    base = np.vstack(base)
    travel = base[:, 0] / -0.02
    change = np.column_stack([np.zeros(len(base)), 0.01 * travel * np.abs(travel) / 60.0])
    return np.concatenate(times), np.repeat(np.arange(4), [len(t) for t in times]), base, change, tests


def test_a_predictions_change_is_read_through_the_transducers_errors():
    """A cause's toe change (:func:`_bump_steer_campaign`) measured through a toe head reading 2 %
    high and seeing 1.5 % of its camber, white noise on top: fitted beside the cause's prediction,
    the head's gain and cross-talk are read within 3 of their uncertainties (1.51 ± 0.08 % for 1.5).
    Their columns are the baseline's rows; the cause's change is read through the same gain
    (:func:`~elastokin.diagnosis.kc_transducers.as_read`), not left to the cross-talk, whose camber
    the change partly follows (so left: 0.78 ± 0.19 %)."""
    rng = np.random.default_rng(3)
    times, recording, base, change, tests = _bump_steer_campaign()
    gain, crosstalk, truth = 0.02, 0.015, base + change
    measured = truth + 0.003 * rng.standard_normal(truth.shape)
    measured[:, 1] += gain * truth[:, 1] + crosstalk * truth[:, 0]
    layout = kc_layout.Layout(["camber_fl", "toe_fl"], measured, times, recording, recording.copy(), tests)
    scorer = Scorer(layout, base, np.array([False, True, False, True]), reading_columns(layout, base))
    read = {(g.kind, g.channel): g for g in scorer.rig_errors(truth, [change])}
    for key, value in ((("gain", "toe_fl"), gain), (("cross-talk", "toe_fl"), crosstalk), (("gain", "camber_fl"), 0.0)):
        assert abs(read[key].value - value) < 3.0 * read[key].std and read[key].std < 0.002, (key, read[key])


def test_a_rig_inputs_gain_acts_on_a_causes_change_too():
    """The same cause, its slow tests played by a wheel pad whose travel transducer reads 2 % high
    (the car gets the command / 1.02; the toy car's rows are proportional to the travel), its fast
    ones by an exact one, measured through exact heads in white noise: the input-gain column is the
    baseline's, so read beside the cause's run the rest of its change, 2 % of it in the slow tests,
    goes to the gain (2.27 ± 0.04 % for 2); with the baseline and the cause run again under the gain
    read (:meth:`~elastokin.diagnosis.kc_scorer.Scorer.rig_errors_under_inputs`), every reading is
    within 3 of its uncertainties of the truth (the gain 1.98 ± 0.04 %)."""
    rng = np.random.default_rng(5)
    times, recording, base, change, tests = _bump_steer_campaign()
    slow = (recording < 2)[:, None]
    servo, truth = 1.0 / 1.02, base + change
    measured = np.where(slow, servo, 1.0) * truth + 0.003 * rng.standard_normal(truth.shape)
    layout = kc_layout.Layout(["camber_fl", "toe_fl"], measured, times, recording, recording.copy(), tests)
    columns = {(INPUT_GAIN, "pad_z_fl", None): slow * base, **reading_columns(layout, base)}   # d rows / d its scale
    scorer = Scorer(layout, base, np.array([False, True, False, True]), columns)
    runs = []

    def rerun(factors: dict[str, float]) -> list[np.ndarray]:
        runs.append(factors)
        scale = np.where(slow, factors["pad_z_fl"], 1.0)
        return [scale * base, scale * truth]

    plain = scorer.rig_errors(truth, [change])
    read, model = scorer.rig_errors_under_inputs(truth, [change], rerun)
    assert len(runs) == 1 and runs[0]["pad_z_fl"] == pytest.approx(servo, abs=0.005)   # the first reading's
    truths = {("input gain", "pad_z_fl"): 0.02}
    assert abs(plain[0].value - 0.02) > 3.0 * plain[0].std and plain[0].channel == "pad_z_fl"
    for g in read:
        assert abs(g.value - truths.get((g.kind, g.channel), 0.0)) < 3.0 * g.std and g.std < 0.002, g
    assert np.abs(model - base - np.where(slow, runs[0]["pad_z_fl"], 1.0) * change).max() < 1e-12
    assert scorer.rig_errors_under_inputs(truth, [], rerun)[1] is truth and len(runs) == 1   # no cause: no runs


def test_what_a_rigs_errors_leave_of_a_change_is_what_lies_beyond_their_bounds():
    """:meth:`~elastokin.diagnosis.kc_scorer.Scorer.seen_left` of a change that a wheel pad's travel
    gain in the slow tests would make (its column, ``f`` × the slow rows): within the gain's bound
    (±2.5 %) the gain takes all of it; beyond, the gain stops at its bound and what is left is what a
    scorer without that gain leaves of the change beyond the bound (the lags' taps refitted either
    way), in both signs."""
    rng = np.random.default_rng(7)
    times, recording, base, _, tests = _bump_steer_campaign()
    slow = (recording < 2)[:, None]
    measured = base + 0.003 * rng.standard_normal(base.shape)
    layout = kc_layout.Layout(["camber_fl", "toe_fl"], measured, times, recording, recording.copy(), tests)
    held = np.array([False, True, False, True])
    gain = Scorer(layout, base, held, {(INPUT_GAIN, "pad_z_fl", None): slow * base})
    plain = Scorer(layout, base, held)
    rows = np.ones(len(base), dtype=bool)
    size = np.abs(gain.seen(0.01 * slow * base, rows)).max()
    assert size > 1.0   # the change is seen: above the noise
    for f in (0.01, -0.02):
        assert np.abs(gain.seen_left(f * slow * base, rows)).max() < 1e-9 * size
    for f in (0.04, -0.06):
        beyond = (f - np.sign(f) * CALIBRATION_BOUND) * slow * base
        left = gain.seen_left(f * slow * base, rows)
        assert np.abs(left - plain.seen_left(beyond, rows)).max() < 1e-6 * size
        assert np.abs(left).max() > 0.5 * np.abs(plain.seen(beyond, rows)).max()
