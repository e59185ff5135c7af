"""Static spring preloads: the springs carry the vehicle at design ride height.

``preload: auto`` in the vehicle file is resolved here by virtual work on the rigid-bushing
kinematics of :mod:`elastokin.vehicle.model.kinematics`: with the wheel load W of the corner (from the total mass
and its CG), the preload P satisfies W = P·MR + g·Σ m_i·dz_i/dz_wheel, where MR = −dL/dz_wheel is
the spring's motion ratio and the sum runs over the corner's moving parts.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Callable

import mujoco
import numpy as np

from elastokin.vehicle.model.builder import build
from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.kinematics import CornerState, front_corner, rear_heave
from elastokin.vehicle.model.plausibility import MAX_PRELOAD_N
from elastokin.core.errors import InputError

GRAVITY = 9.81
_STEP = 5e-4  # finite-difference travel [m]


def _masses(v: VehicleDefinition) -> tuple[dict[str, tuple[float, np.ndarray]], float, float]:
    """Mass and design COM of every body, total mass and total CG x, from the compiled model."""
    zero = dataclasses.replace(
        v, front=dataclasses.replace(v.front, spring=dataclasses.replace(v.front.spring, preload=0.0)),
        rear=dataclasses.replace(v.rear, spring=dataclasses.replace(v.rear.spring, preload=0.0)))
    car = build(zero, BuildOptions(rig=False))
    m, d = car.model, mujoco.MjData(car.model)
    mujoco.mj_forward(m, d)
    bodies = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, i): (float(m.body_mass[i]), d.xipos[i].copy())
              for i in range(1, m.nbody)}
    total = sum(mass for mass, _ in bodies.values())
    x_cg = sum(mass * com[0] for mass, com in bodies.values()) / total
    return bodies, total, x_cg


def _gravity_term(bodies, parts_of, state_plus, state_minus) -> float:
    """g·Σ m_i·dz_i/dz_wheel for the bodies mapped to parts by ``parts_of``."""
    total = 0.0
    for name, part in parts_of.items():
        mass, com = bodies[name]
        dz = state_plus.parts[part](com)[2] - state_minus.parts[part](com)[2]
        total += mass * dz / (2 * _STEP)
    return GRAVITY * total


def resolve_preloads(v: VehicleDefinition) -> VehicleDefinition:
    """The definition with every ``auto`` spring preload replaced by its static value [N]."""
    if v.front.spring.preload is not None and v.rear.spring.preload is not None:
        return v
    bodies, total, x_cg = _masses(v)
    x_f, x_r = v.front.hardpoints["wheel_centre"][0], v.rear.hardpoints["wheel_centre"][0]
    front_load = total * GRAVITY * (x_cg - x_r) / (x_f - x_r) / 2.0  # per wheel [N]
    rear_load = total * GRAVITY / 2.0 - front_load

    front, rear = v.front, v.rear
    if front.spring.preload is None:
        plus, minus = _solved(v, "front", lambda: (front_corner(v, _STEP)[0], front_corner(v, -_STEP)[0]))
        parts = {"wishbone_left": "wishbone", "knuckle_left": "knuckle", "strut_rod_left": "rod",
                 "wheel_front_left": "knuckle"}
        parts |= {f"{b.name}_left_sleeve": "wishbone" for b in v.bushings if b.child == "front.wishbone"}
        parts = {k: p for k, p in parts.items() if k in bodies}
        ratio = -(plus.strut_extension - minus.strut_extension) / (2 * _STEP)
        preload = _checked(v, "front", (front_load - _gravity_term(bodies, parts, plus, minus)) / ratio)
        front = dataclasses.replace(front, spring=dataclasses.replace(front.spring, preload=preload))
    if rear.spring.preload is None:
        plus, minus = _solved(v, "rear", lambda: (rear_heave(v, _STEP), rear_heave(v, -_STEP)))
        parts = {"arm_left": "arm", "hub_left": "arm", "wheel_rear_left": "arm"}
        parts |= {f"{b.name}_left_sleeve": "arm" for b in v.bushings if b.child == "rear.arm"}
        parts = {k: p for k, p in parts.items() if k in bodies}
        beam_mass, beam_com = bodies["beam_centre"]
        bodies_half = dict(bodies, beam_centre=(beam_mass / 2.0, beam_com))  # shared by both arms
        parts["beam_centre"] = "arm"
        hp = {k: np.array(p) for k, p in v.rear.hardpoints.items()}
        length = lambda s: np.linalg.norm(hp["spring_upper"] - s.parts["arm"](hp["spring_lower"]))
        ratio = -(length(plus) - length(minus)) / (2 * _STEP)
        preload = _checked(v, "rear", (rear_load - _gravity_term(bodies_half, parts, plus, minus)) / ratio)
        rear = dataclasses.replace(rear, spring=dataclasses.replace(rear.spring, preload=preload))
    return dataclasses.replace(v, front=front, rear=rear)


def _solved(v: VehicleDefinition, axle: str, solve: Callable[[], tuple[CornerState, CornerState]]
            ) -> tuple[CornerState, CornerState]:
    """The corner states ``solve`` gives; InputError naming the axle's hardpoints if the kinematics
    fail to close about the design position."""
    try:
        return solve()
    except (RuntimeError, ValueError) as exc:  # the kinematics' Newton finds no pose
        raise InputError(f"the suspension does not move about its design position ({exc}); check the hardpoints",
                         source=str(v.path), key=f"{axle}.hardpoints") from None


def _checked(v: VehicleDefinition, axle: str, preload: float) -> float:
    """``preload`` [N], or InputError if it is not a finite compression the spring can hold."""
    if not (math.isfinite(preload) and 0.0 <= preload <= MAX_PRELOAD_N):
        raise InputError(f"carrying the car at design height would need a spring preload of {preload:.6g} N; expected "
                         f"0 to {MAX_PRELOAD_N:g} N: check the masses, the CG and the spring's hardpoints",
                         source=str(v.path), key=f"{axle}.spring.preload")
    return float(preload)


def cg_height(v: VehicleDefinition) -> float:
    """Height of the whole car's centre of mass (body and every part of the axles and wheels)
    above the ground at design [m]."""
    bodies, total, _ = _masses(v)
    return sum(mass * com[2] for mass, com in bodies.values()) / total


def axle_loads(v: VehicleDefinition) -> tuple[float, float, float]:
    """(total weight, front axle load, rear axle load) [N] of the model built from ``v``."""
    _, total, x_cg = _masses(v)
    x_f, x_r = v.front.hardpoints["wheel_centre"][0], v.rear.hardpoints["wheel_centre"][0]
    front = total * GRAVITY * (x_cg - x_r) / (x_f - x_r)
    return total * GRAVITY, front, total * GRAVITY - front
