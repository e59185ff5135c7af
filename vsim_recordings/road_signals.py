"""What a run of a road scenario records: the body's motion (ISO 8855 intermediate axes, at the
centre of mass), the driver, each wheel's angles relative to the body and its travel, each tyre's
forces and slips, then the suspension's signals as on the rig
(:class:`vsim_recordings.run_signals.SuspensionSignals`)."""

from __future__ import annotations

from typing import Sequence

import numpy as np

from vehicle.model.definition import CORNERS
from vehicle.scenarios.channels import CORNER_TAGS
from vehicle.simulation.outputs import RoadSample
from vsim_core.units import DEG_PER_RAD, MM_PER_M, per_si
from vsim_recordings.run_format import SignalSpec
from vsim_recordings.run_signals import SuspensionSignals
from vsim_tyres.road_contact import SIGNALS as TYRE_SIGNALS

_TAGS = tuple(CORNER_TAGS[c] for c in CORNERS)
_KMH = per_si("km/h")
#: The body's signals: name, unit, and the factor from the SI value of RoadOutputs.
VEHICLE_SIGNALS = (("x", "m", 1.0), ("y", "m", 1.0), ("yaw", "deg", DEG_PER_RAD), ("roll", "deg", DEG_PER_RAD),
                   ("pitch", "deg", DEG_PER_RAD), ("speed", "km/h", _KMH), ("sideslip", "deg", DEG_PER_RAD),
                   ("yaw_rate", "deg/s", DEG_PER_RAD), ("lateral_acceleration", "m/s²", 1.0),
                   ("longitudinal_acceleration", "m/s²", 1.0))
#: The driver's signals.
DRIVER_SIGNALS = (("steering_wheel", "deg", DEG_PER_RAD), ("rack", "mm", MM_PER_M), ("target_speed", "km/h", _KMH),
                  ("drive_force", "N", 1.0))
#: Each tyre's recorded signals: the name in vsim_tyres.road_contact.SIGNALS, the recorded name, unit and factor.
TYRE_RECORDED = {"Fz_N": ("tyre_fz", "N", 1.0), "Fx_N": ("tyre_fx", "N", 1.0), "Fy_N": ("tyre_fy", "N", 1.0),
                 "Mz_Nm": ("tyre_mz", "N·m", 1.0), "My_Nm": ("tyre_my", "N·m", 1.0), "kappa": ("slip_ratio", "-", 1.0),
                 "alpha_rad": ("slip_angle", "deg", DEG_PER_RAD), "gamma_rad": ("inclination", "deg", DEG_PER_RAD),
                 "vx_mps": ("wheel_speed", "m/s", 1.0), "deflection_m": ("tyre_deflection", "mm", MM_PER_M)}


class RoadSignalLayout:
    """The recorded signals of the car on the road, and one sample's values in the same order."""

    def __init__(self, bushings: Sequence[str] = (), springs: Sequence[str] = (), dampers: Sequence[str] = ()):
        specs = [SignalSpec(n, u, "vehicle") for n, u, _ in VEHICLE_SIGNALS]
        specs += [SignalSpec(n, u, "driver") for n, u, _ in DRIVER_SIGNALS]
        for quantity, unit in (("wheel_travel", "mm"), ("camber", "deg"), ("toe", "deg"), ("steer", "deg")):
            specs += [SignalSpec(f"{quantity}_{t}", unit, quantity) for t in _TAGS]
        for name, unit, _ in TYRE_RECORDED.values():
            specs += [SignalSpec(f"{name}_{t}", unit, "tyres") for t in _TAGS]
        self.tyre_scale = np.array([TYRE_RECORDED[s][2] for s in TYRE_SIGNALS])
        self.suspension = SuspensionSignals(bushings, springs, dampers)
        self.specs = specs + self.suspension.specs

    def values(self, s: RoadSample) -> np.ndarray:
        """One sample's values, in the recorded units and the order of :attr:`specs`."""
        o = s.outputs
        body = (o.position[0], o.position[1], o.yaw, o.roll, o.pitch, o.speed, o.sideslip, o.yaw_rate,
                o.lateral_acceleration, o.longitudinal_acceleration)
        driver = (s.steering_wheel, o.rack, s.target_speed, o.drive_force)
        w = [o.wheels[c] for c in CORNERS]
        tyres = np.array([x.tyre for x in w]) * self.tyre_scale   # (corner, signal): recorded signal-major
        return np.concatenate([
            [v * f for v, (_, _, f) in zip(body, VEHICLE_SIGNALS)],
            [v * f for v, (_, _, f) in zip(driver, DRIVER_SIGNALS)],
            [x.travel * MM_PER_M for x in w], [x.camber * DEG_PER_RAD for x in w], [x.toe * DEG_PER_RAD for x in w],
            [x.steer * DEG_PER_RAD for x in w],
            tyres.T.ravel(),
            self.suspension.values(s),
        ])
