"""Kinematics of the suspensions with rigid bushings, solved from the hardpoints alone (no MuJoCo).

Used as the independent reference of the kinematics test and for the static spring preloads. The
bushings are ball joints (rigid in translation, free in rotation): the wishbone turns about the
line through its two pivots, the twist beam about the line through the arm pivots (heave).
Wheels are braked (fixed to knuckle or arm); the rig moves the wheel's design contact point
vertically. Left side; the right side is its mirror image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.geometry import wheel_axis


@dataclass(frozen=True)
class Motion:
    """A rigid displacement from design: ``p -> rot @ p + shift`` (world coordinates)."""

    rot: np.ndarray
    shift: np.ndarray

    def __call__(self, p) -> np.ndarray:
        return self.rot @ np.asarray(p, float) + self.shift


#: Largest residual of a solved pose [m] (its equations are lengths and heights).
SOLVED_M = 1e-10


def rotation(rotvec) -> np.ndarray:
    """The rotation matrix of a rotation vector [rad] (Rodrigues; series near zero)."""
    v = np.asarray(rotvec, float)
    k = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    a2 = float(v @ v)
    a = math.sqrt(a2)
    sin_a, one_minus_cos = ((1.0 - a2 / 6.0, 0.5 - a2 / 24.0) if a < 1e-6 else
                            (math.sin(a) / a, (1.0 - math.cos(a)) / a2))
    return np.eye(3) + sin_a * k + one_minus_cos * (k @ k)


def newton(residual, x0: np.ndarray, what: str, iterations: int = 50) -> np.ndarray:
    """The root of ``residual`` (n equations, n unknowns) from ``x0``: Newton steps on a central-
    difference Jacobian, halved while they do not reduce the residual; RuntimeError naming
    ``what`` if the residual stays above SOLVED_M. Kept off scipy.optimize, whose import alone
    cost a third of a second of every run (the statics call it)."""
    x = np.array(x0, float)
    r = residual(x)
    for _ in range(iterations):
        if not np.all(np.isfinite(r)) or np.abs(r).max() <= 1e-14:
            break
        h = 1e-7 * np.maximum(1.0, np.abs(x))
        jac = np.column_stack([(residual(x + e) - residual(x - e)) / (2.0 * e[i])
                               for i, e in enumerate(np.diag(h))])
        if not np.all(np.isfinite(jac)):
            break
        step = np.linalg.lstsq(jac, -r, rcond=None)[0]
        for _ in range(30):
            trial = residual(x + step)
            if np.all(np.isfinite(trial)) and np.abs(trial).max() < np.abs(r).max():
                break
            step = step / 2.0
        else:
            break
        x, r = x + step, trial
    if not np.abs(r).max() <= SOLVED_M:
        found = f"residual {np.abs(r).max():.3g} m" if np.all(np.isfinite(r)) else "a non-finite residual"
        raise RuntimeError(f"{what} did not converge: {found}")
    return x


def about(point, axis, angle: float) -> Motion:
    """Rotation by ``angle`` [rad] about the line through ``point`` along ``axis``."""
    rot = rotation(np.asarray(axis) / np.linalg.norm(axis) * angle)
    point = np.asarray(point, float)
    return Motion(rot, point - rot @ point)


def contact_point(centre, spin_axis, radius: float) -> np.ndarray:
    """The lowest point of the wheel's mid-plane circle at design (fixed on the wheel after that)."""
    up = np.array([0.0, 0, 1]) - spin_axis * spin_axis[2]
    return np.asarray(centre) - radius * up / np.linalg.norm(up)


def wheel_angles(spin_out: np.ndarray, sign: float = 1.0) -> tuple[float, float]:
    """(toe-in, camber) [rad] of a wheel from its outward spin axis (ISO 8855 signs)."""
    spin_out = np.asarray(spin_out, float)
    toe, camber, _ = wheel_orientation(sign * spin_out[0], sign * spin_out[1], sign * spin_out[2], sign)
    return toe, camber


@nb.njit(cache=True)
def wheel_orientation(left_x: float, left_y: float, left_z: float, sign: float) -> tuple[float, float, float]:
    """(toe-in, camber, steer) [rad] of a wheel from its spin axis pointing to the vehicle's left
    (components in the frame the angles are taken in); ``sign`` +1 for a left wheel, −1 for a right
    one. Steer is the yaw of the heading ``spin_left × z``, to the left positive. Compiled: the
    rig's measurement calls it at every sample (elastokin.vehicle.simulation.probes)."""
    out_x, out_y, out_z = sign * left_x, sign * left_y, sign * left_z   # the outward spin axis
    toe = math.atan2(out_x, sign * out_y)
    camber = -math.asin(1.0 if out_z > 1.0 else (-1.0 if out_z < -1.0 else out_z))
    return toe, camber, math.atan2(-left_x, left_y)


@dataclass(frozen=True)
class CornerState:
    """Pose of a corner's parts for one wheel travel."""

    travel: float                     #: contact-point height change [m], bump positive
    parts: dict[str, Motion]          #: motion of each part from design
    strut_extension: float            #: front strut slide [m] (extension positive); rear: 0
    toe: float                        #: [rad]
    camber: float                     #: [rad]
    wheel_centre: np.ndarray          #: [m]


def front_corner(v: VehicleDefinition, travel: float, rack: float = 0.0,
                 guess: np.ndarray | None = None) -> tuple[CornerState, np.ndarray]:
    """Left front corner at contact-point travel ``travel`` [m] and rack shift ``rack`` [m, +y].

    Unknowns: wishbone angle about its pivot line, knuckle rotation vector about the ball joint,
    strut extension. Equations: rod top at the top mount (3), tie-rod length (1), contact height (1).
    Returns the state and the solution vector (a guess for the next call).
    """
    hp = {k: np.array(p) for k, p in v.front.hardpoints.items()}
    e1, e2, lbj = hp["wishbone_front_pivot"], hp["wishbone_rear_pivot"], hp["lower_ball_joint"]
    s0, top = hp["strut_lower"], hp["strut_top"]
    strut_len = np.linalg.norm(top - s0)
    e0 = (top - s0) / strut_len
    inner = hp["tie_rod_inner"] + np.array([0.0, rack, 0.0])
    tie_len = np.linalg.norm(hp["tie_rod_outer"] - hp["tie_rod_inner"])
    spin = wheel_axis(v.front.static_toe, v.front.static_camber, 1.0)
    contact = contact_point(hp["wheel_centre"], spin, v.tyre.radius)

    def parts(x):
        wishbone = about(e1, e1 - e2, x[0])
        rot = rotation(x[1:4])
        knuckle = Motion(rot, wishbone(lbj) - rot @ lbj)
        rod = Motion(rot, knuckle.shift + rot @ e0 * x[4])
        return {"wishbone": wishbone, "knuckle": knuckle, "rod": rod}

    def residual(x):
        p = parts(x)
        k = p["knuckle"]
        return np.concatenate([
            k(s0) + k.rot @ e0 * (strut_len + x[4]) - top,
            [np.linalg.norm(k(hp["tie_rod_outer"]) - inner) - tie_len,
             k(contact)[2] - contact[2] - travel]])

    x0 = np.zeros(5) if guess is None else guess
    x = newton(residual, x0, f"front kinematics at travel {travel} m, rack {rack} m")
    p = parts(x)
    toe, camber = wheel_angles(p["knuckle"].rot @ spin)
    return CornerState(travel, p, float(x[4]), toe, camber, p["knuckle"](hp["wheel_centre"])), x


def rear_heave(v: VehicleDefinition, travel: float) -> CornerState:
    """Left rear corner in heave (both arms turning together about the pivot line)."""
    hp = {k: np.array(p) for k, p in v.rear.hardpoints.items()}
    pivot = hp["arm_pivot"]
    spin = wheel_axis(v.rear.static_toe, v.rear.static_camber, 1.0)
    contact = contact_point(hp["wheel_centre"], spin, v.tyre.radius)
    arm = lambda angle: about(pivot, [0.0, 1.0, 0.0], angle)
    angle = newton(lambda a: np.array([arm(a[0])(contact)[2] - contact[2] - travel]), np.zeros(1),
                   f"rear kinematics at travel {travel} m")[0]
    m = arm(angle)
    toe, camber = wheel_angles(m.rot @ spin)
    return CornerState(travel, {"arm": m}, 0.0, toe, camber, m(hp["wheel_centre"]))


def steering_ratio(v: VehicleDefinition, rack_step: float = 1e-4) -> float:
    """The overall steering ratio at straight ahead (ISO 8855): steering-wheel angle over the mean
    steer angle of the front wheels, kinematic (rigid bushings, at design height), from a central
    difference of ``rack_step`` [m] of the rack."""
    # the right wheel at rack +r is the mirror of the left at −r; the left's toe-in steers it right
    toe = lambda rack: front_corner(v, 0.0, rack)[0].toe
    mean_steer_per_m = -(toe(rack_step) - toe(-rack_step)) / (2.0 * rack_step)
    wheel_per_m = 2.0 * math.pi / v.front.rack_travel_per_rev
    return abs(wheel_per_m / mean_steer_per_m)
