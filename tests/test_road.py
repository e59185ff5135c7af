"""The car on the road (issue 26, step 3): the rig's car mounted free on its Magic Formula tyres;
it settles where the rig's statics and the tyres' vertical law put it, a braked car does not
creep, a coasting car loses energy and keeps straight."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.optimize import brentq

from elastokin.vehicle.model.builder import build
from elastokin.vehicle.model.definition import CORNERS
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.statics import resolve_preloads
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.simulation.rig import KCRig
from elastokin.vehicle.simulation.road import RoadCar
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.tyres import magic_formula as mf
from elastokin.tyres.road_contact import SIGNALS

FZ, FX, FY, VX = (SIGNALS.index(k) for k in ("Fz_N", "Fx_N", "Fy_N", "vx_mps"))


def settled(brakes: float, seconds: float = 6.0) -> RoadCar:
    car = RoadCar(load_vehicle(DEFAULT_VEHICLE))
    car.set_brakes(brakes)
    car.step(int(seconds / car.model.opt.timestep))
    return car


def wheel_centres(car: RoadCar) -> np.ndarray:
    mujoco.mj_kinematics(car.model, car.data)
    return car.data.xipos[car.wheel_body].copy()


def test_the_car_settles_where_the_rig_statics_and_the_tyres_put_it() -> None:
    car = settled(brakes=300.0)
    rig = KCRig(load_vehicle(DEFAULT_VEHICLE))
    rig.settle(1.0)
    pads = np.array([rig.measure().wheels[c].pad_force[2] for c in CORNERS])
    fz = car.tyre_signals[:, FZ]
    # the same car: the road carries each corner as the rig's pads do at design
    np.testing.assert_allclose(fz, pads, rtol=0.01)
    np.testing.assert_allclose(fz.sum(), mujoco.mj_getTotalmass(car.model) * 9.81, rtol=1e-3)
    # each wheel centre stands at the tyre's loaded radius under that load (the road is z = 0)
    tyre = car.tyres[0]
    loaded = [tyre["UNLOADED_RADIUS"] - brentq(lambda d: mf.vertical_force(tyre, d, 0.0) - f, 0.0, 0.1) for f in pads]
    centres = wheel_centres(car)
    np.testing.assert_allclose(centres[:, 2], loaded, atol=3e-4)
    # the body sits on the suspension as at design, lowered with its wheels (interpolated between axles)
    design = car.vehicle.body.design_ride_height
    drop = centres[:, 2] - car.vehicle.tyre.radius
    x_point = car.vehicle.body.ride_height_point[0]
    x_front, x_rear = centres[0, 0], centres[2, 0]
    share = (x_point - x_rear) / (x_front - x_rear)
    expected = design + share * drop[:2].mean() + (1 - share) * drop[2:].mean()
    assert car.ride_height() == pytest.approx(expected, abs=2e-3)
    # the vehicle file's loaded radius is its tyre's: the car stands at its design ride height
    assert car.ride_height() == pytest.approx(design, abs=2e-3)
    assert abs(centres[0, 1] + centres[1, 1]) < 1e-5 and abs(centres[2, 1] + centres[3, 1]) < 1e-5   # symmetric


def test_a_braked_car_at_rest_does_not_creep() -> None:
    car = settled(brakes=300.0)
    before = car.car.body_point(car.data, [0.0, 0.0, 0.0])
    car.step(round(4.0 / car.model.opt.timestep))
    moved = car.car.body_point(car.data, [0.0, 0.0, 0.0]) - before
    assert np.abs(moved).max() < 5e-5                      # 0.05 mm in 4 s
    assert np.abs(car.data.qvel[:3]).max() < 1e-4


def test_a_coasting_car_loses_energy_steadily_and_keeps_straight() -> None:
    car = settled(brakes=0.0, seconds=3.0)
    car.set_speed(20.0)
    energy, speed = [], []
    for _ in range(12):
        car.step(round(0.25 / car.model.opt.timestep))
        energy.append(car.energy())
        speed.append(car.data.qvel[0])
    assert np.all(np.diff(energy) < 0)                     # rolling resistance only takes
    # the speed falls as the rolling resistance of the four tyres pulls (≈ 1 % of the weight)
    decel = -(speed[-1] - speed[0]) / (11 * 0.25)
    weight = mujoco.mj_getTotalmass(car.model) * 9.81
    resistance = -car.tyre_signals[:, SIGNALS.index("My_Nm")].sum() / car.tyres[0]["UNLOADED_RADIUS"]
    assert decel * weight / 9.81 == pytest.approx(resistance, rel=0.25)
    assert 0.008 < resistance / weight < 0.02
    assert abs(car.data.qpos[1]) < 1e-3 and abs(car.data.qvel[5]) < 1e-3   # no drift nor yaw
    np.testing.assert_allclose(car.tyre_signals[:, VX], speed[-1], rtol=0.01)


def test_the_road_mounting_is_the_rig_car_without_the_rig() -> None:
    vehicle = resolve_preloads(load_vehicle(DEFAULT_VEHICLE))
    road = build(vehicle, BuildOptions(rig=False, clamped=False, road=True)).model
    rig = build(vehicle, BuildOptions()).model
    name = lambda m, kind, i: mujoco.mj_id2name(m, kind, i)
    bodies = lambda m: {name(m, mujoco.mjtObj.mjOBJ_BODY, i) for i in range(m.nbody)}
    assert bodies(rig) - bodies(road) == {f"{part}_{c}" for part in ("pad", "carriage") for c in CORNERS}
    assert bodies(road) <= bodies(rig)
    assert mujoco.mj_name2id(road, mujoco.mjtObj.mjOBJ_EQUALITY, "rack_drive") >= 0
    assert mujoco.mj_name2id(road, mujoco.mjtObj.mjOBJ_GEOM, "road") >= 0
    assert road.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE
    with pytest.raises(ValueError, match="neither on the rig nor clamped"):
        build(vehicle, BuildOptions(road=True))


def test_the_compiled_road_measurement_is_its_definition() -> None:
    """The measured vector of a car turning at speed against its definition computed with MuJoCo's
    Python API and numpy: ISO 8855 body angles, speeds and accelerations in the intermediate axes
    (MuJoCo's accelerations carry −g), wheel angles and travel in the body frame, the tyres' signals."""
    from elastokin.vehicle.model.kinematics import wheel_angles
    from elastokin.vehicle.model.definition import SIDE_SIGN

    car = settled(brakes=0.0, seconds=1.0)
    car.set_speed(15.0)
    steps = 400
    u = car.drive_inputs(np.full(steps, 1.5), np.full(steps, 15.0))   # 1.5 rad of steering wheel: a turn
    measured, _, _ = car.sampled(2, steps // 2, u)
    cols, m, d = car.columns, car.model, car.data
    v = measured[-1]
    mujoco.mj_forward(m, d)
    mujoco.mj_rnePostConstraint(m, d)
    rot = d.xmat[car.chassis].reshape(3, 3)
    motion, acc = np.zeros(6), np.zeros(6)
    mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, car.chassis, motion, 0)
    mujoco.mj_objectAcceleration(m, d, mujoco.mjtObj.mjOBJ_BODY, car.chassis, acc, 0)
    yaw = np.arctan2(rot[1, 0], rot[0, 0])
    to_road = np.array([[np.cos(yaw), np.sin(yaw)], [-np.sin(yaw), np.cos(yaw)]])
    speed = to_road @ motion[3:5]
    accel = to_road @ (acc[3:5] + m.opt.gravity[:2])
    expected = {"x": d.xipos[car.chassis, 0], "y": d.xipos[car.chassis, 1], "yaw": yaw,
                "roll": np.arctan2(rot[2, 1], rot[2, 2]), "pitch": -np.arcsin(rot[2, 0]), "speed": speed[0],
                "lateral_speed": speed[1], "yaw_rate": motion[2], "longitudinal_acceleration": accel[0],
                "lateral_acceleration": accel[1], "sideslip": np.arctan2(speed[1], speed[0]),
                "rack": d.qpos[car.rack_qpos], "drive_force": car.driver_state[1]}
    for name, value in expected.items():
        assert v[cols.of(name)] == pytest.approx(value, rel=1e-9, abs=1e-12), name
    assert abs(v[cols.of("yaw_rate")]) > 0.05 and abs(v[cols.of("lateral_acceleration")]) > 0.5   # turning
    for k, corner in enumerate(CORNERS):
        spin_out = SIDE_SIGN[corner] * (rot.T @ d.xmat[car.wheel_body[k]].reshape(3, 3)[:, 1])
        toe, camber = wheel_angles(spin_out, SIDE_SIGN[corner])
        travel = (rot.T @ (d.xipos[car.wheel_body[k]] - d.xpos[car.chassis]))[2] - car._design_z[k]
        for name, value in (("toe", toe), ("camber", camber), ("travel", travel)):
            assert v[cols.wheel(name)[k]] == pytest.approx(value, abs=1e-12), (corner, name)
        np.testing.assert_array_equal(v[[cols.wheel(s)[k] for s in SIGNALS]], car.tyre_signals[k])
