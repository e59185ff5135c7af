"""K&C-level diagnosis: a cause hidden in the car at a random place and magnitude (drawn from a seed
among the places the K&C campaign sees, with random noise and zero errors) must be named with its
place, and the held-out model error (the RMS error in excess of the measurement noise) cut by at
least half; noise alone gives no cause; backlash (outside the catalogue) is reported as unexplained.
The diagnosis runs in a fresh process on a copied directory. Also: the extended vehicle file, the
in-memory runner and the CLI's level checks."""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.stats import norm

from elastokin.bushings.parameter_sets import load_parameter_set
from tests.damage_helpers import damaged_kc_dataset
from tests.diagnosis_helpers import (MIN_PAIR_SUCCESS_RATE, MIN_SUCCESS_RATE, OWN_FORM_SUCCESS_RATE, PAIR, SLOW_SEEDS,
                                     assert_success_rate)
from elastokin.vehicle.model.file_overrides import vehicle_with
from elastokin.vehicle.model.vehicle_file import load_vehicle, with_extensions
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.core.errors import InputError
from elastokin.diagnosis.kc_catalogue import (OBSERVABLE, THROUGH_A_RIG, Hypothesis, draw, drawn_ways, extended_vehicle,
                                              extended_vehicle_yaml, locations, parameters)
from elastokin.cluster.executor import LOCAL, SerialExecutor, executor
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.diagnosis.catalogue import PAIR_SEPARATOR, Parameter
from elastokin.diagnosis.kc_alike import alike, separations
from elastokin.diagnosis.kc_diagnosis import _best_per_place, _second_stage, diagnose_kc, hypotheses
from elastokin.diagnosis.kc_fits import (Candidate, fit, fit_pair, halfway, nominal, separation, significant,
                                    verify)
from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.kc_layout import Layout, Test, run_sets
from elastokin.diagnosis.kc_rig_mechanics import BY_KEY, RIG
from elastokin.diagnosis.verdict import PARAMETER_PENALTY, Separation, pair_named, split, told_apart
from elastokin.diagnosis.rig_chain import DRAWN, GROUPS, draw_chain, draw_rig
from elastokin.diagnosis.virtual_kc_rig import DEFAULT_SCENARIOS, measure_kc, parse_kc_truth
from tests.test_rig_chain import WHITE   # the white noise of each measured quantity: a drawn chain's scale
from tests.test_rig_export import _import_all
from elastokin.cli import main as cli
from elastokin.vehicle.scenarios.channels import CORNER_TAGS
from elastokin.presentation.kc_report import _candidate, _parameters, summary, verdict_sentence, write_report
from elastokin.recordings.recorder import run_scenario, simulate
from elastokin.recordings.kc_dataset import read_kc_dataset
from elastokin.recordings.run_reader import DamagedRecording, load_run

KC_CAUSES = sorted(c for c in OBSERVABLE if c != "backlash")
#: The default suite diagnoses one draw (about 2 min); the slow suite SLOW_SEEDS per cause.
SEED = int(os.environ.get("VSIM_TEST_SEED", "0"))


# -- the pieces ----------------------------------------------------------------------------------
def test_extended_vehicle_file_reads_back_as_the_extended_vehicle(tmp_path):
    v = load_vehicle()
    hs = [Hypothesis("coupling", ("e1_rear", "x", "z"), {"stiffness": 70.0}),
          Hypothesis("mullins", ("e1_front", "y"), {"mullins": 0.2}),
          Hypothesis("broad_relaxation", ("e1_rear", "y"), {"k1": 50.0, "alpha": 0.2}),
          Hypothesis("strut_friction", (), {"strut_friction": 150.0}),
          Hypothesis("beam_torsion", (), {"beam_torsion_scale": 1.4})]
    path = tmp_path / "extended.yaml"
    path.write_text(extended_vehicle_yaml(v, hs, "fitted by a test"))
    written, expected = load_vehicle(path), extended_vehicle(v, hs)
    assert written.front.strut_friction == (150.0, 150.0) and written.rear.beam_torsion_scale == 1.4
    for a, b in zip(written.bushings, expected.bushings):
        assert a.coupling == b.coupling
        for d in "xyz":
            assert a.directions[d].channel() == b.directions[d].channel()
            assert a.directions[d].effects_si() == b.directions[d].effects_si()
    # the hypotheses changed what they name and nothing else
    base = {b.name: b for b in v.bushings}
    assert written.bushings[0].directions["y"].channel() == base["e1_front"].directions["y"].channel()
    assert written.bushings[0].directions["y"].effects_si().mullins == 0.2
    assert written.bushings[0].directions["z"].effects_si() == base["e1_front"].directions["z"].effects_si()
    assert len(written.bushings[2].directions["y"].channel().maxwell_k) == \
        len(base["e1_rear"].directions["y"].channel().maxwell_k) + 15


def test_a_law_replaced_by_a_set_reads_as_that_set_and_quantities_are_checked():
    v = load_vehicle()
    stvs = load_parameter_set("fig5_9")
    w = with_extensions(v, laws={"e1_rear.z": stvs})
    assert {b.name: b for b in w.bushings}["e1_rear"].directions["z"].channel() == stvs.channel()
    rotation = replace(stvs, quantity="rotation")
    with pytest.raises(InputError, match="needs a translation set") as err:
        with_extensions(v, laws={"e1_rear.z": rotation})
    assert err.value.key == "laws.e1_rear.z"


def test_places_and_draws():
    v = load_vehicle()
    assert ("e1_rear", "z") in locations(v, "viscoelasticity_missing")      # an STS: no dampers
    assert ("e2_front", "x") not in locations(v, "viscoelasticity_missing")  # an STVS already
    assert locations(v, "preload") == []                                     # no nonlinear elastic law
    for cause in OBSERVABLE:
        a, b = draw(cause, np.random.default_rng(7)), draw(cause, np.random.default_rng(7))
        assert a == b and a.location in OBSERVABLE[cause]
        assert a.location in locations(v, cause) or cause == "backlash"
        for p in parameters(cause):
            lo, hi = p.draw
            x = abs(a.values[p.name])
            assert lo <= x <= hi or (p.factor and lo <= 1 / x <= hi)
        first = parameters(cause)[0]
        for seed in range(50):   # the first parameter in the observable part of its range at its place
            h = draw(cause, np.random.default_rng(seed))
            x = abs(h.values[first.name])
            x = max(x, 1 / x) if first.factor else x
            low = max(first.draw[0], OBSERVABLE[cause][h.location])
            assert low * (1 - 1e-12) <= x <= first.draw[1] * (1 + 1e-12), (h, low)
    # through a rig's errors: fewer places, each from its floor without them or a larger one, drawn
    # there alone, within the range, every way draw gives
    for cause, places in THROUGH_A_RIG.items():
        first = parameters(cause)[0]
        assert set(places) <= set(OBSERVABLE[cause])
        assert all(floor >= OBSERVABLE[cause][where] for where, floor in places.items()), cause
        ways = set()
        for seed in range(20):
            h = draw(cause, np.random.default_rng(seed), THROUGH_A_RIG)
            value = h.values[first.name]
            size = max(value, 1 / value) if first.factor else abs(value)
            low = max(places[h.location], first.draw[0])
            assert h.location in places and low * (1 - 1e-12) <= size <= first.draw[1] * (1 + 1e-12), (h, places)
            ways.add(next(k for k, w in enumerate(drawn_ways(cause, size)) if value == pytest.approx(w, rel=1e-12)))
        assert len(ways) == len(drawn_ways(cause, first.draw[1])), cause   # every way is drawn
    with pytest.raises(KeyError):
        draw(next(c for c in OBSERVABLE if c not in THROUGH_A_RIG), np.random.default_rng(0), THROUGH_A_RIG)
    signs = {math.copysign(1.0, draw("asymmetry", np.random.default_rng(s)).values["asymmetry"]) for s in range(20)}
    assert signs == {1.0, -1.0}
    # a design value off either way, on either axle it can sit in
    rates = [draw("spring_rate", np.random.default_rng(s)) for s in range(20)]
    assert {h.values["spring_rate_scale"] > 1.0 for h in rates} == {True, False}
    assert {h.location for h in rates} == {("front",), ("rear",)} == set(locations(v, "spring_rate"))
    assert locations(v, "anti_roll_bar") == [("front",)] and locations(v, "beam_torsion") == [()]
    # a bushing's stiffness off either way, in a linear direction and in ladder ones; a hypothesis in
    # every translation of every bushing, the linear ones too
    stiff = [draw("stiffness", np.random.default_rng(s)) for s in range(40)]
    assert {h.values["stiffness_scale"] > 1.0 for h in stiff} == {True, False}
    assert {h.location for h in stiff} == set(OBSERVABLE["stiffness"]) >= {("e1_rear", "x"), ("e1_front", "y")}
    assert locations(v, "stiffness") == [(b.name, d) for b in v.bushings for d in ("x", "y", "z")]


def test_the_screening_tries_a_cause_on_each_sign_whose_effect_is_not_odd_in_it():
    """A sided cause and a cross stiffness are screened on both signs at each place, every other cause
    on one; the ranking keeps the better of a cross stiffness's two fits and both sides of a sided cause."""
    v = load_vehicle()
    signs: dict[tuple, set[float]] = {}
    for h in hypotheses(v):
        first = parameters(h.cause)[0]
        signs.setdefault((h.cause, h.location), set()).add(math.copysign(1.0, first.effect(h.values[first.name])))
    for (cause, location), seen in signs.items():
        # a cross stiffness softens both directions it couples (even part), an asymmetry picks its side
        both = cause in ("coupling", "asymmetry", "preload")
        assert seen == ({1.0, -1.0} if both else {1.0}), (cause, location, seen)
    assert {loc for c, loc in signs if c == "coupling"} == set(locations(v, "coupling"))
    with pytest.raises(ValueError, match="needs signed"):   # a fit on one sign's run must be free to take the other
        Parameter("stiffness", "N/mm", (0.0, 500.0), (40.0, 120.0), even_part=True)
    # the ranking names each thing once: a coupling's better fit of its two, both sides of an asymmetry
    hs = [h for h in hypotheses(v) if h.location in (("e1_rear", "x", "z"), ("e1_rear", "x"))
          and h.cause in ("coupling", "asymmetry")]   # asymmetry +, -, coupling +, -
    fitted = [Candidate(h, math.nan, screened_error=e) for h, e in zip(hs, [3.0, 2.0, 2.5, 1.5])]
    kept = _best_per_place(fitted)
    assert sorted(c.screened_error for c in kept) == [c.screened_error for c in kept]
    assert {(c.hypothesis.cause, c.hypothesis.values[parameters(c.hypothesis.cause)[0].name] > 0) for c in kept} \
        == {("coupling", False), ("asymmetry", True), ("asymmetry", False)}, hs


def test_a_screened_hypothesis_is_penalised_for_the_parameters_its_screening_fitted():
    """Two screening fits leaving the same training error score alike, one of a cause whose second
    parameter the screening held where it ran it (a broad relaxation's breadth) and one of a
    single-parameter cause (a stiffness factor): the screening ranks them by that error alone. A fit
    that moved the second parameter too, and a verified candidate, are penalised for two; the rank
    of the same error then goes to the single parameter."""
    place = ("e1_front", "y")
    one = Candidate(Hypothesis("stiffness", place, {"stiffness_scale": 1.05}), math.nan, {"stiffness_scale": 0.01},
                    screened_error=0.8)
    held = Candidate(Hypothesis("broad_relaxation", place, {"k1": 60.0, "alpha": 0.175}), math.nan, {"k1": 5.0},
                     screened_error=0.8)
    assert one.fitted == held.fitted == 1 and one.score == held.score == 0.8 * (1.0 + PARAMETER_PENALTY)
    moved = replace(held, std={"k1": 5.0, "alpha": 0.02})
    assert moved.fitted == 2 and moved.score == pytest.approx(0.8 * (1.0 + 2.0 * PARAMETER_PENALTY))
    for c in (one, held):
        verify([c], [np.zeros((1, 1))], SimpleNamespace(heldout_error=lambda rows: 0.9, test_errors=lambda rows: None))
    assert (one.fitted, held.fitted) == (1, 2) and held.score > one.score


def test_an_axle_factor_scales_its_design_value_in_the_vehicle_and_its_file(tmp_path):
    """spring_rate, damper_force and anti_roll_bar multiply the axle's spring curve, damper curve
    and bar rate, in the extended vehicle and in the file the diagnosis writes (which reads back as it)."""
    v = load_vehicle()
    hs = [Hypothesis("spring_rate", ("rear",), {"spring_rate_scale": 0.8}),
          Hypothesis("damper_force", ("front",), {"damper_scale": 1.3}),
          Hypothesis("anti_roll_bar", ("front",), {"anti_roll_bar_scale": 1.25})]
    e = extended_vehicle(v, hs)
    assert e.rear.spring.rate == pytest.approx(0.8 * v.rear.spring.rate, rel=1e-9)
    assert e.front.spring.rate == v.front.spring.rate
    assert e.front.damper.curve.y == tuple(1.3 * y for y in v.front.damper.curve.y)
    assert e.front.damper.curve.x == v.front.damper.curve.x and e.rear.damper == v.rear.damper
    assert e.front.anti_roll_rate == pytest.approx(1.25 * v.front.anti_roll_rate)
    path = tmp_path / "extended.yaml"
    path.write_text(extended_vehicle_yaml(v, hs, "test"))
    back = load_vehicle(path)
    assert back.rear.spring.rate == pytest.approx(e.rear.spring.rate, rel=1e-9)
    assert back.front.damper.curve == e.front.damper.curve and back.front.anti_roll_rate == e.front.anti_roll_rate
    assert Hypothesis("spring_rate", ("rear",), {}).location_json() == {"axle": "rear"}


def test_a_hardpoint_offset_moves_the_point_what_sits_on_it_and_its_file(tmp_path):
    """A hardpoint cause moves one coordinate of a left-side point (the right mirrors it): the bushing
    that sits on it and the axes through it follow, as in the vehicle file edited by hand, which the
    diagnosis writes and which reads back as the extended vehicle; offsets at one place add up."""
    v = load_vehicle()
    places = locations(v, "hardpoint")
    points = {"front": len(v.front.hardpoints), "rear": len(v.rear.hardpoints)}
    # the beam centre stays on the centre plane; a wheel centre's height is the tyre radius's
    assert len(places) == 3 * (points["front"] + points["rear"]) - 3
    assert ("rear", "beam_centre", "y") not in places and ("rear", "beam_centre", "z") in places
    assert ("front", "wheel_centre", "z") not in places and ("front", "wheel_centre", "x") in places
    h = Hypothesis("hardpoint", ("front", "wishbone_front_pivot", "z"), {"offset": 2.5})
    assert h.label == "hardpoint@front.wishbone_front_pivot.z"
    assert h.location_json() == {"axle": "front", "hardpoint": "wishbone_front_pivot", "coordinate": "z"}
    e = extended_vehicle(v, [h, replace(h, values={"offset": 0.5})])
    before, after = (np.array(x.front.hardpoints["wishbone_front_pivot"]) for x in (v, e))
    assert after - before == pytest.approx([0.0, 0.0, 3e-3], abs=1e-12)
    bushings = {b.name: (b0, b) for b0, b in zip(v.bushings, e.bushings)}
    old, new = bushings["e1_front"]
    assert np.subtract(new.location, old.location) == pytest.approx([0.0, 0.0, 3e-3], abs=1e-12)
    old, new = bushings["e2_front"]   # its x axis runs from the rear pivot to the front one
    expected = np.subtract(after, v.front.hardpoints["wishbone_rear_pivot"])
    assert new.axes[0] == pytest.approx(expected / np.linalg.norm(expected), abs=1e-12) and new.axes[0] != old.axes[0]
    old, new = bushings["e1_rear"]
    assert (new.location, new.axes) == (old.location, old.axes)
    path = tmp_path / "extended.yaml"
    path.write_text(extended_vehicle_yaml(v, [h], "test"))
    assert load_vehicle(path).front.hardpoints == extended_vehicle(v, [h]).front.hardpoints
    # a vehicle changed in code is not what its file says: refused rather than moved from the file's
    # points, and no hardpoint is screened on it; one made from its file by values at places is
    changed = with_extensions(v, beam_torsion_scale=1.2)
    with pytest.raises(ValueError, match="no longer describes it"):
        extended_vehicle(changed, [h])
    assert locations(changed, "hardpoint") == []
    assert locations(vehicle_with(v.text, v.path, {"front.spring.rate": 30000.0}, "test"), "hardpoint") == places


def test_alike_rivals_are_those_the_tests_cannot_tell_from_the_best():
    """A rival is alike when it would be named alone and the best does not beat it as a cause beats
    a baseline; an extra test separates two causes when the wrong one's error on it would be told
    from the right one's (the noise), which a difference of RMS 0.484 × the noise just does."""
    def verified(label: str, error: float) -> Candidate:
        return Candidate(Hypothesis("hardpoint", ("front", label, "z"), {"offset": 1.0}), error, simulated=np.zeros(1))

    best = verified("tie_rod_inner", 1.02)
    close, beaten, weak = verified("tie_rod_outer", 1.06), verified("strut_top", 1.4), verified("strut_lower", 2.8)
    same_place = Candidate(Hypothesis("hardpoint", ("front", "tie_rod_inner", "z"), {"offset": 2.0}), 1.03,
                           simulated=np.zeros(1))
    assert alike(best, [best, close, beaten, weak, same_place], before=3.0) == [close]
    threshold = math.sqrt((1 / 0.9) ** 2 - 1.0)   # √(1 + d²) · 0.9 = 1: the gain a cause needs
    assert Separation("s", Path("s.yaml"), threshold * 1.001).separates
    assert not Separation("s", Path("s.yaml"), threshold * 0.999).separates
    assert told_apart(1.5, 1.0, 1.0) and not told_apart(1.05, 1.0, 1.0)
    # the separating test: the largest difference in noise units, each channel's mean removed; a
    # scenario a vehicle did not finish is left out
    tests = [(Path(f"{n}.yaml"), SimpleNamespace(name=n)) for n in ("slow", "shifted", "apart", "failed")]
    t = np.linspace(0.0, 1.0, 200)
    rival = {"slow": 0.2 * t, "shifted": 5.0 + 0 * t, "apart": 0.8 * np.sin(6 * t), "failed": None}

    def run(jobs):
        return [{"toe": 0 * t, "camber": 0 * t} if j.vehicle == "best" else
                (None if rival[j.scenario.name] is None else {"toe": 2.0 * rival[j.scenario.name], "camber": 0 * t})
                for j in jobs]

    (sep,) = separations(["best", "rival"], tests, ["toe", "camber"], np.array([2.0, 1.0]), 1.0, run)
    d = 0.8 * np.sin(6 * t)
    assert sep.test == "apart" and sep.difference == pytest.approx(np.sqrt(np.mean((d - d.mean()) ** 2) / 2))


def test_the_screening_fit_scales_the_effect_and_clips_a_hopeless_one_at_its_bound():
    """The effect is taken proportional to the first parameter (a stiffness k1: 1.5 times the nominal
    run's effect is 1.5 k1), to its logarithm for a factor (the beam's torsion scale s: s^1.5); a
    hypothesis with almost no effect is clipped at its bound (a factor's overflowed exp)."""
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 1.0, 2000)
    shape = np.column_stack([np.sin(2 * np.pi * t), np.cos(3 * np.pi * t)])
    base = np.zeros_like(shape)
    measured = 1.5 * shape + 0.2 * rng.standard_normal(shape.shape)
    tests = [Test(name, None, rows, np.arange(len(rows)), True)
             for name, rows in (("a", np.arange(1000)), ("b", np.arange(1000, 2000)))]
    layout = Layout(["c_x", "c_y"], measured, np.zeros(2000), np.zeros(2000, dtype=int), np.repeat([0, 1], 1000), tests)
    scorer = Scorer(layout, base, split(2))
    for h, name, as_fitted in ((Hypothesis("broad_relaxation", ("e1_front", "y"), nominal("broad_relaxation")),
                                "k1", lambda x, x0: x / x0),
                               (Hypothesis("beam_torsion", (), nominal("beam_torsion")),
                                "beam_torsion_scale", lambda x, x0: math.log(x) / math.log(x0))):
        fitted = fit(h, shape, base, scorer)
        # about 4 standard deviations of the noise
        assert as_fitted(fitted.hypothesis.values[name], h.values[name]) == pytest.approx(1.5, abs=0.03)
        assert fitted.screened_error == pytest.approx(1.0, abs=0.1)   # what is left is the noise
        hopeless = fit(h, 1e-6 * shape, base, scorer)
        assert hopeless.hypothesis.values[name] == pytest.approx(parameters(h.cause)[0].bounds[1], rel=1e-12)


def test_the_refit_fits_a_second_parameter_along_its_slope_and_keeps_it_in_bounds():
    """Given the rows' slope along the second parameter, the refit solves for both: the mismatch
    1.4·signature + 0.05·slope is fitted as k1 = 1.4 k1₀, alpha = alpha₀ + 0.05, each within its
    uncertainty; a move beyond the bound stops at it, and the first parameter is refitted given it."""
    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 1.0, 2000)
    shape = np.column_stack([np.sin(2 * np.pi * t), np.cos(3 * np.pi * t)])
    slope = np.column_stack([np.sin(5 * np.pi * t), t - 0.5]) * 8.0
    tests = [Test(name, None, rows, np.arange(len(rows)), True)
             for name, rows in (("a", np.arange(1000)), ("b", np.arange(1000, 2000)))]
    h = Hypothesis("broad_relaxation", ("e1_front", "y"), nominal("broad_relaxation"))
    k1, alpha = h.values["k1"], h.values["alpha"]
    for move, expected in ((0.05, alpha + 0.05), (0.8, parameters(h.cause)[1].bounds[1])):
        measured = 1.4 * shape + move * slope + 0.2 * rng.standard_normal(shape.shape)
        layout = Layout(["c_x", "c_y"], measured, np.zeros(2000), np.zeros(2000, dtype=int), np.repeat([0, 1], 1000),
                        tests)
        scorer = Scorer(layout, np.zeros_like(shape), split(2))
        fitted = fit(h, shape, np.zeros_like(shape), scorer, slope)
        assert fitted.hypothesis.values["alpha"] == pytest.approx(expected, abs=3 * fitted.std["alpha"] + 1e-12)
        if move < 0.5:
            assert fitted.hypothesis.values["k1"] == pytest.approx(1.4 * k1, abs=3 * fitted.std["k1"])
            assert 0.0 < fitted.std["alpha"] < 0.01 and fitted.std["k1"] < 0.03 * k1
            assert fitted.screened_error == pytest.approx(1.0, abs=0.1)
        else:   # k1 refitted with alpha at its bound: the best it can do along the signature
            train = slice(0, 1000)   # each channel's zero error removed, as the scorer does
            r, e = (a[train] - a[train].mean(axis=0) for a in (measured - (expected - alpha) * slope, shape))
            best = float(np.sum(r * e) / np.sum(e ** 2))
            assert fitted.hypothesis.values["k1"] == pytest.approx(best * k1, rel=0.02)
    # a slope that changes nothing the signature does not: the second parameter is left alone
    flat = fit(h, shape, np.zeros_like(shape), scorer, 0.5 * shape)
    assert flat.hypothesis.values["alpha"] == alpha and "alpha" not in flat.std


def test_the_pair_refit_fits_the_second_causes_second_parameter_along_its_slope():
    """What the first cause leaves is 0.9 × a second cause's effect plus its second parameter moved by
    0.05 (its rows' slope along it): the pair refit finds both, each within 3 of its uncertainties,
    and the first's magnitude; without the slope the held second parameter is absorbed elsewhere."""
    rng = np.random.default_rng(8)
    t = np.linspace(0.0, 1.0, 4000)
    first, second, slope = (np.column_stack([np.sin(k * np.pi * t), np.cos((k + 1) * np.pi * t)]) for k in (2, 5, 9))
    slope = 8.0 * slope
    measured = 1.2 * first + 0.9 * second + 0.05 * slope + 0.2 * rng.standard_normal(first.shape)
    tests = [Test(str(i), None, np.arange(1000 * i, 1000 * (i + 1)), np.arange(1000), True) for i in range(4)]
    layout = Layout(["c_x", "c_y"], measured, np.zeros(4000), np.zeros(4000, dtype=int), np.repeat(np.arange(4), 1000),
                    tests)
    base = np.zeros_like(first)
    scorer = Scorer(layout, base, split(4))
    h1 = Hypothesis("coupling", ("e1_rear", "x", "z"), nominal("coupling"))
    h2 = Hypothesis("broad_relaxation", ("e1_front", "y"), nominal("broad_relaxation"))
    one, two = Candidate(h1, math.nan, simulated=first), Candidate(h2, math.nan, simulated=first + second)
    pair = fit_pair(one, two, base, scorer, slope)
    assert pair.hypothesis.values["alpha"] == pytest.approx(h2.values["alpha"] + 0.05, abs=3 * pair.std["alpha"])
    assert pair.hypothesis.values["k1"] == pytest.approx(0.9 * h2.values["k1"], abs=3 * pair.std["k1"])
    assert pair.beside.hypothesis.values["stiffness"] == pytest.approx(1.2 * h1.values["stiffness"],
                                                                       abs=3 * pair.beside.std["stiffness"])
    assert 0.0 < pair.std["alpha"] < 0.01 and pair.screened_error == pytest.approx(1.0, abs=0.1)
    held = fit_pair(one, two, base, scorer)
    assert "alpha" not in held.std and held.screened_error > 1.5


def test_the_second_stage_fits_the_second_cause_beside_the_first():
    """What the first cause leaves (0.8 × a second hypothesis's effect) is fitted by that hypothesis,
    not by a decoy, at 0.8 × its nominal magnitude, run beside the first (here a linear stand-in for
    the vehicle) and scored: the pair is at the noise, and named. The second's effect overlaps the
    first's, so the first's magnitude as fitted alone is off (here 1.43 for 1.06 × its nominal); it
    is refitted with the second."""
    rng = np.random.default_rng(11)
    t = np.linspace(0.0, 1.0, 4000)
    first, second, decoy = (np.column_stack([np.sin(k * np.pi * t), np.cos((k + 1) * np.pi * t)]) for k in (2, 5, 9))
    measured = 1.3 * first + 0.8 * second + 0.05 * decoy + 0.2 * rng.standard_normal(first.shape)
    second = second + 0.3 * first     # the second hypothesis's effect overlaps the first's
    tests = [Test(str(i), None, np.arange(1000 * i, 1000 * (i + 1)), np.arange(1000), True) for i in range(4)]
    layout = Layout(["c_x", "c_y"], measured, np.zeros(4000), np.zeros(4000, dtype=int), np.repeat(np.arange(4), 1000),
                    tests)
    base = np.zeros_like(first)
    scorer = Scorer(layout, base, split(4))
    shapes = {"mullins": first, "coupling": second, "strut_friction": decoy}
    hs = [Hypothesis("coupling", ("e1_rear", "x", "z"), nominal("coupling")),
          Hypothesis("strut_friction", (), nominal("strut_friction"))]
    best = Candidate(Hypothesis("mullins", ("e1_front", "y"), {"mullins": 1.1 * 1.3 * nominal("mullins")["mullins"]}),
                     math.nan)

    def effect(h: Hypothesis) -> np.ndarray:   # linear in the first parameter, as the screening assumes
        p = parameters(h.cause)[0].name
        return h.values[p] / nominal(h.cause)[p] * shapes[h.cause]

    verify([best], [effect(best.hypothesis)], scorer)
    pairs = _second_stage(best, [(h, base + effect(h)) for h in hs], base, scorer,
                          lambda hss, tests: [sum(effect(h) for h in hs) for hs in hss], range(4),
                          [0, 2])
    assert pairs[0].hypothesis.cause == "coupling" and pairs[0].beside.hypothesis.cause == "mullins"
    for c, truth in ((pairs[0], 0.8), (pairs[0].beside, 1.3 - 0.3 * 0.8)):
        p = parameters(c.hypothesis.cause)[0].name
        mid = nominal(c.hypothesis.cause)[p]
        assert c.hypothesis.values[p] == pytest.approx(truth * mid, rel=0.05)   # the first was 35 % off
    assert pairs[0].heldout_error == pytest.approx(1.0, abs=0.1) and best.heldout_error > 2.0
    assert pair_named(scorer.heldout_error(base), best.heldout_error, pairs[0].heldout_error, 1.0)
    assert significant(pairs[0])
    # with no second effect in the data, the pair's gain is the first's joint refit: the second's
    # magnitude is not told from none
    layout.measured[:] = 1.3 * first + 0.2 * rng.standard_normal(first.shape)
    scorer = Scorer(layout, base, split(4))
    verify([best], [effect(best.hypothesis)], scorer)
    nulls = _second_stage(best, [(h, base + effect(h)) for h in hs], base, scorer,
                          lambda hss, tests: [sum(effect(h) for h in hs) for hs in hss], range(4),
                          [0, 2])
    assert not any(significant(c) for c in nulls)


def test_a_pair_refit_that_overshoots_is_tried_at_half_its_step():
    """The second cause's effect steepens along its shape beyond a knee its slope run (shape 1.25)
    does not reach: the linearised refit overshoots the hidden shape 1.32 (to about 1.5) and its
    run is worse than its start; half its step is run, kept, and significant. The halfway point
    lies on the scale the fit moved each parameter along (a factor's logarithm), with the refit's own
    uncertainties."""
    rng = np.random.default_rng(11)
    t = np.linspace(0.0, 1.0, 4000)
    first, a, b = (np.column_stack([np.sin(k * np.pi * t), np.cos((k + 1) * np.pi * t)]) for k in (2, 5, 9))
    m0, beam0 = nominal("mullins")["mullins"], nominal("beam_torsion")["beam_torsion_scale"]

    def effect(h: Hypothesis) -> np.ndarray:   # the beam log-linear; the softening linear in its magnitude
        if h.cause == "beam_torsion":
            return math.log(h.values["beam_torsion_scale"]) / math.log(beam0) * first
        d = h.values["mullins_shape"] - 1.0
        return h.values["mullins"] / m0 * (a + (d if d <= 0.3 else 0.3 + 10.0 * (d - 0.3)) * b)

    mullins = Hypothesis("mullins", ("e1_rear", "x"), nominal("mullins"))
    truth = replace(mullins, values={"mullins": 1.2 * m0, "mullins_shape": 1.32})
    tests = [Test(str(i), None, np.arange(1000 * i, 1000 * (i + 1)), np.arange(1000), True) for i in range(4)]
    layout = Layout(["c_x", "c_y"], first + effect(truth) + 0.2 * rng.standard_normal(first.shape), np.zeros(4000),
                    np.zeros(4000, dtype=int), np.repeat(np.arange(4), 1000), tests)
    base = np.zeros_like(first)
    scorer = Scorer(layout, base, split(4))
    best = Candidate(Hypothesis("beam_torsion", (), nominal("beam_torsion")), math.nan)
    verify([best], [effect(best.hypothesis)], scorer)
    runs = []

    def rows(hss: list[list[Hypothesis]], tests) -> list[np.ndarray]:
        runs.extend(hs[1].values["mullins_shape"] for hs in hss)
        return [sum(effect(h) for h in hs) for hs in hss]

    (pair,) = _second_stage(best, [(mullins, base + effect(mullins))], base, scorer, rows, range(4), [0, 2])
    start, slope, full, half = runs   # the screening fit, its slope run, the refit, its half step
    assert (start, slope) == (1.0, 1.25) and full > 1.45
    shape = pair.hypothesis.values["mullins_shape"]
    assert shape == pytest.approx(0.5 * (start + full), rel=1e-12) and shape == pytest.approx(half, rel=1e-12)
    assert pair.heldout_error < 1.6 and significant(pair)
    assert pair.hypothesis.values["mullins"] == pytest.approx(1.2 * m0, rel=0.1)
    # no linearised fit gave it: its training error is written as null, the JSON strict
    assert json.loads(json.dumps(_candidate(pair), allow_nan=False))["training_error"] is None
    # the halfway of two candidates: a factor magnitude on its logarithm, a shape linearly
    one = Candidate(Hypothesis("beam_torsion", (), {"beam_torsion_scale": 1.3}), math.nan)
    two = Candidate(Hypothesis("beam_torsion", (), {"beam_torsion_scale": 1.9}), math.nan,
                    {"beam_torsion_scale": 0.01})
    near, far = (Candidate(replace(mullins, values=v), math.nan, {"mullins": 0.004}) for v in
                 ({"mullins": 0.1, "mullins_shape": 1.0}, {"mullins": 0.2, "mullins_shape": 1.5}))
    far.beside = two
    mid = halfway(one, near, far)
    assert mid.hypothesis.values == pytest.approx({"mullins": 0.15, "mullins_shape": 1.25}, rel=1e-12)
    assert mid.beside.hypothesis.values["beam_torsion_scale"] == pytest.approx(math.sqrt(1.3 * 1.9), rel=1e-12)
    assert mid.std == far.std and mid.std is not far.std and mid.z == pytest.approx(0.15 / 0.004)


def test_a_magnitude_is_significant_off_no_effect_on_its_effects_scale():
    """Two standard uncertainties off no effect: 0 for an offset, 1 for a factor (on its logarithm);
    a null or unbounded uncertainty does not tell."""
    offset, factor = parameters("hardpoint")[0], parameters("spring_rate")[0]
    assert separation(offset, -2.1, 1.0) == pytest.approx(2.1) and separation(offset, 0.17, 5.1) < 0.1
    assert separation(factor, 1.05, 0.02) == pytest.approx(math.log(1.05) / (0.02 / 1.05))   # 2.56
    assert separation(factor, 1.03, 0.02) < 2.0                                                # 1.55
    assert math.isnan(separation(offset, 1.0, 0.0)) and math.isnan(separation(offset, 1.0, math.inf))
    assert not significant(Candidate(Hypothesis("hardpoint", ("front",), {"offset": 1.0}), math.nan))


def test_the_verdict_says_which_parameters_the_kc_fit_held():
    """A parameter the K&C fit held (the screen's second parameter, or the refit's when its slope
    changes nothing the first does not) is reported as held, with no uncertainty, in valid JSON (the
    uncertainty was NaN)."""
    h = Hypothesis("broad_relaxation", ("e1_front", "y"), {"k1": 60.0, "alpha": 0.16})
    out = _parameters(SimpleNamespace(named=True, best=Candidate(h, 1.0, {"k1": 5.0})))
    assert out["k1"] == {"value": 60.0, "std": 5.0, "unit": "N/mm", "fitted": True}
    assert out["alpha"] == {"value": 0.16, "std": None, "unit": "-", "fitted": False}
    json.dumps(out, allow_nan=False)


def test_simulate_gives_the_recorded_run(tmp_path):
    scenario = load_scenario(DEFAULT_SCENARIOS[0])
    scenario = replace(scenario, cases=scenario.cases[:1])
    recorded = load_run(run_scenario(scenario, tmp_path / "run.mcap", duration_scale=0.1).path)
    memory = simulate(scenario, duration_scale=0.1)
    assert list(memory.signals) == list(recorded.signals)
    np.testing.assert_allclose(memory.t_s, recorded.t_s, atol=1e-9)
    for name, values in recorded.signals.items():
        np.testing.assert_array_equal(memory.signals[name], values, err_msg=name)
    assert json.loads(json.dumps(memory.metadata.bushing_parameters)) == recorded.metadata.bushing_parameters


def test_diagnose_refuses_a_bushing_model_for_a_kc_dataset(tmp_path):
    (tmp_path / "rig.yaml").write_text("level: kc\nvehicle: car\nrecordings: []\n")
    done = subprocess.run([sys.executable, "-m", "elastokin", "diagnose", str(tmp_path), "--bushing-set",
                           "fig5_9"], capture_output=True, text=True)
    assert done.returncode != 0
    assert "--vehicle" in done.stderr and "rig.yaml" in done.stderr


# -- hidden causes --------------------------------------------------------------------------------
def measure(tmp: Path, cause: str, seed: int) -> tuple[Hypothesis | None, Path]:
    """A drawn truth measured on the K&C campaign at 4 times its speed (7 tests, 3 held out; each
    recording keeps its duration scale, so the baseline plays the same), copied to ``tmp/measured``."""
    rng = np.random.default_rng([seed, sum(map(ord, cause))])
    h = None if cause == "none" else draw(cause, rng)
    return h, measure_truth(tmp, [h] if h else [], seed, duration_scale=0.25)


def hidden_pair(seed: int) -> list[Hypothesis]:
    """Two different causes drawn (each at a place the campaign sees it, in its observable range)."""
    rng = np.random.default_rng([seed, sum(map(ord, PAIR))])
    first, second = rng.choice(len(KC_CAUSES), size=2, replace=False)
    return [draw(KC_CAUSES[first], rng), draw(KC_CAUSES[second], rng)]


def measure_truth(tmp: Path, hs: list[Hypothesis], seed: int, *, duration_scale: float,
                  scenarios: list[str] | None = None, chain: dict | None = None, rig: dict | None = None) -> Path:
    """The default car with the hypotheses ``hs`` hidden, measured on ``scenarios`` (default: the K&C
    campaign) through the rig's ``chain`` (a truth's chain mapping, rig_chain) on a rig of the
    mechanics ``rig`` (a truth's rig mapping), copied to ``tmp/measured``."""
    effects = []
    for h in hs:
        entry = {"cause": h.cause, **h.values}
        if len(h.location) in (1, 2) or h.cause == "hardpoint":
            entry["location"] = ".".join(h.location)
        elif len(h.location) == 3:
            entry["location"], entry["directions"] = h.location[0], list(h.location[1:])
        effects.append(entry)
    data = {"level": "kc", "duration_scale": duration_scale, "effects": effects, "seed": seed}
    if scenarios is not None:
        data["scenarios"] = scenarios
    if chain:
        data["chain"] = chain
    if rig:
        data["rig"] = rig
    truth = parse_kc_truth(data, "<test truth>", Path.cwd())
    out = measure_kc(truth, tmp / "rig_output")
    copy = tmp / "measured"
    shutil.copytree(out, copy)
    shutil.rmtree(out)
    return copy


def diagnose_fresh(directory: Path, *options: str) -> dict:
    """``vsim diagnose DIR --json [options]`` (the default car as baseline) in a fresh Python process."""
    done = subprocess.run([sys.executable, "-m", "elastokin", "diagnose", str(directory), "--json", *options],
                          capture_output=True, text=True, timeout=1800, cwd=directory.parent)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def _excess(error: float) -> float:
    """The model error in excess of the noise (errors are in units of the noise: 1 is perfect)."""
    return math.sqrt(max(error ** 2 - 1.0, 0.0))


def _within(fitted: float, hidden: float, p: Parameter, share: float = 0.3) -> bool:
    """Whether a fitted value is the hidden one, of the same sign, within ``share`` of its magnitude
    in the coordinate its effect grows with (:meth:`Parameter.effect`: a factor's logarithm, so that
    ×1.08 fitted ×1.10 is 24 % off, not 2 %)."""
    return fitted * hidden > 0.0 and abs(p.effect(fitted) - p.effect(hidden)) <= share * abs(p.effect(hidden))


def check(result: dict, h: Hypothesis | None) -> str:
    """AssertionError unless ``result`` diagnoses the hidden ``h`` right; "reported alike" when the
    truth is a rival the report says these tests cannot tell from the cause it names, "reported
    beside a rig error" when no cause is named and the report says the truth would explain what a
    rig error took out as well, else ""."""
    if h is None:
        assert result["cause"] == "none", result["ranking"][:3]
        assert result["causes"] == [] and result["explained"] == "full" and result["misfits"] == []
        return ""
    if h.cause == "backlash":
        assert result["cause"] == "unexplained", result["ranking"][:3]
        assert result["explained"] == "none"
        return ""
    first = parameters(h.cause)[0]
    # no car cause named, the rig errors explaining the data, and the truth said to explain what one of
    # them took out as well (kc_rig_or_car: the campaign cannot tell them apart, and says so)
    beside = [r for c in result["rig_or_car"] for r in c["rivals"]
              if (r["cause"], r["location"]) == (h.cause, h.location_json())]
    if result["cause"] == "none" and beside:
        fitted, hidden = beside[0]["parameters"][first.name], h.values[first.name]
        assert _within(fitted, hidden, first), (fitted, h.values)
        return "reported beside a rig error"
    assert len(result["causes"]) == 1 and result["explained"] in ("full", "partial")
    assert _excess(result["heldout_error_after"]) <= 0.5 * _excess(result["heldout_error_before"])
    # the named cause, or a rival the report says these tests cannot tell from it (kc_alike)
    rival = [a for a in result["alike"] if (a["cause"], a["location"]) == (h.cause, h.location_json())]
    if rival:
        fitted, hidden = rival[0]["parameters"][first.name], h.values[first.name]
        assert _within(fitted, hidden, first), (fitted, h.values)
        return "reported alike"
    assert result["cause"] == h.cause, result["ranking"][:3]
    assert result["location"] == h.location_json()
    assert result["parameters"][first.name]["fitted"]
    fitted, hidden = result["parameters"][first.name]["value"], h.values[first.name]
    # the magnitude (and sign) within 30 % (a factor's logarithm) where every parameter was fitted; within a factor of 2 where
    # the verdict held a second one at mid-range, which the first absorbs (a damper Co·v^pw fitted with
    # the wrong pw matches the force at the rig's node speeds, not Co)
    assert fitted * hidden > 0.0, (fitted, h.values)
    if all(p["fitted"] for p in result["parameters"].values()):
        assert _within(fitted, hidden, first), (fitted, h.values)
    else:
        assert 0.5 <= fitted / hidden <= 2.0, (fitted, h.values)
    return ""


def check_pair(result: dict, hs: list[Hypothesis]) -> None:
    """Both hidden causes named at their places, with magnitudes within 30 % (the first parameter; a factor's logarithm),
    shares adding up to the pair's."""
    named = {(c["cause"], json.dumps(c["location"])): c for c in result["causes"]}
    assert set(named) == {(h.cause, json.dumps(h.location_json())) for h in hs}, \
        (list(named), result["ranking"][:2], result["pairs"][:2])
    assert result["cause"] == PAIR_SEPARATOR.join(c["cause"] for c in result["causes"])
    assert result["explained"] in ("full", "partial")
    assert _excess(result["heldout_error_after"]) <= 0.5 * _excess(result["heldout_error_before"])
    shares = [c["share_explained"] for c in result["causes"]]
    assert sum(shares) == pytest.approx(result["share_explained"]) and min(shares) >= 0.0
    for h in hs:
        first = parameters(h.cause)[0]
        fitted = named[(h.cause, json.dumps(h.location_json()))]["parameters"][first.name]["value"]
        assert _within(fitted, h.values[first.name], first), (h, fitted)


@pytest.mark.slow   # the default run keeps two end-to-end diagnoses below; the slow suite draws every cause
def test_a_drawn_cause_is_named_at_its_place(tmp_path):
    cause = KC_CAUSES[SEED % len(KC_CAUSES)]
    h, measured = measure(tmp_path, cause, SEED)
    check(diagnose_fresh(measured), h)


#: The end-to-end tests' rig: the wheel-position heads (toe, camber, wheel travel and centre: one
#: acquisition path) 15 ms late, the pads' lateral-force transducers reading 1.5 % high (the car gets
#: the command / 1.015).
E2E_CHAIN = {**{stem: {"delay_ms": 15.0} for stem in GROUPS["wheel_sensors"]}, "pad_fy": {"gain": 0.015}}
#: The rear pivot's axial direction 250 N/mm where the car's file says 200 (a harder rubber, ×1.25):
#: the one-scenario report's cause, and the harder car of the serial/cluster bits tests.
HARDER_PIVOT = Hypothesis("stiffness", ("e1_rear", "x"), {"stiffness_scale": 1.25})


def through_a_rigs_csv(tmp: Path, hs: list[Hypothesis], seed: int, rig: dict | None = None) -> Path:
    """The default car with ``hs`` hidden measured on the lateral-force test at 10 times its speed
    through :data:`E2E_CHAIN` on a rig of the mechanics ``rig`` (default: ideal), exported as a
    rig's CSV + META in SAE signs (`vsim rig export`) and brought in as a user's would be (`vsim rig
    import`, `vsim rig dataset`): the dataset's folder."""
    root = Path(__file__).resolve().parents[1]
    measured = measure_truth(tmp, hs, seed, duration_scale=0.1, chain=E2E_CHAIN, rig=rig,
                             scenarios=[str(root / "scenarios" / "kc" / "lateral_force.yaml")])
    assert cli.main(["rig", "export", str(measured), "-o", str(tmp / "csv"), "--convention", "sae"]) == 0
    _import_all(tmp / "csv", tmp / "dataset")
    return tmp / "dataset"


def assert_the_chain_recovered(result: dict, rig: dict | None = None) -> None:
    """The wheel sensors' 15 ms and the pads' none within 3 standard uncertainties and
    LAG_TOLERANCE_S; every pad's lateral-force gain within 3 of its uncertainties (and 0.1 %) of
    1.5 % (on one test, its response's channels' own gains act alike: the uncertainty is wide), every
    measured channel's gain, cross-talk and zero's drift of none, the rig's mechanics ``rig`` (default: ideal;
    every element within 3 standard uncertainties, a tenth and its floor); no car cause said to
    explain a rig error as well, nor one the rig's errors may hide."""
    lags = {a["path"]: a for a in result["acquisition"]}
    for path, truth_ms in (("wheel sensors", 15.0), ("pad sensors", 0.0)):
        lag = lags[path]
        assert abs(lag["lag_ms"] - truth_ms) <= 3.0 * lag["delay_std_ms"] + 1e3 * LAG_TOLERANCE_S, lag
    gains = {g["channel"]: g for g in result["transducers"] if g["kind"] == "input gain"}
    assert set(gains) == {f"pad_fy_{w}" for w in CORNER_TAGS.values()}
    for g in gains.values():
        assert abs(g["value"] - 0.015) <= 3.0 * g["std"] + 1e-3, g
    for g in result["transducers"]:   # the measured channels' transducers read true, and are not shown
        if g["kind"] != "input gain":
            assert abs(g["value"]) <= 3.0 * g["std"] + 2e-3 and not g["shown"], g
    # each measured channel's zero read not drifting through the recording (its input repeats), in its unit
    drifts = [g for g in result["transducers"] if g["kind"] == "drift"]
    assert sorted(g["channel"] for g in drifts) == sorted(g["channel"] for g in result["transducers"] if g["kind"] == "gain")
    assert {g["source"] for g in drifts} == {"01_kc_lateral_force"} and {g["unit"] for g in drifts} <= {"deg", "mm", "N"}
    assert {g["element"] for g in result["rig"]} == set(BY_KEY)
    for g in result["rig"]:
        truth = (rig or {}).get(g["element"], 0.0)
        assert abs(g["value"] - truth) <= 3.0 * g["std"] + 0.1 * truth + BY_KEY[g["element"]].floor, g
    assert result["rig_or_car"] == [] and result["hidden_cause"] is None


def test_a_spring_on_a_rig_whose_pads_have_friction_is_named_and_the_friction_taken_out(tmp_path):
    """The front springs 6 % stiffer, measured in pumping alone at 20 times its speed on a rig whose
    pads have 15 N of friction (with 3 mm/kN of compliance before they slip: the diagnosis's own
    pads have a typical 3.5): the springs named with their factor within 3 standard
    uncertainties and 2 % (the front pads' load cells' gains, which act on vertical loads much as a
    stiffer spring does, fitted with it and not taking it), the friction recovered within 3 standard
    uncertainties and a tenth (from the second run, on a rig with the friction the first shows),
    the rig's mechanics said as the rig's in the verdict, not as stated by the scenarios."""
    root = Path(__file__).resolve().parents[1]
    h = Hypothesis("spring_rate", ("front",), {"spring_rate_scale": 1.06})
    measured = measure_truth(tmp_path, [h], 4, duration_scale=0.05,
                             rig={"pad_friction_n": 15.0, "pad_compliance_mm_per_kn": 3.0},
                             scenarios=[str(root / "scenarios" / "kc" / "pumping.yaml")])
    said: list[str] = []
    diagnosis = diagnose_kc(read_kc_dataset(measured), load_vehicle(DEFAULT_VEHICLE), executor=SerialExecutor(),
                            progress=said.append)
    assert sum("every run again on a rig with it" in m for m in said) == 1
    result = json.loads(json.dumps(summary(diagnosis)))
    check(result, h)
    fitted = result["parameters"]["spring_rate_scale"]
    assert abs(fitted["value"] - 1.06) <= min(3.0 * fitted["std"], 0.02 * 1.06), fitted
    friction = next(g for g in result["rig"] if g["element"] == "pad_friction_n")
    assert abs(friction["value"] - 15.0) <= 3.0 * friction["std"] + 1.5, friction
    assert "The rig itself shows: the pads' friction" in verdict_sentence(diagnosis)   # not "beyond ... state"
    assert friction["shown"] and not any(g["shown"] for g in result["rig"] if g is not friction)


def test_a_clean_car_through_a_rigs_lag_and_force_gain_is_given_no_car_cause(tmp_path):
    """A clean car measured through :data:`E2E_CHAIN` on a rig whose body clamp yields 0.015 mm/kN
    sideways (0.18 mm under the test's 12 kN, as a lateral compliance of the axles would read) and
    brought in as a rig's SAE CSV exports: "none", the lag, the gains and the clamp recovered
    (without the gains' fit: a coupling and a stiffness)."""
    rig = {"clamp_lateral_mm_per_kn": 0.015}
    result = diagnose_fresh(through_a_rigs_csv(tmp_path, [], 2, rig))
    check(result, None)
    assert_the_chain_recovered(result, rig)
    clamp = next(g for g in result["rig"] if g["element"] == "clamp_lateral_mm_per_kn")
    assert clamp["value"] > 3.0 * clamp["std"], clamp   # seen, not only allowed


def test_report_of_a_one_scenario_dataset_and_a_bushing_stiffer_than_its_law(tmp_path):
    """The rear pivot's axial direction 250 N/mm where the car's file says 200 (a harder rubber,
    ×1.25), measured on the lateral-force test alone at 10 times its speed through a rig's lag and
    force gain, brought in as the rig's SAE CSV exports (:func:`through_a_rigs_csv`): a stiffness
    factor named at its place, its factor within 3 standard uncertainties and 3 %, not an asymmetry;
    the chain recovered; ``-o`` writes the report, its pictures, diagnosis.json and an extended
    vehicle file that carries the fitted factor where it was found."""
    h = HARDER_PIVOT
    measured = through_a_rigs_csv(tmp_path, [h], 2)
    report = tmp_path / "report"
    result = diagnose_fresh(measured, "-o", str(report))   # on a local Dask cluster of 2 workers
    check(result, h)
    fitted = result["parameters"]["stiffness_scale"]
    assert abs(fitted["value"] - 1.25) <= min(3.0 * fitted["std"], 0.03 * 1.25), fitted
    assert all(c["cause"] != "asymmetry" for c in result["causes"])
    assert_the_chain_recovered(result)
    assert json.loads((report / "diagnosis.json").read_text())["cause"] == "stiffness"
    text = (report / "report.md").read_text()
    assert text.count("![") == 3 and all((report / name).stat().st_size > 0 for name in
                                         ("overlays.png", "residuals.png", "ranking.png"))
    assert "pad_fy_fl" in text and "transducer" in text   # the gains said and tabled
    extended = {b.name: b for b in load_vehicle(report / "extended_vehicle.yaml").bushings}
    baseline = {b.name: b for b in load_vehicle(DEFAULT_VEHICLE).bushings}
    assert extended["e1_rear"].directions["x"].params["K0"] == pytest.approx(
        fitted["value"] * baseline["e1_rear"].directions["x"].params["K0"], rel=1e-6)
    assert extended["e1_rear"].directions["y"] == baseline["e1_rear"].directions["y"]


def test_a_campaigns_runs_give_the_same_bits_on_a_local_cluster_and_serially(tmp_path):
    """The runs a diagnosis sends out (its fits are this process's) give the same rows, every bit, on
    a local Dask cluster of 2 worker processes as serially in this process: the baseline and a car
    with a harder bushing on the lateral-force test through :data:`E2E_CHAIN`, where the two cars
    differ. (The whole verdict's bits, in a fresh process on a cluster and serially here: the slow
    suite's :func:`test_a_verdict_is_the_same_bits_on_a_local_cluster_and_serially`.)"""
    vehicle = load_vehicle(DEFAULT_VEHICLE)
    layout = Layout.of(read_kc_dataset(through_a_rigs_csv(tmp_path, [], 2)), vehicle)
    every = range(len(layout.tests))
    harder = extended_vehicle(vehicle, [HARDER_PIVOT])
    sets = [(label, layout.jobs(v, every), every) for label, v in (("baseline", vehicle), ("harder", harder))]
    serial = run_sets(layout, SerialExecutor(), sets)
    with executor(LOCAL, workers=2) as pool:
        spread = run_sets(layout, pool, sets)
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(serial, spread))
    assert np.nanmax(np.abs(serial[1] - serial[0])) > 0.0


@pytest.mark.slow   # two whole diagnoses of one dataset; the default run compares their runs' bits (above)
def test_a_verdict_is_the_same_bits_on_a_local_cluster_and_serially(tmp_path):
    """The same verdict, every number of it, from ``vsim diagnose`` in a fresh process on a local
    Dask cluster of 2 workers and from :func:`diagnose_kc` serially in this process (another hash
    seed, other processes' runs): the dataset of the one-scenario report's test."""
    measured = through_a_rigs_csv(tmp_path, [HARDER_PIVOT], 2)
    result = diagnose_fresh(measured)
    serial = diagnose_kc(read_kc_dataset(measured), load_vehicle(DEFAULT_VEHICLE), executor=SerialExecutor())
    assert ({k: v for k, v in json.loads(json.dumps(summary(serial))).items() if k != "wall_s"}
            == {k: v for k, v in result.items() if k != "wall_s"})


def test_a_hardpoint_off_is_named_or_reported_with_its_rivals(tmp_path):
    """A tie rod's inner end 2 mm high (bump steer) hidden in the car, measured in pumping alone at 20
    times its speed: named with its offset, or reported among the rivals these tests cannot tell
    from the named cause, each with the shipped test that separates it best."""
    root = Path(__file__).resolve().parents[1]
    h = Hypothesis("hardpoint", ("front", "tie_rod_inner", "z"), {"offset": 2.0})
    measured = measure_truth(tmp_path, [h], 3, duration_scale=0.05,
                             scenarios=[str(root / "scenarios" / "kc" / "pumping.yaml")])
    result = json.loads(json.dumps(summary(diagnose_kc(read_kc_dataset(measured), load_vehicle(DEFAULT_VEHICLE),
                                                       executor=SerialExecutor()))))
    check(result, h)
    for rival in result["alike"]:
        separated = rival["separated_by"]
        assert Path(separated["file"]).is_file() and separated["scenario"] != "kc_pumping"
        assert separated["separates"] == (separated["difference"] >= math.sqrt(1 / 0.9 ** 2 - 1))


@pytest.mark.slow
def test_two_drawn_causes_are_both_named_at_their_places(tmp_path):
    hs = hidden_pair(SEED)
    check_pair(diagnose_fresh(measure_truth(tmp_path, hs, SEED, duration_scale=0.25)), hs)


@pytest.mark.slow
@pytest.mark.parametrize("cause", KC_CAUSES + ["none", "backlash", PAIR])
def test_success_rate_over_many_seeds(tmp_path, record_property, cause):
    """At least OWN_FORM_SUCCESS_RATE of the draws per catalogue cause diagnosed right (20) and of
    clean draws naming nothing (10), MIN_SUCCESS_RATE of backlashes (outside the catalogue) never a
    confident cause, both causes of MIN_PAIR_SUCCESS_RATE of the pairs (20; the tally goes to the
    run's summary)."""
    def attempt(case: Path, seed: int) -> str:
        if cause == PAIR:
            hs = hidden_pair(seed)
            check_pair(diagnose_fresh(measure_truth(case, hs, seed, duration_scale=0.25)), hs)
            return ""
        h, measured = measure(case, cause, seed)
        return check(diagnose_fresh(measured), h)

    seeds = SLOW_SEEDS[:max(len(SLOW_SEEDS) // 2, 1)] if cause == "none" else SLOW_SEEDS
    assert_success_rate(cause, seeds, tmp_path, attempt, record_property,
                        MIN_PAIR_SUCCESS_RATE if cause == PAIR else MIN_SUCCESS_RATE if cause == "backlash"
                        else OWN_FORM_SUCCESS_RATE)


#: How close a path's lag at low frequency must come to the chain's [s], beyond 3 of its standard
#: uncertainties: its filter's shape is fitted, not known (a filter's lag is √2/(2π f_c)).
LAG_TOLERANCE_S = 5e-4


def _chain_lags(chain: dict) -> dict[str, float]:
    """Each acquisition path's lag at low frequency in a drawn chain [s] (its filter's and its delay)."""
    out = {}
    for path, stem in (("wheel sensors", "toe"), ("pad sensors", "pad_fz")):
        e = chain.get(stem, {})
        cutoff = e.get("low_pass_hz", 0.0)
        out[path] = 1e-3 * e.get("delay_ms", 0.0) + (math.sqrt(2.0) / (2.0 * math.pi * cutoff) if cutoff else 0.0)
    return out


def _chain_reading(chain: dict, reading: dict) -> float:
    """A drawn chain's value of a transducer error the diagnosis reports (a gain; a cross-talk's
    coefficient; a drift's bound, its rate being drawn per recording within ± it), from the channel's
    own entry over its quantity's."""
    entry = {**chain.get(reading["channel"].rsplit("_", 1)[0], {}), **chain.get(reading["channel"], {})}
    if reading["kind"] == "cross-talk":
        return entry.get("crosstalk", {}).get(reading["source"], 0.0)
    return entry.get("drift_per_min" if reading["kind"] == "drift" else "gain", 0.0)


#: How often a draw whose readings all have honest uncertainties may fail on one of them by chance:
#: a draw judges ~180 readings (lags, every transducer's errors, the rig's mechanics), and at 3 of
#: their uncertainties each, one or more would fail two draws in five; each is judged instead at
#: the two-sided normal quantile of this over their number (Bonferroni), chance then taking at most a
#: fifth of the draws OWN_FORM_SUCCESS_RATE lets fail. Decided before seeds 106 on (issue 53).
FAMILY_ALPHA = 0.01


def family_sigmas(n: int) -> float:
    """How many standard uncertainties each of ``n`` readings of one draw may be off [1]: the
    two-sided normal quantile of FAMILY_ALPHA / n, never fewer than 3."""
    return max(3.0, float(norm.isf(FAMILY_ALPHA / (2 * max(n, 1)))))


def _read_right(chain: dict, reading: dict, sigmas: float) -> bool:
    """Whether a transducer error the diagnosis reports is the drawn chain's within ``sigmas`` of its
    standard uncertainties and 0.1 % (a drift: within its bound and ``sigmas`` of them)."""
    truth = _chain_reading(chain, reading)
    if reading["kind"] == "drift":
        return abs(reading["value"]) <= truth + sigmas * reading["std"]
    return abs(reading["value"] - truth) <= sigmas * reading["std"] + 1e-3


def test_a_draws_readings_with_honest_uncertainties_fail_together_as_often_as_family_alpha():
    """Of 40 000 draws of 184 readings, each off by its standard uncertainty times a normal deviate,
    those with a reading beyond family_sigmas fail at FAMILY_ALPHA (within 4 binomial standard
    deviations); at 3 each, two in five would."""
    rng = np.random.default_rng(53)
    n, draws = 184, 40_000
    worst = np.abs(rng.standard_normal((draws, n))).max(axis=1)
    rate = np.mean(worst > family_sigmas(n))
    assert abs(rate - FAMILY_ALPHA) <= 4.0 * math.sqrt(FAMILY_ALPHA * (1 - FAMILY_ALPHA) / draws), rate
    assert np.mean(worst > 3.0) == pytest.approx(1 - (1 - 2 * norm.sf(3.0)) ** n, abs=0.01)
    assert family_sigmas(1) == 3.0


def _with_hidden_truth(result: dict, h: Hypothesis | None) -> dict[tuple, dict]:
    """The shown rig errors as the report reads them with the car cause it says the rig's errors may
    hide (``result["hidden_cause"]``), by (kind, channel, source), if that cause is ``h``'s at its
    place (each with the channel and kind of its reading, its value and standard uncertainty then);
    else none."""
    hidden = result.get("hidden_cause")
    if h is None or hidden is None or (hidden["cause"], hidden["location"]) != (h.cause, h.location_json()):
        return {}
    return {(r["kind"], r["channel"], r["source"]): {**r, "value": r["value_with"], "std": r["std_with"]}
            for r in hidden["readings"]}


@pytest.mark.slow
@pytest.mark.parametrize("cause, elements", [("none", (e,)) for e in DRAWN] + [("none", DRAWN)]
                         + [(c, DRAWN) for c in KC_CAUSES])
def test_success_rate_through_a_rigs_acquisition(tmp_path, record_property, cause, elements):
    """Measured through a typical rig's chain drawn from the seed, on a rig of its own mechanics drawn
    too (each element alone on clean cars, all of them; all of them with each cause): a clean car
    never given a car cause; a cause of THROUGH_A_RIG, drawn there, named as without the chain
    (check); one it lacks, drawn where OBSERVABLE has it, named so or "none" found (the rig's errors
    may take it, never another cause), or "unexplained" with the report saying it is the cause the
    rig's errors may hide (decided before seeds 110 on); each path's lag and each moved input's transducer gain
    recovered within :func:`family_sigmas` of its standard uncertainties (and LAG_TOLERANCE_S, 0.1 %),
    each zero's drift within its bound (:func:`_read_right`), each element of the rig's mechanics
    within them and a tenth of its value (issue 53); of a cause found "none", the rig errors the
    report shows alone; a reading off is right too where the report reads it right with the car cause it
    says the rig's errors may hide, that cause being the truth's at its place (:func:`_with_hidden_truth`;
    decided before seeds 108 on)."""
    def attempt(case: Path, seed: int) -> str:
        rng = np.random.default_rng([seed, 53])
        chain = draw_chain(rng, "typical", WHITE, elements)
        floors = THROUGH_A_RIG if cause in THROUGH_A_RIG else OBSERVABLE
        h = None if cause == "none" else draw(cause, rng, floors)
        rig = draw_rig(rng, "typical", elements)
        result = diagnose_fresh(measure_truth(case, [h] if h else [], seed, duration_scale=0.25, chain=chain,
                                              rig=rig))
        # the car's verdict first: a wrong one is the failure to report
        with_truth = _with_hidden_truth(result, h)
        missed = h is not None and cause not in THROUGH_A_RIG and (
            result["cause"] == "none" or result["cause"] == "unexplained" and bool(with_truth))
        if missed:   # the rig's errors took it: what they read is the chain's and the cause's
            if result["cause"] == "none":
                check(result, None)
            assert result["causes"] == []
            note = ("unexplained, " if result["cause"] == "unexplained" else "") + (
                "said as one the rig's errors may hide" if with_truth else "not seen through the rig's errors")
        else:
            note = check(result, h)
        transducers = [g for g in result["transducers"] if g["shown"] or not missed]
        mechanics = [g for g in result["rig"] if g["shown"] or not missed]
        sigmas = family_sigmas(len(result["acquisition"]) + len(transducers) + len(mechanics))
        for a in result["acquisition"]:
            truth = _chain_lags(chain)[a["path"]]
            assert abs(1e-3 * a["lag_ms"] - truth) <= 1e-3 * sigmas * a["delay_std_ms"] + LAG_TOLERANCE_S, (a, truth)
        for g in transducers:
            with_it = with_truth.get((g["kind"], g["channel"], g["source"]))
            assert _read_right(chain, g, sigmas) or (with_it is not None and _read_right(chain, with_it, sigmas)), \
                (g, with_it, _chain_reading(chain, g), sigmas)
        for g in mechanics:
            # the diagnosis's pads have a typical compliance, not the rig's: a tenth besides
            truth = rig.get(g["element"], 0.0)
            with_it = with_truth.get((RIG, g["element"], None))
            assert any(abs(r["value"] - truth) <= sigmas * r["std"] + 0.1 * truth + BY_KEY[g["element"]].floor
                       for r in (g, with_it) if r is not None), (g, with_it, truth)
        return note

    assert_success_rate(f"{cause} through {'+'.join(elements)}", SLOW_SEEDS, tmp_path, attempt, record_property,
                        OWN_FORM_SUCCESS_RATE)


@pytest.mark.slow
def test_a_damaged_dataset_used_as_it_is_still_names_its_cause(tmp_path):
    """The shipped dataset (a rear coupling of 70 N/mm, data/README.md) with a chunk of its roll
    recording failing its CRC (8.6 s of the roll test missing), diagnosed with --use-damaged: the
    same cause at its place, the stiffness within two of its standard deviations, the damage in the
    report."""
    folder = damaged_kc_dataset(tmp_path)
    with pytest.warns(DamagedRecording):
        data = read_kc_dataset(folder, use_damaged=True)
    result = diagnose_kc(data, load_vehicle(DEFAULT_VEHICLE), executor=SerialExecutor())
    out = summary(result)
    assert out["cause"] == "coupling" and out["location"]["bushing"] == "e1_rear"
    stiffness = out["parameters"]["stiffness"]
    assert abs(stiffness["value"] - 70.0) <= 2 * stiffness["std"]
    assert out["damage"] == [f"02_kc_roll.mcap: {data.tests[1].run.reason}"]
    write_report(result, load_vehicle(DEFAULT_VEHICLE), tmp_path / "report", str(folder))
    assert "**Diagnosed on a damaged dataset**" in (tmp_path / "report" / "report.md").read_text()

