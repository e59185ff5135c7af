"""Bench-level diagnosis: a cause hidden in measured data at a random magnitude (drawn from a seed
in its realistic range, with random noise and zero errors) must be named, with the held-out error
cut by at least half; two causes hidden at once must both be named; noise alone must give no cause;
an effect outside the catalogue must be reported as unexplained. The diagnosis runs in a fresh
process on a copied directory."""

from __future__ import annotations

import json
import math
import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from elastokin.bushings.bench.programmes import TimeSeries
from elastokin.bushings.bench.records import sample_steps, simulate_record
from elastokin.bushings.effects import Effects, broad_relaxation_branches, effects_to_si
from elastokin.bushings.extended_bank import ExtendedBank
from elastokin.bushings.parameter_sets import ParameterSet, load_parameter_set
from elastokin.core.errors import InputError
from tests.diagnosis_helpers import (MIN_PAIR_SUCCESS_RATE, MIN_SUCCESS_RATE, OWN_FORM_SUCCESS_RATE, PAIR, SLOW_SEEDS,
                                     assert_success_rate, diagnose_fresh, measure)
from elastokin.diagnosis.bench_alike import REST_BEFORE_S, Programme, extra_programmes, load_cell_noise_n, separations
from elastokin.diagnosis.bench_diagnosis import REST_STEP_S, Replay
from elastokin.diagnosis.catalogue import CAUSES, PAIR_SEPARATOR
from elastokin.diagnosis.truth_forms import BOX_PER_DECADE, BOX_TAU_MIN_S, FORMS, box_taus
from elastokin.diagnosis.verdict import pair_shares
from elastokin.diagnosis.virtual_bench import OUTSIDE

BENCH_CAUSES = sorted(CAUSES)
#: Seeds per cause in the default suite (one, for time: each diagnosis takes 15-60 s); the slow
#: suite (``pytest -m slow``) runs SLOW_SEEDS more.
SEEDS = [int(os.environ.get("VSIM_TEST_SEED", "1"))]


def _check_named(result: dict, cause: str, effects: list[dict]) -> None:
    assert result["cause"] == cause, result["ranking"][:3]
    assert result["heldout_error_after"] <= 0.5 * result["heldout_error_before"]
    # one cause hidden: the verdict lists it alone, with the share the verdict's errors give
    assert [c["cause"] for c in result["causes"]] == [cause] and result["explained"] in ("full", "partial")
    floor2 = result["noise_floor"] ** 2
    excess = lambda e: max(e ** 2 - floor2, 0.0)
    before, after = excess(result["heldout_error_before"]), excess(result["heldout_error_after"])
    assert result["share_explained"] == pytest.approx(min(1.0, max(0.0, 1.0 - after / before)) if before else 1.0)
    truth = effects[0]
    factors = {p.name for p in CAUSES[cause].parameters if p.factor}
    for name, fitted in result["parameters"].items():
        # The fitted magnitude is the hidden one, within 4 standard uncertainties or 25 % (the
        # self-heating rate and time constant trade off against each other over a 30 s endurance run);
        # a factor's magnitude is its distance from 1.
        # (a null uncertainty: a parameter the tests do not see, e.g. a slip stiffness with no slip force)
        size = abs(truth[name] - 1.0) if name in factors else abs(truth[name])
        tolerance = max(4.0 * (fitted["std"] if fitted["std"] is not None else np.inf), 0.25 * size)
        assert abs(fitted["value"] - truth[name]) <= tolerance, (name, fitted, truth[name])


#: Causes whose drawn diagnosis runs in the slow stage only, for the default suite's time: it names
#: each all the same, in a dataset measured apart (Mullins with its magnitude: tests/test_layout.py),
#: in another form of its family (the asymmetry's one-sided cubic, below), at the other level (a
#: bushing direction's stiffness factor on the K&C rig: tests/test_diagnosis_kc.py; the bench's is
#: 20/20 in the slow suite, README) or fitted as the rival of another cause (a preload, beside the
#: one-sided stiffening below; every bench diagnosis fits it). Each is drawn from 20 seeds in the
#: slow suite's rates.
NAMED_ELSEWHERE = ("mullins", "asymmetry", "stiffness", "preload")


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("cause", [pytest.param(c, marks=pytest.mark.slow) if c in NAMED_ELSEWHERE else c
                                   for c in BENCH_CAUSES])
def test_hidden_cause_is_named_with_its_magnitude(tmp_path, cause, seed):
    baseline, effects, measured = measure(tmp_path, cause, seed)
    result = diagnose_fresh(measured, baseline, report=tmp_path / "report")
    _check_named(result, cause, effects)
    written = json.loads((tmp_path / "report" / "diagnosis.json").read_text())
    assert written["cause"] == cause
    extended = load_parameter_set(tmp_path / "report" / "extended_model.yaml")
    assert extended.channel() is not None
    assert (tmp_path / "report" / "report.md").read_text().count("![") == 3


def _check_pair(result: dict, effects: list[dict]) -> None:
    """Both hidden causes named, with their shares of the mismatch adding up to the pair's."""
    named = [c["cause"] for c in result["causes"]]
    assert sorted(named) == sorted(e["cause"] for e in effects), (named, result["ranking"][:2], result["pairs"][:2])
    assert result["cause"] == PAIR_SEPARATOR.join(named) and result["explained"] in ("full", "partial")
    assert result["heldout_error_after"] <= 0.5 * result["heldout_error_before"]
    shares = [c["share_explained"] for c in result["causes"]]
    assert sum(shares) == pytest.approx(result["share_explained"]) and min(shares) >= 0.0
    truth = {k: v for e in effects for k, v in e.items() if k != "cause"}
    for cause in result["causes"]:
        for name, fitted in cause["parameters"].items():
            assert abs(fitted["value"] - truth[name]) <= max(4.0 * fitted["std"], 0.25 * abs(truth[name])), \
                (name, fitted, truth[name])


@pytest.mark.slow   # two minutes on 2 cores: the pair stage runs after the screening
@pytest.mark.parametrize("seed", SEEDS)
def test_two_hidden_causes_are_both_named(tmp_path, seed):
    baseline, effects, measured = measure(tmp_path, PAIR, seed)
    result = diagnose_fresh(measured, baseline, report=tmp_path / "report")
    _check_pair(result, effects)
    # the extended set is the baseline with both causes at their fitted values; the report names both
    extended = load_parameter_set(tmp_path / "report" / "extended_model.yaml")
    fitted = {k: v["value"] for c in result["causes"] for k, v in c["parameters"].items()}
    a, b = (CAUSES[c["cause"]] for c in result["causes"])
    expected = b.apply(a.apply(load_parameter_set(baseline), fitted), fitted)
    assert extended.model == expected.model and extended.channel() == expected.channel()
    assert extended.effects_si() == expected.effects_si()
    report = (tmp_path / "report" / "report.md").read_text()
    assert all(f"**{c['cause']}**" in report for c in result["causes"]) and "Second stage" in report


def test_pair_shares_add_up_and_split_hidden_effects_alike():
    floor = 0.01
    # one cause alone explains everything the pair does: it takes the whole share
    a, b = pair_shares(0.2, [0.01, 0.2], 0.01, floor)
    assert a == pytest.approx(1.0) and b == pytest.approx(0.0)
    # two effects that hide each other (neither explains anything alone) share the whole alike
    a, b = pair_shares(0.2, [0.2, 0.2], 0.01, floor)
    assert a == pytest.approx(0.5) and b == pytest.approx(0.5)
    # in general: the shares add up to the pair's, 1 − excess_after² / excess_before²
    a, b = pair_shares(0.1, [0.05, 0.08], 0.02, floor)
    assert a + b == pytest.approx(1.0 - (0.02 ** 2 - floor ** 2) / (0.1 ** 2 - floor ** 2)) and a > b > 0.0


@pytest.mark.parametrize("seed", SEEDS)
def test_noise_alone_names_no_cause(tmp_path, seed):
    baseline, _, measured = measure(tmp_path, "none", seed)
    result = diagnose_fresh(measured, baseline)
    assert result["cause"] == "none", result["ranking"][:3]
    assert result["location"] is None and result["causes"] == [] and result["explained"] == "full"


@pytest.mark.slow   # 85 s on 2 cores
def test_backlash_outside_the_catalogue_is_unexplained(tmp_path):
    baseline, _, measured = measure(tmp_path, "backlash", SEEDS[0])
    result = diagnose_fresh(measured, baseline)
    assert result["cause"] == "unexplained", result["ranking"][:3]
    assert result["heldout_error_before"] > 0.02


def test_broad_relaxation_branches_follow_the_power_law():
    """The Prony series relaxes as k1·t^−α from 10 ms to 100 s within 5 %, for every order drawn."""
    t = np.logspace(-2, 2, 9)
    for alpha in (0.1, 0.25, 0.4):
        k, c = broad_relaxation_branches(k1=100e3, alpha=alpha)
        modulus = (k[None, :] * np.exp(-t[:, None] / (c / k)[None, :])).sum(axis=1)
        np.testing.assert_allclose(modulus, 100e3 * t ** -alpha, rtol=0.05)


@pytest.mark.parametrize("tau_end_s", [10.0, 100.0, 1000.0])
def test_a_terminal_time_keeps_the_power_laws_rate_well_below_it_and_relaxes_fully_beyond(tau_end_s):
    """Cut off at τ_end: at τ_end/1000 the modulus falls at the power law's rate, −α·k1·t^(−α−1),
    within 1 %; at 10 τ_end less than 1 % of the uncut spectrum's modulus is left; no branch without
    stiffness; ∞ is the uncut spectrum, bit for bit."""
    for alpha in (0.1, 0.25, 0.5):
        k, c = broad_relaxation_branches(100e3, alpha, tau_end_s)
        uncut_k, uncut_c = broad_relaxation_branches(100e3, alpha)
        assert (k > 0.0).all() and len(k) <= len(uncut_k)
        modulus = lambda t, k=k, c=c: float((k * np.exp(-t / (c / k))).sum())
        t = tau_end_s / 1000.0
        rate = -float((k / (c / k) * np.exp(-t / (c / k))).sum())
        assert rate == pytest.approx(-alpha * 100e3 * t ** (-alpha - 1.0), rel=0.01)
        assert modulus(10 * tau_end_s) < 0.01 * float((uncut_k * np.exp(-10 * tau_end_s / (uncut_c / uncut_k))).sum())
        infinite = broad_relaxation_branches(100e3, alpha, math.inf)
        assert all(np.array_equal(a, b) for a, b in zip(infinite, (uncut_k, uncut_c)))


def test_mullins_first_loading_is_the_virgin_curve_and_reloading_is_softer():
    ch = load_parameter_set("fig5_9_progressive").channel("elastic")
    virgin = ExtendedBank([ch]).run(np.linspace(0, 2e-3, 50), 0.01)[:, 0]
    bank = ExtendedBank([ch], [Effects(mullins=0.2)])
    first = bank.run(np.linspace(0, 2e-3, 50), 0.01)[:, 0]
    np.testing.assert_allclose(first, virgin, rtol=1e-12)
    back = bank.run(np.linspace(2e-3, 1e-3, 26), 0.01)[-1, 0]
    # η = 1 − μ(1 − x/x_max) at half the largest deflection: 0.9 of the elastic force.
    assert back == pytest.approx(0.9 * ch.K0 * 1e-3, rel=1e-9)


def _reloaded(effects, start_m: float, end_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(deflections, forces, tangents) of the elastic channel of fig5_9_progressive with ``effects``
    first loaded to ``start_m`` then moved slowly to ``end_m`` (the law's own, and the effects')."""
    ch = load_parameter_set("fig5_9_progressive").channel("elastic")
    bank = ExtendedBank([ch], [effects])
    bank.run(np.linspace(0.0, start_m, 40), 0.01)
    e = np.linspace(start_m, end_m, 201)
    forces, tangents = [], []
    for x in e:
        f, k = bank.step(np.array([x]), 0.01)
        forces.append(f[0])
        tangents.append(k[0])
    return e, np.array(forces), np.array(tangents)


def test_asymmetry_family_adds_a_kink_and_a_progressive_part_on_one_side():
    """F = F_law + K0·(|s|·x + |a|·x|x|/2) on the stiffened side (compression for s, a > 0), the law
    alone on the other; the tangent jumps by |s|·K0 at zero (a kink) and is the force's slope."""
    ch = load_parameter_set("fig5_9_progressive").channel("elastic")
    s, a = 0.08, 0.1e3          # fraction, and fraction per metre (0.1 per mm)
    e, law, _ = _reloaded(Effects(), 0.0, -2e-3)
    _, both, tangent = _reloaded(Effects(asymmetry=a, asymmetry_step=s), 0.0, -2e-3)
    np.testing.assert_allclose(both - law, ch.K0 * (s * e + a * e * np.abs(e) / 2.0), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(tangent[1:-1], np.gradient(both, e)[1:-1], rtol=2e-3)
    _, tension, _ = _reloaded(Effects(asymmetry=a, asymmetry_step=s), 0.0, 2e-3)
    _, tension_law, _ = _reloaded(Effects(), 0.0, 2e-3)
    np.testing.assert_allclose(tension, tension_law, rtol=1e-12)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_asymmetry_step_spread_over_a_width_rises_linearly_and_keeps_the_kinks_slope_beyond(sign):
    """A step s spread over w: towards the stiffened side (u = ∓x), the extra tangent is
    |s|·K0·(1/2 + u/w) within |u| < w/2, |s|·K0 beyond and 0 before; the extra force its integral
    from zero, −s·K0·(u − w/8) beyond (the kink's, shifted by a constant) and s·K0·w/8 before."""
    ch = load_parameter_set("fig5_9_progressive").channel("elastic")
    s, w = 0.08 * sign, 0.4e-3
    toward = -sign        # deflection direction of the stiffened side
    e, law, law_tangent = _reloaded(Effects(), 0.0, 1.5e-3 * toward)
    _, spread, tangent = _reloaded(Effects(asymmetry_step=s, asymmetry_step_width=w), 0.0, 1.5e-3 * toward)
    u = e * toward
    fraction = np.clip(0.5 + u / w, 0.0, 1.0)
    np.testing.assert_allclose(tangent - law_tangent, abs(s) * ch.K0 * fraction, rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(tangent[1:-1], np.gradient(spread, e)[1:-1], rtol=2e-3)
    beyond = u > w / 2
    np.testing.assert_allclose((spread - law)[beyond], -s * ch.K0 * (u[beyond] - w / 8.0), rtol=1e-9)
    # the same law loaded the other way: the soft side, a constant w/8 of the step's force before it
    _, back, _ = _reloaded(Effects(asymmetry_step=s, asymmetry_step_width=w), 0.0, -1.5e-3 * toward)
    e_back, back_law, _ = _reloaded(Effects(), 0.0, -1.5e-3 * toward)
    before = e_back * toward < -w / 2
    np.testing.assert_allclose((back - back_law)[before], s * ch.K0 * w / 8.0, rtol=1e-9)


@pytest.mark.parametrize("power", [1.0, 1.5, 2.0, 3.0])
def test_asymmetry_progressive_part_grows_as_its_power(power):
    """With power n the extra tangent is |a|·K0·r·(|x|/r)^n (r = 1 mm: ``a`` keeps its meaning, the
    tangent fraction per mm at 1 mm) and the extra force its integral, |a|·K0·r·(|x|/r)^n·x/(n + 1)."""
    ch = load_parameter_set("fig5_9_progressive").channel("elastic")
    a, r = 0.1e3, 1e-3
    e, law, law_tangent = _reloaded(Effects(), 0.0, -2e-3)
    _, stiffer, tangent = _reloaded(Effects(asymmetry=a, asymmetry_power=power), 0.0, -2e-3)
    grown = a * r * (np.abs(e) / r) ** power
    np.testing.assert_allclose(stiffer - law, ch.K0 * grown * e / (power + 1.0), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(tangent - law_tangent, ch.K0 * grown, rtol=1e-9, atol=1e-6)
    # at 1 mm every power adds the same tangent fraction a·r
    assert np.interp(-1e-3, e[::-1], (tangent - law_tangent)[::-1]) == pytest.approx(ch.K0 * a * r, rel=1e-6)


def test_a_parameter_set_refuses_an_asymmetry_power_out_of_range():
    assert effects_to_si({"asymmetry": 0.1, "asymmetry_power": 2.0}).asymmetry_power == 2.0
    for bad in (0.5, 6.0, float("nan")):
        with pytest.raises(InputError, match="asymmetry_power"):
            effects_to_si({"asymmetry": 0.1, "asymmetry_power": bad}, source="set.yaml")
    # the kink's width in mm (deg for a rotation), never negative
    assert effects_to_si({"asymmetry_step": 0.1, "asymmetry_step_width": 0.5}).asymmetry_step_width == pytest.approx(5e-4)
    with pytest.raises(InputError, match="asymmetry_step_width"):
        effects_to_si({"asymmetry_step": 0.1, "asymmetry_step_width": -0.2}, source="set.yaml")


@pytest.mark.parametrize("shape", [1.0, 2.5, 4.0])
def test_mullins_recovery_is_the_power_of_its_shape(shape):
    """Reloaded from x_max/10 to x_max: η = 1 − μ(1 − (x/x_max)^p) of the virgin force, and the
    tangent the force's slope (what the implicit stepping needs)."""
    mu, top = 0.2, 2e-3
    _, soft, tangent = _reloaded(Effects(mullins=mu, mullins_shape=shape), top, top / 10)
    e_back, virgin_back, _ = _reloaded(Effects(), top, top / 10)
    eta = 1.0 - mu * (1.0 - (e_back / top) ** shape)
    np.testing.assert_allclose(soft, eta * virgin_back, rtol=1e-9)
    np.testing.assert_allclose(tangent[1:-1], np.gradient(soft, e_back)[1:-1], rtol=5e-3)


def test_a_parallel_dashpot_dissipates_pi_c_omega_a_squared_a_cycle():
    """truth_forms' viscous_parallel: over a sine of amplitude A at ω the dashpot c adds a loop of
    area π·c·ω·A² (the Kelvin–Voigt element's closed form), and no force at rest."""
    c_mm, amplitude, omega = 0.7, 1.5e-3, 2.0 * np.pi * 3.0
    dt = 2.0 * np.pi / omega / 4000
    t = np.arange(0.0, 2.0 * np.pi / omega + dt / 2, dt)
    x = amplitude * np.sin(omega * t)
    force = FORMS["viscous_parallel"].change(x, np.zeros_like(x), 5e5, {"dashpot": c_mm}, {}, dt, 0.0)
    assert _loop_area(x, force) == pytest.approx(np.pi * c_mm * 1e3 * omega * amplitude ** 2, rel=1e-3)
    held = FORMS["viscous_parallel"].change(np.full(10, amplitude), np.ones(10), 5e5, {"dashpot": c_mm}, {}, dt, 0.0)
    assert np.array_equal(held, np.ones(10))


def _cycled(change, amplitude_m: float, cycles: int = 2, per_cycle: int = 4000) -> tuple[np.ndarray, np.ndarray]:
    """(deflection, force) of the last of ``cycles`` sine cycles of ``amplitude_m`` through ``change``
    (deflections [m] -> forces [N]), started from rest at zero deflection."""
    x = amplitude_m * np.sin(2.0 * np.pi * np.arange(cycles * per_cycle + 1) / per_cycle)
    force = change(x)
    return x[-per_cycle - 1:], force[-per_cycle - 1:]


def _loop_area(x: np.ndarray, force: np.ndarray) -> float:
    """∮F dx [J] by the trapezoidal rule: positive for a loop that dissipates."""
    return float(np.sum(0.5 * (force[1:] + force[:-1]) * np.diff(x)))


def test_a_slipping_interface_adds_the_elastoplastic_loop_and_its_tangent():
    """elastokin.bushings.effects' slip element (a spring k_s in series with a slider F_s, in parallel with the
    law): cycled between ±A it adds the parallelogram of area 4·F_s·(A − F_s/k_s), whatever the rate;
    the tangent is k_s while it sticks, 0 while it slips."""
    ch = load_parameter_set("fig5_9_progressive").channel("elastic")
    fs, fraction, amplitude = 8.0, 0.3, 0.5e-3
    si = effects_to_si({"slip_force": fs, "slip_stiffness": fraction})
    assert (si.slip_force, si.slip_stiffness) == (fs, fraction) and si.active
    assert not effects_to_si({"slip_stiffness": fraction}).active
    ks = fraction * ch.K0
    for period_s in (0.5, 50.0):
        run = lambda effects: (lambda x: ExtendedBank([ch], [effects]).run(x, period_s / 4000)[:, 0])
        x, slipping = _cycled(run(si), amplitude)
        _, law = _cycled(run(Effects()), amplitude)
        assert _loop_area(x, slipping) - _loop_area(x, law) == pytest.approx(4 * fs * (amplitude - fs / ks), rel=2e-3)
    e, force, tangent = _reloaded(si, amplitude, -amplitude)
    _, law, law_tangent = _reloaded(Effects(), amplitude, -amplitude)
    down = amplitude - e   # from the top (at the limit: unloading sticks), the first 2F_s/k_s stick
    sticks = down < 2 * fs / ks - 1e-7
    assert sticks[0] and sticks.sum() > 10
    np.testing.assert_allclose((tangent - law_tangent)[sticks], ks, rtol=1e-12)
    np.testing.assert_allclose((tangent - law_tangent)[down > 2 * fs / ks + 1e-7], 0.0, atol=1e-9)
    np.testing.assert_allclose((force - law)[-1], -fs, rtol=1e-12)
    # mounted on a preload far beyond F_s/k_s, the interface is clamped unloaded there: ±k_s·δ either way
    delta = 0.25 * fs / ks
    for sign in (1.0, -1.0):
        moved = [ExtendedBank([ch], [replace(fx, preload=1e-3)]).step(np.array([sign * delta]), 0.01)[0][0]
                 for fx in (si, Effects())]
        assert moved[0] - moved[1] == pytest.approx(sign * ks * delta, rel=1e-9)


@pytest.mark.parametrize("name", ["fig5_9_progressive", "fig5_6", "fig5_8", "linear", "curve"])
def test_a_stiffness_scale_multiplies_every_force_of_the_law(name):
    """The stiffness family (a harder or softer rubber): along any history (a virgin loading, minor
    loops, a fast sine, a hold), the scaled law's force is the factor times the baseline's, to the
    ladder solver's tolerance, for a ladder with a progressive elastic law, an STS, an RT, a linear
    law with a dashpot and a Maxwell branch and a tabulated curve; its node deflections unchanged."""
    base = {"linear": ParameterSet("linear", "linear", "translation",
                                   {"K0": 300.0, "C": 0.5, "maxwell_k": [80.0], "maxwell_c": [8.0]}, "test"),
            "curve": ParameterSet("curve", "curve", "translation",
                                  {"curve": [[-2.0, -900.0], [0.0, 0.0], [1.0, 350.0], [2.0, 1100.0]]}, "test")
            }.get(name) or load_parameter_set(name)
    scale = 1.0 / 1.17 if name == "fig5_8" else 1.21
    scaled = CAUSES["stiffness"].apply(base, {"stiffness_scale": scale})
    t = np.linspace(0.0, 6.0, 6001)
    e = 1e-3 * (2.5 * np.sin(0.5 * np.pi * t) * (t < 4.0) + 0.3 * np.sin(2 * np.pi * 5.0 * t) * (t > 2.0) * (t < 4.0))
    e = np.where(t >= 4.0, e[np.searchsorted(t, 4.0) - 1], e)   # held from 4 s
    forces = simulate_record([base.channel(), scaled.channel()], t, e)
    assert np.abs(forces[:, 0]).max() > 200.0
    np.testing.assert_allclose(forces[:, 1], scale * forces[:, 0], rtol=1e-6, atol=1e-3)


def test_dahl_friction_closes_its_loop_at_fc_tanh():
    """truth_forms' dahl_parallel, cycled between ±A: the force at the top of the loop is
    F_c·tanh(σA/F_c) and the loop's area 2·(2A·F_c − (F_c + F_top)·F_c/σ·(1 − e^{−2σA/F_c}))
    (dF/dx = σ(1 − F/F_c·sgn ẋ) integrated along each branch)."""
    k0, fc, fraction = 5e5, 12.0, 0.3
    sigma = fraction * k0
    amplitude = 2.0 * fc / sigma          # σA/F_c = 2: the loop's corners are round
    change = lambda x: FORMS["dahl_parallel"].change(x, np.zeros_like(x), k0, {"dahl_force": fc,
                                                     "dahl_stiffness": fraction}, {}, 1e-3, 0.0)
    x, force = _cycled(change, amplitude)
    top = fc * np.tanh(sigma * amplitude / fc)
    assert force[np.argmax(x)] == pytest.approx(top, rel=1e-4)
    decay = 1.0 - np.exp(-2.0 * sigma * amplitude / fc)
    area = 2.0 * (2.0 * amplitude * fc - (fc + top) * fc / sigma * decay)
    assert _loop_area(x, force) > 0.0
    assert _loop_area(x, force) == pytest.approx(area, rel=1e-3)
    assert np.array_equal(FORMS["dahl_parallel"].change(x, force, k0, {"dahl_force": 0.0, "dahl_stiffness": 0.3},
                                                        {}, 1e-3, 0.0), force)


def test_two_node_heating_softens_as_the_core_heat_of_the_mean_power():
    """truth_forms' heating_two_node through a dashpot law F = c·ẋ cycled at ω for whole cycles
    (where the secant's stored energy is zero): the core holds the heat of the mean power
    P = c·ω²·A²/2 fed through the network (Q̇ = R·Q + (P, 0)), and the force falls by exp(−κ·Q_core)."""
    c, amplitude, omega, kappa = 2e4, 5e-3, 2.0 * np.pi * 2.0, 1.0
    core_tau, shell_tau, duration = 20.0, 300.0, 30.0
    dt = 2.0 * np.pi / omega / 400
    t = np.arange(0.0, duration + dt / 2, dt)
    x, law = amplitude * np.sin(omega * t), c * amplitude * omega * np.cos(omega * t)
    values = {"heating_exp": kappa, "core_tau_s": core_tau, "shell_tau_s": shell_tau}
    softened = FORMS["heating_two_node"].change(x, law, 1.0, values, {}, dt, 0.0)
    rates = np.array([[-1 / core_tau, 1 / core_tau], [1 / core_tau, -1 / core_tau - 1 / shell_tau]])
    power = c * omega ** 2 * amplitude ** 2 / 2.0
    w, v = np.linalg.eig(rates)   # Q(T) = V·diag((e^{λT} − 1)/λ)·V⁻¹·(P, 0)
    core = float((v @ np.diag(np.expm1(w * t[-1]) / w) @ np.linalg.solve(v, [power, 0.0]))[0].real)
    ratio = softened[-1] / law[-1]
    assert ratio < 0.9    # the test sees the softening, not a rounding
    assert ratio == pytest.approx(np.exp(-kappa * 1e-3 * core), rel=2e-3)


def test_box_relaxation_falls_by_a_decades_branches_each_decade_and_relaxes_at_rest():
    """truth_forms' relaxation_box: after a step x0 the force falls, each decade of time well inside
    the box, by the stiffness of the branches in a decade times x0 (a box spectrum's force is linear
    in log t); a rest at zero deflection before the next test relaxes each branch from its force
    less k·x0 (what the jump back to zero adds) by e^{−t/τ}."""
    k_mm, tau_max, x0, dt = 100.0, 300.0, 1e-3, 1e-3
    values = {"box_k": k_mm, "box_tau_max_s": tau_max}
    t = np.arange(0.0, 10.0 + dt / 2, dt)
    x = np.where(t > 0.0, x0, 0.0)
    state: dict = {}
    force = FORMS["relaxation_box"].change(x, np.zeros_like(x), 1.0, values, state, dt, 0.0)
    taus = box_taus(tau_max)
    assert taus[0] == pytest.approx(BOX_TAU_MIN_S * 10 ** (0.5 / BOX_PER_DECADE)) and taus[-1] < tau_max
    per_decade = k_mm * 1e3 * BOX_PER_DECADE / len(taus) * x0
    at = lambda s: force[int(round(s / dt))]
    for start in (0.1, 1.0):
        assert at(start) - at(10 * start) == pytest.approx(per_decade, rel=0.06)
    # each branch after the step over one sample (dx/dt constant within it), then held
    k = k_mm * 1e3 / len(taus)
    held = k * x0 * taus / dt * (1 - np.exp(-dt / taus)) * np.exp(-(t[-1] - dt) / taus)
    np.testing.assert_allclose(force[-1], held.sum(), rtol=1e-9)
    rest = 5.0
    after = FORMS["relaxation_box"].change(np.zeros(3), np.zeros(3), 1.0, values, state, dt, rest)
    expected = ((held - k * x0) * np.exp(-(rest + dt) / taus)).sum()
    assert after[0] == pytest.approx(expected, rel=1e-9)
    assert after[0] < 0.0    # the branches' memory of the step, pulling back after the jump to zero


def _named_as_family(result: dict, form: str) -> str:
    """AssertionError unless a drawn ``form`` is named as its family, or reported alike with the
    cause named ("reported alike"); a cause named over a rival that the held-out tests preferred was
    the better of the two scored on both halves."""
    family = FORMS[form].family
    first = result["ranking"][0]
    if result["cause"] == family and first["cause"] != family:
        named = next(c for c in result["ranking"] if c["cause"] == family)
        assert named["two_fold_error"] < first["two_fold_error"], result["ranking"][:3]
    if result["cause"] != family and family in [a["cause"] for a in result["alike"]]:
        return "reported alike"
    assert result["cause"] == family, result["ranking"][:3]
    return ""


#: Other forms drawn here, in the slow stage only for the default suite's time (all of
#: truth_forms.FORMS in the slow suite's rates too: the two-node heating's and the box spectrum's
#: diagnoses take a minute each on 2 cores, and so do Dahl's friction and the dashpot alone; the
#: asymmetry's forms and Ogden-Roxburgh's softening half a minute each). The default suite keeps one
#: other form, the cubic asymmetry, in its own test below.
DEFAULT_FORMS = [pytest.param(f, marks=pytest.mark.slow) for f in
                 ("asymmetry_smooth_kink", "asymmetry_exponential", "mullins_ogden", "dahl_parallel", "viscous_parallel")]


@pytest.mark.parametrize("form", DEFAULT_FORMS)
def test_another_form_of_a_family_is_named_as_the_family(tmp_path, form):
    """A form the catalogue does not write (truth_forms: a kink smoothed over a width, an exponential
    stiffening, Ogden-Roxburgh softening, Dahl's friction, a dashpot alone) is named as its family,
    explained at least in part, with most of the mismatch beyond the noise removed (not a confident
    other cause)."""
    baseline, _, measured = measure(tmp_path, form, SEEDS[0])
    result = diagnose_fresh(measured, baseline)
    _named_as_family(result, form)
    assert result["explained"] in ("full", "partial")
    # most of the mismatch beyond the noise removed (a weak effect leaves an error near the noise's)
    excess = lambda e: max(e ** 2 - result["noise_floor"] ** 2, 0.0) ** 0.5
    assert excess(result["heldout_error_after"]) <= 0.5 * excess(result["heldout_error_before"])


def test_a_stiffening_the_held_out_tests_cannot_place_is_judged_on_both_halves(tmp_path):
    """One side stiffening as the square of the deflection (truth_forms, written apart from the
    family's power 2): on the held-out tests a preload on the progressive law fits as well; the
    diagnosis scores both on both halves, each fitted on the other, and names the family, or reports
    the two alike with the shipped programme that would separate them."""
    baseline, _, measured = measure(tmp_path, "asymmetry_cubic", SEEDS[0])
    result = diagnose_fresh(measured, baseline, report=tmp_path / "report")
    _named_as_family(result, "asymmetry_cubic")
    for rival in result["alike"]:
        sep = rival["separated_by"]
        assert sep["programme"] in [p.stem for p in Path(sep["file"]).parent.glob("*.yaml")]
        assert sep["separates"] == (sep["difference"] >= 0.4843)
        assert rival["cause"] in (tmp_path / "report" / "report.md").read_text().split("\n")[2]


@pytest.mark.slow
@pytest.mark.parametrize("cause", BENCH_CAUSES + ["none", PAIR, *FORMS, *OUTSIDE])
def test_success_rate_over_many_seeds(tmp_path, record_property, cause):
    """At least OWN_FORM_SUCCESS_RATE of 20 draws per catalogue cause diagnosed right (and of clean
    draws naming nothing), MIN_SUCCESS_RATE per other form or outside effect, and
    both causes of MIN_PAIR_SUCCESS_RATE of 20 pairs; a form the catalogue does not write
    (truth_forms.FORMS) named as its family; an effect outside the catalogue (backlash) never
    presented as the whole story: unexplained, explained in part, or too small to see ("none");
    the tally goes to the run's summary."""
    def attempt(case: Path, seed: int) -> str | None:
        baseline, effects, measured = measure(case, cause, seed)
        result = diagnose_fresh(measured, baseline)
        if cause in FORMS:
            return _named_as_family(result, cause)
        elif cause in OUTSIDE:
            assert result["cause"] in ("unexplained", "none") or result["explained"] == "partial", result["ranking"][:3]
            return result["cause"] if result["cause"] in ("unexplained", "none") else "partial"
        elif cause == "none":
            assert result["cause"] == "none", result["ranking"][:3]
        elif cause == PAIR:
            _check_pair(result, effects)
        else:
            _check_named(result, cause, effects)

    # the 95 % for a catalogue cause in its own form (and clean data), measured 20/20 each;
    # MIN_SUCCESS_RATE for other forms and effects outside the catalogue
    own = cause in CAUSES or cause == "none"
    assert_success_rate(cause, SLOW_SEEDS, tmp_path, attempt, record_property,
                        MIN_PAIR_SUCCESS_RATE if cause == PAIR else OWN_FORM_SUCCESS_RATE if own else MIN_SUCCESS_RATE)


def test_programmes_continue_the_history_as_one_replay_of_it_and_each_would():
    """Replay.continued plays the history and the rest once and each programme from a copy of the
    state they left: the forces are bit for bit those of one replay of history, rest and programme,
    for parts whose state carries over (Mullins softening, heat, a slipping interface, a preload)."""
    t = np.arange(0.0, 2.0, 1e-3)
    history = 1e-3 * np.sin(2 * np.pi * 3 * t) * (1 + t)
    replay = Replay(history, np.full(len(t), 1e-3), np.zeros(len(t), dtype=int), np.zeros(len(t)), ["one"],
                    np.ones(1))
    base = load_parameter_set("fig5_9_progressive")
    models = [base, replace(base, effects={"mullins": 0.3, "heating": 2.0, "heating_tau_s": 20.0}),
              replace(base, effects={"slip_force": 20.0, "slip_stiffness": 0.5, "preload": 1.0})]
    signals = [(np.arange(0.0, 0.5, 2e-3), 5e-4 * np.sin(np.arange(0.0, 0.5, 2e-3) * 20)),
               (np.arange(0.0, 1.0, 5e-3), np.full(200, 8e-4))]
    continued = replay.continued(models, REST_BEFORE_S, signals)
    n = math.ceil(REST_BEFORE_S / REST_STEP_S - 1e-9)
    for (t_s, e_m), forces in zip(signals, continued):
        whole = Replay(np.r_[history, np.zeros(n), e_m], np.r_[replay.dts, np.full(n, REST_BEFORE_S / n),
                       sample_steps(t_s)], np.zeros(len(t) + n + len(t_s), dtype=int), np.zeros(len(t) + n + len(t_s)),
                       ["one"], np.ones(1))
        assert forces.shape == (3, len(t_s))
        assert np.array_equal(forces, whole.simulate(models)[:, -len(t_s):])
    assert not np.allclose(continued[1][0], continued[1][1], rtol=0.01)   # the effects' state shows


def test_the_separating_programme_is_the_one_where_the_rivals_differ_most():
    """bench_alike.separations: every programme played after the part's history and a rest, the
    largest RMS difference in units of the load cell's noise, each prediction's mean removed; the
    noise in newtons is the records' median."""
    t = np.linspace(0.0, 1.0, 101)
    programmes = [Programme(n, Path(f"{n}.yaml"), TimeSeries("sine", t, e))
                  for n, e in (("offset", 0 * t), ("apart", np.sin(6 * t)), ("close", 0.1 * np.sin(6 * t)))]
    played = []

    class History:
        def continued(self, models, rest_s, signals):
            played.append(rest_s)
            return [np.vstack([m(e_m) for m in models]) for _, e_m in signals]

    best, rival = (lambda e: 0 * e), (lambda e: 3.0 + 2.0 * e)   # the offset is a zero error: no difference
    (sep,) = separations(History(), [best, rival], 2.0, programmes)
    d = 2.0 * np.sin(6 * t) / 2.0
    assert sep.test == "apart" and sep.path == Path("apart.yaml")
    assert sep.difference == pytest.approx(np.sqrt(np.mean((d - d.mean()) ** 2)))
    assert played == [REST_BEFORE_S]
    assert separations(History(), [best, rival], 2.0, []) == [None]
    assert load_cell_noise_n(np.array([0.01, 0.02, 0.04]), np.array([100.0, 100.0, 10.0])) == pytest.approx(1.0)
    # every shipped time-series programme is offered, the frequency sweep is not
    offered = {p.name for p in extra_programmes()}
    assert {"relaxation", "firtree", "sine_10hz"} <= offered and "sweep" not in offered
