"""The front wheels' steering axis at design, from the hardpoints: the pseudo-McPherson turns its
knuckle about the line from the lower ball joint to the strut's top mount. The left wheel's figures
(the right wheel is its mirror), with the signs K&C reports use: caster positive with the axis's
top rearward, kingpin inclination positive with its top inboard, scrub radius positive when the
axis meets the ground inboard of the contact point, mechanical (caster) trail positive when it
meets the ground ahead of it."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.geometry import contact_point


@dataclass(frozen=True)
class SteeringAxis:
    """The steering axis's angles [deg] and ground offsets [mm] at design."""

    caster_deg: float
    kingpin_inclination_deg: float
    scrub_radius_mm: float
    mechanical_trail_mm: float


def steering_axis(vehicle: VehicleDefinition) -> SteeringAxis:
    """The left front wheel's :class:`SteeringAxis` at design, on the ground under its contact point."""
    f = vehicle.front
    bottom, top = np.array(f.hardpoints["lower_ball_joint"]), np.array(f.hardpoints["strut_top"])
    axis = top - bottom
    contact = contact_point(f.hardpoints["wheel_centre"], f.static_toe, f.static_camber, 1.0, vehicle.tyre.radius)
    ground = bottom + axis * (contact[2] - bottom[2]) / axis[2]   # where the axis meets the contact point's plane
    return SteeringAxis(math.degrees(math.atan2(-axis[0], axis[2])), math.degrees(math.atan2(-axis[1], axis[2])),
                        float(1e3 * (contact[1] - ground[1])), float(1e3 * (ground[0] - contact[0])))
