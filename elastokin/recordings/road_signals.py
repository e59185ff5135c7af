"""What a run of a road scenario records: the body's motion (ISO 8855 intermediate axes, at the
centre of mass), the driver, each wheel's angles relative to the body and its travel, each tyre's
forces and slips, then the suspension's signals as on the rig
(:class:`elastokin.recordings.run_signals.SuspensionSignals`)."""

from __future__ import annotations

from typing import Sequence

import numpy as np

from elastokin.vehicle.model.definition import CORNERS
from elastokin.vehicle.scenarios.channels import CORNER_TAGS
from elastokin.vehicle.simulation.outputs import ROAD_BODY, ROAD_WHEEL, MeasuredColumns, SampleBlock
from elastokin.core.units import DEG_PER_RAD, MM_PER_M, per_si
from elastokin.recordings.run_format import SignalSpec
from elastokin.recordings.run_signals import SuspensionSignals
from elastokin.tyres.road_contact import SIGNALS as TYRE_SIGNALS

_TAGS = tuple(CORNER_TAGS[c] for c in CORNERS)
_KMH = per_si("km/h")
#: The body's signals: name (in elastokin.vehicle.simulation.outputs.ROAD_BODY), unit, and the factor from its SI value.
VEHICLE_SIGNALS = (("x", "m", 1.0), ("y", "m", 1.0), ("yaw", "deg", DEG_PER_RAD), ("roll", "deg", DEG_PER_RAD),
                   ("pitch", "deg", DEG_PER_RAD), ("speed", "km/h", _KMH), ("sideslip", "deg", DEG_PER_RAD),
                   ("yaw_rate", "deg/s", DEG_PER_RAD), ("lateral_acceleration", "m/s²", 1.0),
                   ("longitudinal_acceleration", "m/s²", 1.0))
#: The driver's signals.
DRIVER_SIGNALS = (("steering_wheel", "deg", DEG_PER_RAD), ("rack", "mm", MM_PER_M), ("target_speed", "km/h", _KMH),
                  ("drive_force", "N", 1.0))
#: Each tyre's recorded signals: the name in elastokin.tyres.road_contact.SIGNALS (in this order), the recorded name,
#: unit and factor.
TYRE_RECORDED = {"Fz_N": ("tyre_fz", "N", 1.0), "Fx_N": ("tyre_fx", "N", 1.0), "Fy_N": ("tyre_fy", "N", 1.0),
                 "Mz_Nm": ("tyre_mz", "N·m", 1.0), "My_Nm": ("tyre_my", "N·m", 1.0), "kappa": ("slip_ratio", "-", 1.0),
                 "alpha_rad": ("slip_angle", "deg", DEG_PER_RAD), "gamma_rad": ("inclination", "deg", DEG_PER_RAD),
                 "vx_mps": ("wheel_speed", "m/s", 1.0), "deflection_m": ("tyre_deflection", "mm", MM_PER_M)}


class RoadSignalLayout:
    """The recorded signals of the car on the road, and a block of samples' values in the same order."""

    def __init__(self, bushings: Sequence[str] = (), springs: Sequence[str] = (), dampers: Sequence[str] = ()):
        """The signals above, read from the car's measured vectors (:attr:`elastokin.vehicle.simulation.road.RoadCar.columns`)."""
        columns = MeasuredColumns(ROAD_BODY, ROAD_WHEEL + TYRE_SIGNALS, len(springs), len(dampers), len(bushings))
        specs = [SignalSpec(n, u, "vehicle") for n, u, _ in VEHICLE_SIGNALS]
        specs += [SignalSpec(n, u, "driver") for n, u, _ in DRIVER_SIGNALS]
        for quantity, unit in (("wheel_travel", "mm"), ("camber", "deg"), ("toe", "deg"), ("steer", "deg")):
            specs += [SignalSpec(f"{quantity}_{t}", unit, quantity) for t in _TAGS]
        for name, unit, _ in TYRE_RECORDED.values():
            specs += [SignalSpec(f"{name}_{t}", unit, "tyres") for t in _TAGS]
        # measured columns and their factors to the recorded units, in the order of the specs
        # (the driver's steering-wheel angle and target speed come from the block's inputs)
        body = [(columns.of(n), f) for n, _, f in VEHICLE_SIGNALS]
        wheels = [(columns.wheel(q), f) for q, f in (("travel", MM_PER_M), ("camber", DEG_PER_RAD),
                                                     ("toe", DEG_PER_RAD), ("steer", DEG_PER_RAD))]
        wheels += [(columns.wheel(s), TYRE_RECORDED[s][2]) for s in TYRE_RECORDED]
        self._body = np.array([c for c, _ in body]), np.array([f for _, f in body])
        self._driver = np.array([columns.of("rack"), columns.of("drive_force")])
        self._wheels = np.concatenate([c for c, _ in wheels]), np.concatenate([np.full(4, f) for _, f in wheels])
        self.suspension = SuspensionSignals(columns, bushings, springs, dampers)
        self.specs = specs + self.suspension.specs

    def values(self, block: SampleBlock) -> np.ndarray:
        """The block's values (samples, signals), in the recorded units and the order of :attr:`specs`."""
        m, u = block.measured, block.inputs
        (steering, rack, speed, drive) = (f for _, _, f in DRIVER_SIGNALS)
        driver = np.column_stack([u[:, 0] * steering, m[:, self._driver[0]] * rack, u[:, 1] * speed,
                                  m[:, self._driver[1]] * drive])
        return np.hstack([m[:, self._body[0]] * self._body[1], driver, m[:, self._wheels[0]] * self._wheels[1],
                          self.suspension.values(block)])
