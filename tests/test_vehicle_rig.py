"""The default car on the K&C rig: statics, kinematics, conventions, symmetry, loop closure."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from elastokin.vehicle.model.definition import CORNERS
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.kinematics import front_corner, rear_heave
from elastokin.vehicle.model.statics import axle_loads
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.simulation.rig import KCRig


@pytest.fixture(scope="module")
def vehicle():
    return load_vehicle()


@pytest.fixture(scope="module")
def rig(vehicle):
    r = KCRig(vehicle)
    r.settle(1.0)
    return r


def test_static_equilibrium_pad_forces_sum_to_weight(rig):
    weight, front, rear = axle_loads(rig.vehicle)
    o = rig.measure()
    fz = {c: w.pad_force[2] for c, w in o.wheels.items()}
    total = sum(fz.values())
    assert abs(total - weight) / weight < 0.005, (total, weight)
    assert abs(fz["front_left"] + fz["front_right"] - front) / front < 0.01
    assert abs(fz["rear_left"] + fz["rear_right"] - rear) / rear < 0.01


def test_left_right_symmetry_in_pumping(vehicle):
    r = KCRig(vehicle)
    r.settle(0.5)
    for o in [r.measure()] + r.pad_ramp([0] * 4, [0.04] * 4, 1.0, samples=2):
        for axle in ("front", "rear"):
            left, right = o.wheels[f"{axle}_left"], o.wheels[f"{axle}_right"]
            assert math.degrees(abs(left.camber - right.camber)) < 1e-3
            assert math.degrees(abs(left.toe - right.toe)) < 1e-3
            assert abs(left.half_track - right.half_track) < 1e-6
            assert abs(left.pad_force[2] - right.pad_force[2]) < 0.5


def test_loop_closure_below_0_1_mm_at_300_daN_lateral(vehicle):
    r = KCRig(vehicle)
    r.settle(0.3)
    r.set_pad_loads(fy=[3000.0] * 4)
    r.settle(1.0)
    o = r.measure()
    assert o.closure_error < 1e-4, o.closure_error
    # the load really went through: the lateral bushing directions deflect by tenths of a mm
    names = list(o.bushing_names)
    assert abs(o.bushing_deflection[names.index("e1_front_left.y")]) > 5e-5


def test_rigid_kinematics_match_hardpoint_solution(vehicle):
    """Rigid bushings: camber and toe against travel (±60 mm) vs scipy root finding on the links."""
    r = KCRig(vehicle, BuildOptions(rigid_bushings=True))
    r.settle(0.3)
    samples = r.pad_ramp([0] * 4, [0.06] * 4, 1.0, samples=6) + r.pad_ramp([0.06] * 4, [-0.06] * 4, 2.0, samples=12)
    guess = None
    worst = 0.0
    for o in samples:
        for corner in ("front_left", "rear_left"):
            w = o.wheels[corner]
            if corner == "front_left":
                ref, guess = front_corner(r.vehicle, w.pad_height, 0.0, guess)
            else:
                ref = rear_heave(r.vehicle, w.pad_height)
            worst = max(worst, abs(w.camber - ref.camber), abs(w.toe - ref.toe))
    assert math.degrees(worst) < 0.02, math.degrees(worst)
    # the sweep covered the travel and camber really changed (the check is not vacuous)
    heights = [o.wheels["front_left"].pad_height for o in samples]
    assert max(heights) > 0.055 and min(heights) < -0.055
    cambers = [o.wheels["front_left"].camber for o in samples]
    assert math.degrees(max(cambers) - min(cambers)) > 1.0


def test_sign_conventions(vehicle):
    """Toe-in, camber top-out, bump and left steer are positive (ISO 8855)."""
    front = dataclasses.replace(vehicle.front, static_toe=math.radians(2.0), static_camber=math.radians(3.0))
    r = KCRig(dataclasses.replace(vehicle, front=front))
    r.settle(0.3)
    o = r.measure()
    d = r.data
    for corner, sign in (("front_left", 1.0), ("front_right", -1.0)):
        w = o.wheels[corner]
        assert math.degrees(w.toe) == pytest.approx(2.0, abs=0.3)
        assert math.degrees(w.camber) == pytest.approx(3.0, abs=0.3)
        k = CORNERS.index(corner)
        rot = d.xmat[r.wheel_body[k]].reshape(3, 3)
        spin_left = rot[:, 1]
        heading = np.cross(spin_left, [0, 0, 1.0])
        top = np.cross(heading, spin_left)  # up in the wheel plane
        assert heading[0] > 0.99
        assert sign * heading[1] < 0, "toe-in: the wheel's front points towards the centre plane"
        assert sign * top[1] > 0, "positive camber: the wheel top leans outward"
        assert w.steer == pytest.approx(-sign * w.toe, abs=1e-9)
    # bump: raising the pads moves the wheel centres up and compresses the springs
    springs0 = o.spring_force["front_left_spring"]
    z0 = o.wheels["front_left"].wheel_centre[2]
    r.pad_ramp([0] * 4, [0.02] * 4, 0.5)
    r.settle(0.3)
    o = r.measure()
    assert o.wheels["front_left"].pad_height == pytest.approx(0.02, abs=5e-4)
    assert o.wheels["front_left"].wheel_centre[2] - z0 == pytest.approx(0.02, abs=2e-3)
    assert o.spring_force["front_left_spring"] > springs0 + 400.0
    # left steer: the rack (ahead of the axle) moves left, both wheels head left, steer > 0
    r.set_pads([0] * 4)
    r.set_rack(0.01)
    r.settle(0.5)
    o = r.measure()
    for corner in ("front_left", "front_right"):
        k = CORNERS.index(corner)
        heading = np.cross(d.xmat[r.wheel_body[k]].reshape(3, 3)[:, 1], [0, 0, 1.0])
        steer = math.atan2(heading[1], heading[0])
        assert o.wheels[corner].steer == pytest.approx(steer, abs=1e-12)
        assert math.degrees(o.wheels[corner].steer) > 1.0


def test_free_body_rests_at_design_ride_height(vehicle):
    """Body free (6 DOF) on the pads at design: ride height within 2 mm of design, pads carry the weight."""
    r = KCRig(vehicle, BuildOptions(clamped=False))
    r.settle(2.0)
    assert abs(r.ride_height() - vehicle.body.design_ride_height) < 2e-3, r.ride_height()
    assert np.abs(r.data.qvel[:6]).max() < 1e-3  # at rest
    weight, _, _ = axle_loads(r.vehicle)
    total = sum(w.pad_force[2] for w in r.measure().wheels.values())
    assert abs(total - weight) / weight < 0.005, (total, weight)


def test_compiled_steps_match_the_python_loop(vehicle):
    """rig.step (one compiled loop) = coupling.apply + mj_step called from Python, bit for bit."""
    import mujoco

    rigs = [KCRig(vehicle) for _ in range(2)]
    for r in rigs:
        r.set_pads([0.01, 0.01, -0.01, -0.01])
        r.set_pad_loads(fy=[500.0] * 4)
    rigs[0].step(300)
    m, d = rigs[1].model, rigs[1].data
    for _ in range(300):
        rigs[1].coupling.apply(m.opt.timestep)
        mujoco.mj_step(m, d)
    assert np.array_equal(rigs[0].data.qpos, d.qpos)
    assert np.array_equal(rigs[0].coupling.bushings.forces(), rigs[1].coupling.bushings.forces())


def test_played_inputs_match_the_setters_step_by_step(vehicle):
    """rig.play (each row set inside the compiled loop) = the Python setters then one step per row,
    bit for bit; a ramp's inputs follow its linear law."""
    rigs = [KCRig(vehicle) for _ in range(2)]
    t = np.arange(1, 201) * 1e-3
    rows = np.column_stack([np.outer(np.sin(20 * t), [0.01, 0.012, -0.01, -0.008]),
                            np.outer(t, [100.0, 0, 0, -100.0]), np.outer(np.cos(30 * t), [300.0] * 4),
                            np.outer(t, [10.0, -10.0, 5.0, -5.0]), 0.004 * t])
    rigs[0].play(rows)
    for u in rows:
        rigs[1].set_inputs(u)
        rigs[1].step()
    assert np.array_equal(rigs[0].data.qpos, rigs[1].data.qpos)
    assert np.array_equal(rigs[0].data.xfrc_applied, rigs[1].data.xfrc_applied)
    with pytest.raises(ValueError, match=r"shape \(steps, 17\)"):
        rigs[0].play(rows[:, :16])
    rigs[0].ramp(0.05, pads=([0.0] * 4, [0.02, 0.01, 0.0, -0.01]))
    assert np.allclose(rigs[0].model.eq_data[rigs[0].pad_eq, 0], [0.02, 0.01, 0.0, -0.01], rtol=0, atol=1e-15)
    assert rigs[0].model.eq_data[rigs[0].rack_eq, 0] == rows[-1, 16]  # the ramp holds the rack


def test_a_reset_rig_repeats_a_fresh_rigs_run_bit_for_bit(vehicle):
    """reset() returns the bushings of the compiled loop to their virgin state: a rig that ran a
    pumping stroke, was reset and ran it again gives exactly what a fresh rig gives, whereas the
    stroke run a second time without reset does not (the STVS ladders remember the first)."""

    def stroke(rig: KCRig) -> np.ndarray:
        rig.settle(0.2)
        out = rig.pad_ramp([0.0] * 4, [0.03] * 4, 0.3, samples=2) + rig.pad_ramp([0.03] * 4, [0.0] * 4, 0.3, samples=2)
        return np.array([o.bushing_force for o in out])

    fresh = stroke(KCRig(vehicle))
    used = KCRig(vehicle)
    stroke(used)
    used.settle(0.1)
    unreset = stroke(used)
    used.reset()
    np.testing.assert_array_equal(stroke(used), fresh)
    assert np.abs(unreset - fresh).max() > 1.0  # N: the first stroke's memory, the state reset() clears


def test_sampled_run_matches_playing_and_measuring_from_python(vehicle):
    """rig.sampled (steps, mj_forward and the measurement in one compiled loop) = play() then
    measure() from Python at every sample, bit for bit, body poses included; with the inputs held
    it equals step()."""
    import mujoco

    rigs = [KCRig(vehicle) for _ in range(2)]
    every, samples = 15, 6
    t = np.arange(1, every * samples + 1) * 1e-3
    rows = np.zeros((len(t), 17))
    rows[:, :4] = np.outer(np.sin(25 * t), [0.01, 0.012, -0.01, -0.008])
    rows[:, 8:12] = np.outer(t, [2000.0] * 4)
    rows[:, 16] = 0.003 * t
    bodies = np.arange(1, rigs[0].model.nbody)
    measured, pos, quat = rigs[0].sampled(samples, every, rows, bodies)
    r, d = rigs[1], rigs[1].data
    for k in range(samples):
        r.play(rows[k * every:(k + 1) * every])
        o, a = r.measure(), rigs[0].outputs(measured[k])
        np.testing.assert_array_equal(pos[k], d.xpos[bodies])
        np.testing.assert_array_equal(quat[k], d.xquat[bodies])
        np.testing.assert_array_equal(a.bushing_force, o.bushing_force)
        np.testing.assert_array_equal(a.bushing_deflection, o.bushing_deflection)
        assert (a.spring_force, a.damper_force, a.closure_error) == (o.spring_force, o.damper_force, o.closure_error)
        for c in CORNERS:
            w, v = a.wheels[c], o.wheels[c]
            assert (w.camber, w.toe, w.steer, w.half_track, w.travel, w.pad_height, w.pad_torque) == \
                   (v.camber, v.toe, v.steer, v.half_track, v.travel, v.pad_height, v.pad_torque)
            np.testing.assert_array_equal(w.pad_force, v.pad_force)
    held = rigs[0].sampled(2, every)[0][-1]
    r.step(2 * every)
    mujoco.mj_forward(r.model, d)
    np.testing.assert_array_equal(held, rigs[0].sampled(1, 0)[0][0])   # no steps: the same instant again
    assert r.outputs(held).bushing_force.tolist() == r.measure().bushing_force.tolist()


def test_measured_quantities_against_their_definitions(vehicle):
    """The compiled measurement against the quantities read from MuJoCo another way: the pad's Fz
    is the force of its drive equality's row in the last step (not the row mj_forward recomputes
    with that step's target held), the spring force its curve at the spring's
    compression plus preload, a wheel's travel its centre's height change, the closure error the
    largest closure row error; and the measurement refuses to run once MuJoCo's constraint rows
    have moved (a friction row added)."""
    import mujoco

    r = KCRig(vehicle)
    r.set_pads([0.02, -0.01, 0.015, 0.0])
    r.settle(0.5)
    m, d = r.model, r.data
    rows = np.flatnonzero(d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    drives = [rows[d.efc_id[rows] == r.pad_eq[k]][0] for k in range(len(CORNERS))]
    stepped = d.efc_force[drives].copy()    # the rows of the last step (no mj_forward since)
    o = r.measure()
    assert r.measure().wheels["front_left"].pad_force[2] == o.wheels["front_left"].pad_force[2]  # no step: same
    for k, c in enumerate(CORNERS):
        assert o.wheels[c].pad_force[2] == stepped[k]
        assert o.wheels[c].travel == pytest.approx(o.wheels[c].wheel_centre[2] - r.design_centre_z[k], abs=1e-15)
    spring = r.coupling.springs[0]
    joint = spring.kind == "joint"
    coord = d.qpos[m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, spring.target)]] if joint else \
        d.ten_length[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_TENDON, spring.target)]
    x = spring.sign * (coord - r.coupling.sp_design[0])
    curve = spring.spring.curve
    expected = spring.preload + np.interp(x, curve.x, curve.y) - curve(0.0)
    assert o.spring_force[spring.name] == pytest.approx(expected, rel=1e-12)
    closure = [np.linalg.norm(d.efc_pos[rows[d.efc_id[rows] == eq]][:n]) for eq, n in zip(r.closure_eq, r.closure_rows)]
    assert o.closure_error == pytest.approx(max(closure), rel=1e-12)
    m.dof_frictionloss[0] = 1.0
    with pytest.raises(RuntimeError, match="constraint rows moved"):
        r.measure()


def test_a_sampled_block_ends_at_mujocos_reset(vehicle):
    """When MuJoCo resets the state (a non-finite position here), the compiled sampling stops after
    the first sample that follows, and the rig says it was reset."""
    r = KCRig(vehicle)
    measured, _, _ = r.sampled(5, 10)
    assert len(measured) == 5 and not r.was_reset()
    r.data.qpos[r.coupling.bushings.qpos[0]] = np.nan
    measured, pos, quat = r.sampled(5, 10)
    assert len(measured) == len(pos) == len(quat) == 1 and r.was_reset()
    assert np.isfinite(measured).all()   # the sample after the reset: the design pose again
