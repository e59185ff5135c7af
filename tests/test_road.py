"""The car on the road (issue 26, step 3): the rig's car mounted free on its Magic Formula tyres;
it settles where the rig's statics and the tyres' vertical law put it, a braked car does not
creep, a coasting car loses energy and keeps straight."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.optimize import brentq

from vehicle.model.builder import build
from vehicle.model.definition import CORNERS
from vehicle.model.elements import BuildOptions
from vehicle.model.statics import resolve_preloads
from vehicle.model.vehicle_file import load_vehicle
from vehicle.simulation.rig import KCRig
from vehicle.simulation.road import RoadCar
from vsim_core.shipped import DEFAULT_VEHICLE
from vsim_tyres import magic_formula as mf
from vsim_tyres.road_contact import SIGNALS

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
    car.step(4000)
    moved = car.car.body_point(car.data, [0.0, 0.0, 0.0]) - before
    assert np.abs(moved).max() < 5e-5                      # 0.05 mm in 4 s
    assert np.abs(car.data.qvel[:3]).max() < 1e-4


def test_a_coasting_car_loses_energy_steadily_and_keeps_straight() -> None:
    car = settled(brakes=0.0, seconds=3.0)
    car.set_speed(20.0)
    energy, speed = [], []
    for _ in range(12):
        car.step(250)
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
