"""What a vehicle file must describe before the kinematics and MuJoCo build it: values within the
physical ranges of a car (a hardpoint in millimetres, a 1e12 kg body or a 90° toe are typing or unit
errors), and a geometry that holds together: the tyres reach the ground at design, no link has zero
length, the wishbone turns about its pivots, springs are stiff and dampers dissipate."""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from elastokin.vehicle.model.definition import Curve, VehicleDefinition
from elastokin.core.documents import Document, KeyPath

# Largest magnitudes accepted (SI but for the angles): far beyond a passenger car, below what only a
# unit or typing error gives.
MAX_COORDINATE_M = 5.0          #: of a hardpoint, the CG, the ride-height point
MAX_RADIUS_M = 1.0              #: tyre loaded radius
MAX_BODY_MASS_KG = 10_000.0
MAX_PART_MASS_KG = 500.0        #: wheel, wishbone, knuckle, arm, ...
MAX_INERTIA_KGM2 = 1e5
MAX_TOE_DEG, MAX_CAMBER_DEG = 5.0, 10.0
MAX_STIFFNESS_N_PER_M = 1e7     #: springs, anti-roll bar
MAX_TORSION_NM_PER_RAD = 1e7    #: the twist beam
MAX_PRELOAD_N = 1e5
MAX_FRICTION_N = 5_000.0        #: a strut's sliding friction is tens to hundreds of N
MAX_RACK_TRAVEL_M = 0.5         #: per steering-wheel turn
MAX_SCALE = 100.0               #: factor on a design value
#: The loaded radius must bring each contact point to the ground (z = ride-height point − design
#: ride height) within this [m].
CONTACT_TOLERANCE_M = 0.005
#: Shortest link or pivot axis accepted, and the least offset of the ball joint from the pivot axis [m].
MIN_LENGTH_M = 0.01

#: Pairs of hardpoints whose distance is a link's length or an axis: (axle, a, b, what it is).
_LINKS = (("front", "strut_lower", "strut_top", "the strut"), ("front", "tie_rod_inner", "tie_rod_outer", "the tie rod"),
          ("front", "wishbone_front_pivot", "wishbone_rear_pivot", "the wishbone's pivot axis"),
          ("rear", "spring_lower", "spring_upper", "the spring"), ("rear", "damper_lower", "damper_upper", "the damper"),
          ("rear", "arm_pivot", "wheel_centre", "the trailing arm"))


def check_geometry(v: VehicleDefinition, doc: Document) -> None:
    """InputError, naming the key in ``doc`` (the file ``v`` was read from), if the principal
    inertias break the triangle inequality, a tyre does not reach the ground at design, a link has
    no length, the ball joint sits on the wishbone's pivot axis, a spring curve softens to zero or a
    damper curve creates energy."""
    inertia = sorted(v.body.inertia)
    if inertia[2] > inertia[0] + inertia[1]:
        raise doc.error(("body", "inertia"), f"principal inertias {list(v.body.inertia)} break the triangle "
                                             f"inequality (the largest must not exceed the sum of the others)")
    ground = v.body.ride_height_point[2] - v.body.design_ride_height
    for axle in (v.front, v.rear):
        name = "front" if axle is v.front else "rear"
        centre = axle.hardpoints["wheel_centre"][2]
        gap = centre - v.tyre.radius * math.cos(axle.static_camber) - ground
        if abs(gap) > CONTACT_TOLERANCE_M:
            raise doc.error(("tyre", "radius"), f"a loaded radius of {v.tyre.radius} m puts the {name} contact point "
                                                f"{gap * 1e3:+.1f} mm from the ground (wheel centre at z = {centre} m, "
                                                f"ground at body.ride_height_point z − design_ride_height = {ground:.4g} "
                                                f"m); expected them within {CONTACT_TOLERANCE_M * 1e3:g} mm")
    for axle, a, b, what in _LINKS:
        points = getattr(v, axle).hardpoints
        length = float(np.linalg.norm(np.subtract(points[b], points[a])))
        if length < MIN_LENGTH_M:
            raise doc.error((axle, "hardpoints", b), f"{length * 1e3:.1f} mm from {a}: {what} has no length; expected "
                                                     f"at least {MIN_LENGTH_M * 1e3:g} mm")
    p = {k: np.asarray(x) for k, x in v.front.hardpoints.items()}
    axis = p["wishbone_rear_pivot"] - p["wishbone_front_pivot"]
    offset = np.linalg.norm(np.cross(axis / np.linalg.norm(axis), p["lower_ball_joint"] - p["wishbone_front_pivot"]))
    if offset < MIN_LENGTH_M:
        raise doc.error(("front", "hardpoints", "lower_ball_joint"), f"{offset * 1e3:.1f} mm from the wishbone's pivot "
                                                                     f"axis; expected a wishbone that carries it")
    for axle in ("front", "rear"):
        spring, damper = getattr(v, axle).spring, getattr(v, axle).damper
        _check_curve(doc, (axle, "spring", "curve"), spring.curve, "a spring force growing with compression",
                     lambda slope: slope > 0.0)
        _check_curve(doc, (axle, "damper", "curve"), damper.curve, "a damper force not falling as the speed grows",
                     lambda slope: slope >= 0.0)
        for i, (speed, force) in enumerate(zip(damper.curve.x, damper.curve.y)):
            if speed * force < 0.0:
                raise doc.error((axle, "damper", "curve", i), f"force {force:g} N at speed {speed:g} m/s would push the "
                                                              f"motion on and create energy; expected F·v ≥ 0 (a damper "
                                                              f"dissipates)")


def _check_curve(doc: Document, path: KeyPath, curve: Curve, rule: str, ok: Callable[[float], bool]) -> None:
    for i, (x0, x1, y0, y1) in enumerate(zip(curve.x, curve.x[1:], curve.y, curve.y[1:])):
        slope = (y1 - y0) / (x1 - x0)
        if not ok(slope) or abs(slope) > MAX_STIFFNESS_N_PER_M:
            raise doc.error(path + (i + 1,), f"slope {slope:.6g} from point {i} to {i + 1}; expected {rule}, a slope of "
                                             f"at most {MAX_STIFFNESS_N_PER_M:g} N/m (or N·s/m)")
