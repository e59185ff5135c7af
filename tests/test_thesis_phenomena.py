"""The thesis's vehicle-level phenomena that the model reproduces (issue 30; the report is
tools/thesis/report.md, made by tools/thesis_reproduction.py), held by their direction and rough
size so that a later change cannot lose them silently: the loop against the pumping speed and its
causes, the bushing's deflection following the pumping amplitude, the toe loop under lateral force
carried by the front pivot bushing's lateral direction, and the laws' relaxation on the bench (RT
more than STVS). After 50 ms rack steps the car's relaxation and the fading memory of two steps
are not reproduced; what removes them, the corner's ringing working the laws to their relaxed state,
is held on the bench and on the car, where both appear with steps ramped in 0.5 s: a step's own
relaxation, taken from a control run without it, RT more than STVS as on the bench."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from elastokin.vehicle.model.file_overrides import PlaceError, lossier_places, vehicle_with
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.vehicle.scenarios.scenario_file import load_scenario, parse_scenario, with_case_values
from elastokin.bushings.bank import BushingBank
from elastokin.bushings.parameter_sets import load_parameter_set
from elastokin.analysis.run_metrics import case_lag_s, case_loop, case_mask, cases
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.recordings.recorder import simulate

NO_DAMPERS = {f"{axle}.damper.curve.{i}.1": value for axle in ("front", "rear") for i, value in ((0, -1.0), (2, 1.0))}


def _front_axle(kind: str, cases: str, axle: str = "front") -> Scenario:
    """A rig test of the default car's front (or ``axle``) axle, two triangles a case, short settling."""
    return parse_scenario(f"name: {kind}\ntype: {kind}\nvehicle: {DEFAULT_VEHICLE}\naxles: [{axle}]\n"
                          f"output_rate_hz: 50\nsettle: {{before_bushings_s: 0.5, before_input_s: 0.5}}\n"
                          f"defaults: {{shape: triangle, cycles: 2}}\ncases: {cases}\n", Path(f"{kind}.yaml"))


#: Pumping of the front axle, 20 mm, slow and ten times faster.
SPEEDS = _front_axle("pumping", "[{amplitude_mm: 20, speed_mm_s: 2}, {amplitude_mm: 20, speed_mm_s: 20}]")


def _camber_loops(model: str, values: dict, equations: bool = False) -> list[float]:
    """The front left camber loops [deg] of :data:`SPEEDS`, ``model`` on every direction; with
    ``equations`` the family sets are figs. 5.8-5.9 as the equations read them (``fig5_8``, ``fig5_9``
    in place of the file's captions' ``*_caption``)."""
    scenario = replace(SPEEDS, bushing_model=model)
    text = DEFAULT_VEHICLE.read_text()
    if equations:
        text = re.sub(r"\bfig5_([89])_caption\b", r"fig5_\1", text)
    run = simulate(scenario, vehicle_with(text, DEFAULT_VEHICLE, values, "test"))
    return [case_loop(run, c, "pad_height_fl", "camber_fl", "pad_height_fl").width for c in cases(run)]


def test_the_camber_loop_thins_with_the_pumping_speed_through_the_dampers():
    rate_independent = _camber_loops("sts", NO_DAMPERS)
    with_dampers = _camber_loops("sts", {})
    dampers_alone = _camber_loops("linear", {})
    nothing = _camber_loops("linear", NO_DAMPERS)
    # the rig and the car's inertia make no loop; a rate-independent law nearly the same at both speeds
    assert max(nothing) < 0.02 * rate_independent[0]
    assert rate_independent[1] == pytest.approx(rate_independent[0], rel=0.08)
    # the dampers' own loop grows with the speed (viscous: about in proportion) and runs against the
    # sliders': with both, the loop thins, the more so the faster
    assert dampers_alone[1] > 5 * dampers_alone[0]
    assert with_dampers[0] < rate_independent[0] and with_dampers[1] < 0.5 * rate_independent[1]


#: Lateral force on the front axle, 100 daN triangles at 0.1 Hz (fig. 4.31's test).
LATERAL = _front_axle("lateral_force", "[{amplitude_daN: 100, frequency_hz: 0.1}]")


def _toe_loop(directions: tuple[str, ...]) -> float:
    """The front left toe loop's width [deg] against the lateral force with ``directions`` lossier at
    the same |K*| where the test works them (0.2 mm, 0.1 Hz: elastokin.vehicle.model.file_overrides.lossier_places)."""
    vehicle = load_vehicle(DEFAULT_VEHICLE)
    values = {k: v for d in directions for k, v in lossier_places(vehicle, d, 0.2e-3, 0.1).items()}
    run = simulate(LATERAL,
                   vehicle_with(DEFAULT_VEHICLE.read_text(), DEFAULT_VEHICLE, values, "test"), duration_scale=0.25)
    (c,) = cases(run)
    return case_loop(run, c, "pad_fy_fl", "toe_fl", "pad_fy_fl").width


def _rear_camber(bending_nm_per_rad: float | None, model: str) -> tuple[float, float]:
    """(range, loop width) [deg] of the rear left camber in 20 mm pumping of the rear axle at 20 mm/s,
    the twist beam bending at ``bending_nm_per_rad`` (None: rigid), ``model`` on every direction."""
    bending = {} if bending_nm_per_rad is None else {"rear.beam_bending_stiffness": bending_nm_per_rad}
    scenario = replace(_front_axle("pumping", "[{amplitude_mm: 20, speed_mm_s: 20}]", axle="rear"), bushing_model=model)
    run = simulate(scenario, vehicle_with(DEFAULT_VEHICLE.read_text(), DEFAULT_VEHICLE, bending, "test"))
    (c,) = cases(run)
    camber = run.signals["camber_rl"][case_mask(run, c)]
    return float(np.ptp(camber)), case_loop(run, c, "pad_height_rl", "camber_rl", "pad_height_rl").width


def test_a_bending_twist_beam_makes_a_rear_camber_loop_in_pumping():
    """Fig. 4.30's rear loop (report): a twist beam rigid in bending leaves the rear camber to the
    kinematics in pumping, with no loop; one that bends cambers the wheels further, the softer the
    more, and turns the wheel load's hysteresis (the dampers', with linear bushings) into a camber
    loop in proportion to its compliance (half the stiffness, twice the loop, within 5 %); with STVS
    bushings too the loop appears, over 20 times the rigid beam's."""
    (rigid, rigid_loop), *bent = (_rear_camber(k, "linear") for k in (None, 1e5, 5e4, 2.5e4))
    ranges, loops = zip(*bent)
    assert rigid < ranges[0] < ranges[1] < ranges[2]
    assert rigid_loop < 0.05 * loops[0]
    assert loops[1] == pytest.approx(2.0 * loops[0], rel=0.05) and loops[2] == pytest.approx(2.0 * loops[1], rel=0.05)
    assert _rear_camber(5e4, "stvs")[1] > 20.0 * _rear_camber(None, "stvs")[1]


def test_the_toe_loop_under_lateral_force_is_carried_by_the_front_pivot_bushing():
    """Fig. 4.31: a lossier front pivot bushing (E1 front, lateral) widens the toe loop a lot (+66 %
    measured); the wishbone's rear bushing made lossier in all three directions hardly (+1.6 %)."""
    with pytest.raises(PlaceError, match="no ladder law"):
        lossier_places(load_vehicle(DEFAULT_VEHICLE), "e1_front.x", 0.2e-3, 0.1)   # a linear direction
    base = _toe_loop(())
    assert _toe_loop(("e1_front.y",)) > 1.4 * base
    assert base < _toe_loop(("e2_front.x", "e2_front.y", "e2_front.z")) < 1.05 * base


def test_the_rear_pivot_bushing_follows_the_pumping_amplitude():
    run = simulate(replace(load_scenario("pumping"), bushing_model="stvs"), duration_scale=0.2)
    pp = [np.ptp(run.signals["e1_rear_right_z_deflection"][case_mask(run, c)]) for c in cases(run)]
    assert np.all(np.diff(pp) > 0)
    assert 2.5 <= pp[2] / pp[0] <= 3.3      # 30 mm against 10 mm (the caption's pair)
    assert 1.35 <= pp[2] / pp[1] <= 1.65    # 30 mm against 20 mm (the plot title's pair)


#: A 10 mm rack step of the default car ramped in ``rise`` s, ``law`` on every bushing direction.
RACK = ("name: rack\ntype: rack_step\nvehicle: {vehicle}\nbushings: {law}\noutput_rate_hz: 200\n"
        "settle: {{before_bushings_s: 1.0, before_input_s: 1.0}}\n"
        "cases: [{{rack_mm: 10, rise_time_s: {rise}, hold_s: 5.0}}]\n")


def _after_transient(scenario: Scenario, signals: tuple[str, ...]) -> dict[str, tuple[float, float]]:
    """Per signal, (its last step's own change from 0.5 s after that step's hold starts to the end,
    the step's own size by then): the run's less its control's, the same run without the last step
    (Scenario.without_last_steps: the car settling, an earlier step still relaxing)."""
    run = simulate(scenario)
    control = simulate(scenario.without_last_steps())
    (c,) = cases(run)
    on = case_mask(run, c)
    settled = np.searchsorted(run.t_s[on], c["hold_from_s"] + 0.5)
    out = {}
    for s in signals:
        own = run.signals[s][on] - control.signals[s][on]   # 0 until the last step begins
        out[s] = (float(own[-1] - own[settled]), float(own[settled]))
    return out


def test_the_car_does_not_relax_after_a_ringing_rack_step():
    """Figs. 4.32–4.39: a 10 mm rack step ramped in 50 ms rings the steered corner and then the E2
    front bushing's force hardly moves (the ringing works the laws to their relaxed state, the car's
    own settling too); ramped in 0.5 s, it rings far less (and relaxes: the next test)."""
    ringing = []
    for rise in (0.05, 0.5):
        run = simulate(parse_scenario(RACK.format(vehicle=DEFAULT_VEHICLE, law="stvs", rise=rise), Path("rack.yaml")))
        (c,) = cases(run)
        on = case_mask(run, c)
        t, force = run.t_s[on], run.signals["e2_front_left_y_force"][on]
        hold, settled = np.searchsorted(t, c["hold_from_s"]), np.searchsorted(t, c["hold_from_s"] + 0.5)
        ringing.append(np.ptp(force[hold:settled]))
        if rise == 0.05:
            at_rest = run.signals["e2_front_left_y_force"][np.searchsorted(run.t_s, c["input_start_s"])]
            assert abs(force[-1] - force[settled]) < 1e-3 * abs(force[-1] - at_rest)
    assert ringing[1] < 0.3 * ringing[0]


def test_after_a_smooth_rack_step_rt_relaxes_more_than_stvs():
    """Fig. 4.32 on the car (report: the control): the 0.5 s step's own relaxation, the car's settling
    taken away, gives back more of the force with RT than with STVS (1.86 % against 1.78 % of a 5.4 N
    step measured), and its deflection creeps on by some 30 % of its step, far more than the force
    relaxes: the corner sets the bushing's force, not its deflection."""
    force, deflection = "e2_front_left_y_force", "e2_front_left_y_deflection"
    share = {}
    for law in ("stvs", "rt"):
        own = _after_transient(parse_scenario(RACK.format(vehicle=DEFAULT_VEHICLE, law=law, rise=0.5),
                                              Path("rack.yaml")), (force, deflection))
        share[law] = {s: change / step for s, (change, step) in own.items()}
    for law in share:
        assert 0.01 < -share[law][force] < 0.03 and share[law][deflection] > 5.0 * -share[law][force]
    assert -share["rt"][force] > -share["stvs"][force]


def test_the_toe_lags_the_rack_more_with_viscoelastic_bushings():
    """Fig. 4.35: after a 50 ms rack ramp the toe reaches half its step a few milliseconds after the
    rack (the corner's inertia and compliant joints; 2.6 ms with linear bushings measured), later with
    STVS on every direction (4.1 ms)."""
    lag = {}
    for law in ("linear", "stvs"):
        scenario = parse_scenario(RACK.format(vehicle=DEFAULT_VEHICLE, law=law, rise=0.05), Path("rack.yaml"))
        run = simulate(replace(scenario, output_rate_hz=1000.0))
        (c,) = cases(run)
        lag[law] = case_lag_s(run, c, "toe_fl", "rack", 0.5, 0.5)
    assert 1e-3 < lag["linear"] < lag["stvs"] - 0.5e-3 and lag["stvs"] < 10e-3


def test_the_rt_camber_loop_is_thicker_than_the_stvs_one_at_low_speed():
    """Fig. 4.29: RT's camber loop in slow pumping is thicker than STVS's (1.9 % at 20 mm and 2 mm/s
    measured: the two family sets share their elastic and ladder stiffnesses, see the report)."""
    rt, stvs = _camber_loops("rt", {}), _camber_loops("stvs", {})
    assert 1.0 < rt[0] / stvs[0] < 1.2


def test_with_the_equations_reading_the_rt_camber_loop_is_clearly_thicker():
    """Figs. 5.8-5.9 as the equations read them (fig5_8, fig5_9: the STVS slider 80 %
    of the STS threshold, RT all of it at V0): RT's camber loop clearly thicker than STVS's, as fig.
    4.29 has it (×4.5 measured at 20 mm and 2 mm/s; the report: +45 % at 60 mm and 1.5 mm/s, against
    +2 % with the captions' sets)."""
    rt, stvs = _camber_loops("rt", {}, equations=True), _camber_loops("stvs", {}, equations=True)
    assert rt[0] / stvs[0] > 2.0


def test_a_second_smooth_rack_step_relaxes_back_whichever_way_it_goes():
    """Figs. 4.36–4.39 (RT, as the thesis ran them; every step ramped in 0.5 s): taken apart from what
    goes on from before it (the control: the first step alone, the car settling too), a smaller second
    step relaxes back towards where it started, whichever way it goes (+0.061 N after a step of
    −2.65 N, −0.065 N after one of +2.71 N measured)."""
    force = "e2_front_left_y_force"
    for way in ("same", "opposite"):
        shipped = load_scenario(f"double_rack_step_{way}")
        smooth = with_case_values(shipped, {"rise_time_s": 0.5}, "smooth steps")
        change, step = _after_transient(replace(smooth, bushing_model="rt"), (force,))[force]
        assert 0.01 < -change / step < 0.05 and abs(change) > 0.01


def _bench_relaxation(set_name: str, ringing_m: float = 0.0) -> float:
    """Fraction of its force a law loses from 0.5 s after a 50 ms ramp to 0.3 mm until 6 s, the
    deflection held (the bench), after a 20 Hz ringing of ``ringing_m`` that decays in 0.1 s."""
    dt = 1e-4
    t = np.arange(0.0, 6.0, dt)
    after = np.clip(t - 0.05, 0.0, None)
    e = np.clip(t / 0.05, 0.0, 1.0) * 0.3e-3 + ringing_m * np.sin(40 * np.pi * after) * np.exp(-after / 0.1)
    force, _ = BushingBank([load_parameter_set(set_name).channel()]).run(e[:, None], dt)
    return 1.0 - force[-1, 0] / force[5500, 0]


def test_the_laws_relax_on_the_bench_rt_more_than_stvs():
    """Fig. 4.32's bushing-level half: held after a 50 ms ramp to 0.3 mm, the force keeps falling
    from 0.5 s to 6 s, RT (fig5_8_caption) more than STVS (fig5_9_caption)."""
    assert 0.02 < _bench_relaxation("fig5_9_caption") < _bench_relaxation("fig5_8_caption") < 0.1


def test_a_ringing_after_the_step_works_the_relaxation_off():
    """Why the car's rack step shows no relaxation (report, figs. 4.32–4.39): the same bench step
    followed by a 20 Hz ringing of ±0.15 mm that decays in 0.1 s relaxes no further afterwards."""
    assert _bench_relaxation("fig5_9_caption") > 0.03 and abs(_bench_relaxation("fig5_9_caption", 0.15e-3)) < 0.002


def test_the_thesis_cars_lossy_bushings_thicken_the_camber_and_toe_loops():
    """The thesis's car (models/vehicles/c_segment_thesis.yaml: STVS of tan δ 0.3 at 15 Hz, 1 mm on its
    18 principal directions) against the default car with STVS of fig. 5.9's loss (0.17 there) on
    every direction: the loops of figs. 4.30 and 4.31 thicker (measured here +103 % camber at 2 mm/s,
    +78 % toe at 100 daN; the report's longer runs: +81 % camber at 1.5 mm/s, +53 to +88 % toe)."""
    thesis = load_vehicle("c_segment_thesis")

    def loops(scenario: Scenario, y: str, x: str, **run) -> tuple[float, float]:
        default = simulate(replace(scenario, bushing_model="stvs"), load_vehicle(DEFAULT_VEHICLE), **run)
        own = simulate(replace(scenario, bushing_model=None), thesis, **run)
        return tuple(case_loop(r, cases(r)[0], x, y, x).width for r in (default, own))

    camber = loops(SPEEDS, "camber_fl", "pad_height_fl")
    toe = loops(LATERAL, "toe_fl", "pad_fy_fl", duration_scale=0.25)
    assert camber[1] > 1.4 * camber[0]
    assert toe[1] > 1.3 * toe[0]
