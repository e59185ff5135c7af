"""The catalogue's extensions switched on in the vehicle (spec measured-data.md §2).

Bushing law effects (elastokin.bushings.effects) on the vehicle's channels, strut friction, the twist beam's
torsion scale and a bushing's directional coupling: each test says what it holds and to what
tolerance, with numbers.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from elastokin.bushings import BushingBank, load_parameter_set
from elastokin.bushings.effects import NO_EFFECTS
from elastokin.bushings.extended_bank import ExtendedBank
from tests.test_vehicle_definition import _write
from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.kinematics import front_corner
from elastokin.vehicle.model.vehicle_file import load_vehicle, with_extensions
from elastokin.vehicle.scenarios.kc_tests import TEST
from elastokin.vehicle.simulation.kc_triangles import design_contact_base, run_triangle
from elastokin.vehicle.simulation.rig import KCRig
from elastokin.analysis.kc_metrics import fit_window, triangle_metrics
from elastokin.analysis.kc_test import rig_leg
from elastokin.analysis.loops import Branches, centre_slope, loop_width
from elastokin.core.errors import InputError

LINEAR = BuildOptions(bushing_model="linear")


@pytest.fixture(scope="module")
def vehicle() -> VehicleDefinition:
    return load_vehicle()


def _vehicle_file(tmp_path: Path, edit) -> VehicleDefinition:
    """The default car file after ``edit(data)``, loaded from ``tmp_path``."""
    return load_vehicle(_write(tmp_path, edit))


def _pumping_history(rig: KCRig, steps: int, amplitude: float = 0.03, hz: float = 2.0):
    """Step a growing 2 Hz pumping sine one step at a time: (deflections before each step (T, M),
    bank forces after it (T, bank size), bank tangents after it)."""
    b = rig.coupling.bushings
    h = rig.model.opt.timestep
    e, f, k = [], [], []
    for i in range(steps):
        t = i * h
        rig.set_pads([amplitude * t / (steps * h) * math.sin(2 * math.pi * hz * t)] * 4)
        e.append(b.deflections())
        rig.step(1)
        f.append(b.bank.force.copy())
        k.append(b.bank.tangent.copy())
    return np.array(e), np.array(f), np.array(k)


def test_without_effects_the_step_loop_is_bit_identical_to_the_plain_kernel(vehicle):
    """No effects: every step of the vehicle's bank (step_extended) returns exactly the forces and
    tangents of the plain kernel (step_bank) on the same deflections, so the loop, which uses
    nothing else of the bank, follows the trajectory of the loop that called step_bank."""
    rig = KCRig(vehicle, BuildOptions(bushing_model="stvs"))
    assert not any(ch.effects.active for ch in rig.car.channels) and not rig.car.cross
    e, f, k = _pumping_history(rig, 400)
    b = rig.coupling.bushings
    plain = BushingBank(b.bank.bank.channels)
    for t in range(len(e)):
        force, tangent = plain.step(e[t, b.bank_idx], rig.model.opt.timestep)
        assert np.array_equal(force, f[t]) and np.array_equal(tangent, k[t]), t
    assert b.bank.size == 36 and np.abs(f).max() > 100.0  # 36 STVS channels, really loaded


def test_mullins_and_heating_act_in_the_vehicle_as_in_their_extended_bank(vehicle):
    """Mullins on e1_rear.z and self-heating on e1_front.y: the vehicle's force histories of those
    directions equal an ExtendedBank of the same law and effects replayed on the recorded
    deflections (to round-off, 1e-9 of the peak), and differ from the law without effects by > 3 %."""
    effects = {"e1_rear.z": {"mullins": 0.3}, "e1_front.y": {"heating": 2000.0, "heating_tau_s": 5.0}}
    v = with_extensions(vehicle, effects=effects)
    rig = KCRig(v)
    e, f, _ = _pumping_history(rig, 2000)
    names = [ch.name for ch in rig.car.channels]
    bank_idx = list(rig.coupling.bushings.bank_idx)
    bushings = {bu.name: bu for bu in v.bushings}
    h = rig.model.opt.timestep
    for target in effects:
        bushing, direction = target.split(".")
        d = bushings[bushing].directions[direction]
        for side in ("left", "right"):  # the right's law is the left's mirror image: the same for these
            i = names.index(f"{bushing}_{side}.{direction}")
            vehicle_force = f[:, bank_idx.index(i)]
            replay = ExtendedBank([d.channel()], [d.effects_si()]).run(e[:, i], h)[:, 0]
            bare = ExtendedBank([d.channel()], [NO_EFFECTS]).run(e[:, i], h)[:, 0]
            peak = np.abs(vehicle_force).max()
            assert np.abs(vehicle_force - replay).max() <= 1e-9 * peak, target
            assert np.abs(vehicle_force - bare).max() > 0.03 * peak, target


def test_a_slipping_interface_acts_as_in_its_bank_and_the_reference_stiffness_holds_its_stick(vehicle):
    """An interface slipping at 80 N with 2·K0 before slip on e1_rear.z: the vehicle's force
    history equals its ExtendedBank replayed on the recorded deflections (1e-9 of the peak), and the
    force's slope from step to step never exceeds the reference stiffness K_ref the joint carried
    (1e-6), whose floor is the joint's K plus the interface's 2·K0: at every reversal the stuck
    interface brings its stiffness back at once, 1.5 times and more the joint's alone."""
    target = "e1_rear.z"
    v = with_extensions(vehicle, effects={target: {"slip_force": 80.0, "slip_stiffness": 2.0}})
    rig = KCRig(v)
    b = rig.coupling.bushings
    i = [ch.name for ch in rig.car.channels].index("e1_rear_left.z")
    j = list(b.bank_idx).index(i)
    K0 = rig.car.channels[i].params.K0
    assert b.K_floor[j] == pytest.approx(b.K[i] + 2.0 * K0, rel=1e-12)
    h, steps = rig.model.opt.timestep, 3000
    e, f, k_ref = np.empty(steps), np.empty(steps), np.empty(steps)
    for s in range(steps):
        t = s * h
        rig.set_pads([0.03 * t / (steps * h) * math.sin(4 * math.pi * t)] * 4)
        e[s], k_ref[s] = b.deflections()[i], b.K_ref[j]   # the stiffness the joint carries in this step
        rig.step(1)
        f[s] = b.bank.force[j]
    bushing, direction = target.split(".")
    law = next(bu for bu in v.bushings if bu.name == bushing).directions[direction]
    replay = ExtendedBank([law.channel()], [law.effects_si()]).run(e, h)[:, 0]
    assert np.abs(f - replay).max() <= 1e-9 * np.abs(f).max() and np.abs(f).max() > 500.0
    moved = np.abs(np.diff(e)) > 1e-7
    secant = (np.diff(f) / np.where(moved, np.diff(e), 1.0))[moved]
    assert np.all(secant <= k_ref[1:][moved] * (1.0 + 1e-6))
    assert secant.max() > 1.5 * b.K[i]   # the stick the floor holds: a tangent-following K_ref lags it


def test_preload_keeps_design_pad_forces_and_moves_the_tangent_along_the_elastic_law(tmp_path):
    """e1_rear.z on a progressive law (fig5_6_progressive), with and without a 4 mm preload from
    the vehicle file: mounted at design with zero force, so the pad forces at design height stay
    within 0.5 %, while the direction's tangent at design is Kpa (stuck ladder) plus the elastic
    law's tangent at preload + static deflection (to 1e-5), 25 % and more above the unpreloaded one."""
    preload_mm = 4.0

    def car(effects):
        def edit(data):
            data["bushings"][2]["directions"]["z"] = {"set": "fig5_6_progressive", "effects": effects}
        return _vehicle_file(tmp_path, edit)

    law = load_parameter_set("fig5_6_progressive").channel()
    elastic = law.replace(model="elastic", n_cells=0)
    pads, tangents = {}, {}
    for preload in (0.0, preload_mm):
        rig = KCRig(car({"preload": preload}))
        rig.settle(1.0)
        pads[preload] = np.array([w.pad_force[2] for w in rig.measure().wheels.values()])
        b = rig.coupling.bushings
        i = [ch.name for ch in rig.car.channels].index("e1_rear_left.z")
        tangent = b.bank.tangent[list(b.bank_idx).index(i)]
        _, k_el = BushingBank([elastic]).step(np.array([preload * 1e-3 + b.deflections()[i]]), 1e-3)
        assert tangent - law.Kpa == pytest.approx(k_el[0], rel=1e-5)
        tangents[preload] = tangent
    assert np.abs(pads[preload_mm] / pads[0.0] - 1.0).max() < 0.005
    assert tangents[preload_mm] > 1.25 * tangents[0.0]


def test_a_preload_is_mirrored_on_the_right_side(vehicle):
    """A preload on e1_front.y, whose axis is reversed on the right: the right channel gets the
    opposite preload and the mirrored law, so pumping keeps toe and camber left/right symmetric."""
    rig = KCRig(with_extensions(vehicle, effects={"e1_front.y": {"preload": 1.5}}))
    preloads = {ch.name: ch.effects.preload for ch in rig.car.channels}
    assert preloads["e1_front_left.y"] == pytest.approx(1.5e-3) == -preloads["e1_front_right.y"]
    rig.settle(0.3)
    for o in rig.pad_ramp([0.0] * 4, [0.03] * 4, 0.6, samples=3):
        left, right = o.wheels["front_left"], o.wheels["front_right"]
        assert math.degrees(abs(left.toe - right.toe)) < 1e-3 and math.degrees(abs(left.camber - right.camber)) < 1e-3


def _front_pad_loop(v: VehicleDefinition, amplitude: float = 0.01, rate: float = 0.002) -> float:
    """Width at design height [N] of the front-left pad force against pad height, in slow pumping."""
    rig = KCRig(v, LINEAR)
    rig.settle(0.3)
    top = np.full(4, amplitude)
    rig.ramp(amplitude / rate, pads=(np.zeros(4), top))
    down = rig.ramp(2 * amplitude / rate, 100, pads=(top, -top))
    up = rig.ramp(2 * amplitude / rate, 100, pads=(-top, top))
    z = lambda samples: np.array([o.wheels["front_left"].pad_height for o in samples])
    fz = lambda samples: np.array([o.wheels["front_left"].pad_force[2] for o in samples])
    return loop_width(Branches(z(down), fz(down), z(up), fz(up)), 0.8 * amplitude)[0]


def test_strut_friction_widens_the_pad_force_loop_by_twice_the_mapped_friction(vehicle):
    """200 N of rod friction, ±10 mm pumping at 2 mm/s, linear bushings: the front pad-force loop
    is 2·F·MR wide (MR = strut compression per wheel travel, from the rigid kinematics) within
    20 %; without friction the loop (damper only, ≈ 9 N) is below 5 % of that."""
    friction = 200.0
    plus, _ = front_corner(vehicle, 5e-4)
    minus, _ = front_corner(vehicle, -5e-4)
    ratio = -(plus.strut_extension - minus.strut_extension) / 1e-3
    expected = 2.0 * friction * ratio
    assert 0.8 < ratio < 1.0
    assert _front_pad_loop(with_extensions(vehicle, strut_friction=friction)) == pytest.approx(expected, rel=0.2)
    assert _front_pad_loop(vehicle) < 0.05 * expected


def _rear_roll(v: VehicleDefinition) -> tuple[float, float, float]:
    """(roll stiffness [N·m/deg] of the rear axle at the pads, roll steer, roll camber [deg/deg])."""
    rig = KCRig(v, LINEAR)
    base = design_contact_base(rig)["rear"]
    samples = run_triangle(rig, TEST["roll"])
    down, up = (rig_leg(s) for s in samples)
    window = fit_window("roll", TEST["roll"].amplitude, base)
    m = triangle_metrics("roll", "rear", down, up, window, base)
    roll = lambda g: np.degrees((g("pad_height", "rear_right") - g("pad_height", "rear_left")) / base)
    moment = lambda s: np.array([o.wheels["rear_right"].pad_force[2] - o.wheels["rear_left"].pad_force[2]
                                 for o in s]) * base / 2
    k = centre_slope(Branches(roll(down), moment(samples[0]), roll(up), moment(samples[1])), window)
    return k, m["roll_steer_deg_per_deg"], m["roll_camber_deg_per_deg"]


def test_beam_torsion_scale_scales_the_beam_share_of_rear_roll_stiffness(vehicle):
    """The beam's share of the rear roll stiffness is K(1) − K(≈0) (scale 1e-3); with the beam
    doubled the stiffness is K(0) + 2·share within 5 %: the beam acts in series with the arm
    pivots' rotational compliance, so its share grows a little less than linearly (−2.8 % measured).
    A stiffer beam brings the axle towards a rigid axle, whose wheels keep their camber and toe to
    the pads in roll: roll camber and roll steer both fall."""
    k0, steer0, camber0 = _rear_roll(with_extensions(vehicle, beam_torsion_scale=1e-3))
    k1, steer1, camber1 = _rear_roll(vehicle)
    k2, steer2, camber2 = _rear_roll(with_extensions(vehicle, beam_torsion_scale=2.0))
    share = k1 - k0
    assert 0.3 * k1 < share < 0.7 * k1
    assert k2 == pytest.approx(k0 + 2.0 * share, rel=0.05)
    assert camber0 > camber1 > camber2 and steer0 > steer1 > steer2


def test_directional_coupling_gives_the_cross_force_and_stores_energy_without_loss(vehicle):
    """x–z coupling of 80 N/mm on e1_rear. Statics: 1 mm of x alone gives k·e on z (N), the right
    side's x axis being reversed gives −k·e there; the compiled step writes exactly that. Over a
    closed cycle of combined pumping and lateral force (linear laws: elastic), the bushing's x and
    z forces as the vehicle reports them do no net work (round-off, against the work a one-way
    term F_x = k·e_z would do on the same path, which is not small)."""
    k_n_per_m = 80e3
    v = with_extensions(vehicle, coupling={"e1_rear": [{"directions": ["x", "z"], "stiffness": 80.0}]})
    rig = KCRig(v, LINEAR)
    m, d = rig.model, rig.data
    names = [ch.name for ch in rig.car.channels]
    b = rig.coupling.bushings
    for side, sign in (("left", 1.0), ("right", -1.0)):
        ix, iz = names.index(f"e1_rear_{side}.x"), names.index(f"e1_rear_{side}.z")
        mujoco.mj_resetData(m, d)
        d.qpos[b.qpos[ix]] = 1e-3
        mujoco.mj_forward(m, d)
        rig.coupling.apply(m.opt.timestep)
        assert d.qfrc_applied[b.dof[iz]] == pytest.approx(-sign * k_n_per_m * 1e-3, rel=1e-12)
        assert b.forces()[iz] == pytest.approx(sign * k_n_per_m * 1e-3, rel=1e-12)
        assert b.forces()[ix] == pytest.approx(b.K[ix] * 1e-3, rel=1e-12)  # no z, no cross force on x

    rig.reset()
    rig.settle(0.3)
    ix, iz = names.index("e1_rear_left.x"), names.index("e1_rear_left.z")
    path, force = [], []
    n = 2000
    for i in range(n):
        phase = 2 * math.pi * i / n
        rig.set_pads([0.02 * math.sin(phase)] * 4)
        rig.set_pad_loads(fy=[1500.0 * (1.0 - math.cos(phase))] * 4)
        rig.step(1)
        path.append(b.deflections()[[ix, iz]])
        force.append(b.forces()[[ix, iz]])
    # close the cycle on its first sample (the car is back within microns of it)
    (ex, ez), (fx, fz) = np.array(path + path[:1]).T, np.array(force + force[:1]).T
    mid = lambda a: 0.5 * (a[1:] + a[:-1])
    work = np.sum(mid(fx) * np.diff(ex) + mid(fz) * np.diff(ez))
    one_way = abs(np.sum(k_n_per_m * mid(ez) * np.diff(ex)))
    assert one_way > 1e-3  # [J]: the path encloses area in the (e_x, e_z) plane
    assert abs(work) < 1e-9 * one_way


def test_extension_keys_are_validated_in_the_vehicle_file(tmp_path):
    """Bad values of the new keys raise InputError naming the file and the dotted key."""
    cases = [
        (lambda d: d["front"].update(strut_friction=-5.0), "front.strut_friction", "non-negative"),
        (lambda d: d["front"].update(strut_friction={"left": 10.0}), "front.strut_friction.right", "missing"),
        (lambda d: d["rear"].update(beam_torsion_scale=0.0), "rear.beam_torsion_scale", "positive"),
        (lambda d: d["bushings"][2]["directions"]["z"].update(effects={"mulins": 0.2}),
         "bushings[2].directions.z", "unknown effect"),
        (lambda d: d["bushings"][2].update(coupling=[{"directions": ["x", "rz"], "stiffness": 1.0}]),
         "bushings[2].coupling[0].directions", "translation with a rotation"),
        (lambda d: d["bushings"][2].update(coupling=[{"directions": ["x", "z"], "stiffness": 400.0}]),
         "bushings[2].coupling[0].stiffness", "positive definite"),
    ]
    for edit, key, words in cases:
        with pytest.raises(InputError) as err:
            _vehicle_file(tmp_path, edit)
        assert str(tmp_path) in str(err.value) and key in str(err.value) and words in str(err.value), str(err.value)
    with pytest.raises(InputError, match="with_extensions: effects.e9.z: unknown bushing"):
        with_extensions(load_vehicle(), effects={"e9.z": {"mullins": 0.1}})


def test_a_mirrored_direction_is_the_left_law_turned_about_the_origin():
    """The right side's law of a mirrored direction is F_right(e) = −F_left(−e), its preload and
    both parts of its asymmetry (kink and progressive) included, along a loading history."""
    from elastokin.bushings.effects import Effects
    from elastokin.vehicle.model.geometry import mirrored_law

    ch = load_parameter_set("fig5_9_progressive").channel("elastic")
    left = Effects(preload=2e-4, asymmetry=0.1e3, asymmetry_step=0.3)
    right_ch, right = mirrored_law(ch, left, -1.0)
    e = 1.5e-3 * np.sin(np.linspace(0.0, 4.0 * np.pi, 400))
    f_left = ExtendedBank([ch], [left]).run(e, 0.01)[:, 0]
    f_right = ExtendedBank([right_ch], [right]).run(-e, 0.01)[:, 0]
    np.testing.assert_allclose(f_right, -f_left, rtol=1e-9, atol=1e-6)
