"""What the K&C rig and the car on the road measure (ISO 8855: toe-in positive, camber positive when the wheel top leans
outward, steer angle positive to the left, half-track = |y| of the wheel centre), one sample of it,
and one recorded instant of a scenario run. Readers of these need no MuJoCo."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class WheelOutputs:
    """What the rig measures at one wheel."""

    camber: float               #: [rad], top outward positive
    toe: float                  #: [rad], toe-in positive
    steer: float                #: yaw of the wheel heading [rad], to the left positive
    half_track: float           #: |y| of the wheel centre [m]
    travel: float               #: wheel-centre height from design [m], bump positive
    wheel_centre: np.ndarray    #: [m], world frame (the rig's bedplate; the body's, clamped rigidly)
    pad_force: np.ndarray       #: force of the pad on the wheel (Fx, Fy, Fz) [N]
    pad_height: float           #: measured pad (contact-point) displacement [m], bump positive
    pad_torque: float           #: aligning torque applied about the vertical [N·m]


@dataclass(frozen=True)
class SuspensionOutputs:
    """What every mounting of the car measures of its suspension at one instant."""

    time: float                              #: [s]
    bushing_names: tuple[str, ...]           #: ``bushing_side.direction``
    bushing_deflection: np.ndarray           #: [m or rad] in each bushing's frame
    bushing_force: np.ndarray                #: [N or N·m], resisting the deflection
    spring_force: dict[str, float]           #: [N], pushing apart
    damper_force: dict[str, float]           #: [N], pushing apart
    closure_error: float                     #: largest loop-closure position error [m]


@dataclass(frozen=True)
class RigOutputs(SuspensionOutputs):
    """One sample of the rig."""

    wheels: dict[str, WheelOutputs]


#: What the rig measures at each wheel, in its measured vector (SI): the angles [rad], half-track,
#: travel (wheel-centre height from design, bump positive) and centre [m], the pad's Fx, Fy, Fz [N],
#: height [m] and aligning torque [N·m] (the fields of :class:`WheelOutputs`).
RIG_WHEEL = ("camber", "toe", "steer", "half_track", "travel", "centre_x", "centre_y", "centre_z", "pad_fx",
             "pad_fy", "pad_fz", "pad_height", "pad_torque")
#: What the car on the road measures of its body and driver (SI, ISO 8855 intermediate axes, at the
#: body's centre of mass): position on the road [m], yaw, roll (right side down), pitch (nose down)
#: [rad], forward and lateral speed [m/s], yaw rate [rad/s], longitudinal and lateral acceleration
#: in the road's plane [m/s²], sideslip atan2(lateral, forward speed) [rad] (0 below 0.5 m/s), rack
#: displacement from design [m, to the left], the driver's drive force [N].
ROAD_BODY = ("x", "y", "yaw", "roll", "pitch", "speed", "lateral_speed", "yaw_rate", "longitudinal_acceleration",
             "lateral_acceleration", "sideslip", "rack", "drive_force")
#: What the car on the road measures at each wheel, before its tyre's signals: angles relative to
#: the body [rad] and travel (wheel-centre height in the body frame from design) [m].
ROAD_WHEEL = ("camber", "toe", "steer", "travel")


class MeasuredColumns:
    """Where each quantity sits in the vector a mounting of the car measures at one instant (SI):
    its own quantities (``head``), each wheel's (``wheel``, the four corners one after the other in
    the order of CORNERS), then the suspension's: the forces of the springs and of the dampers [N],
    the deflections [m or rad] and forces [N or N·m] of the bushing directions, the loop-closure
    error [m]."""

    def __init__(self, head: tuple[str, ...], wheel: tuple[str, ...], springs: int, dampers: int, bushings: int):
        self.head, self.wheel_fields = head, wheel
        self.wheels_start = len(head)
        self.suspension_start = start = len(head) + 4 * len(wheel)
        self.springs = slice(start, start + springs)
        self.dampers = slice(self.springs.stop, self.springs.stop + dampers)
        self.deflection = slice(self.dampers.stop, self.dampers.stop + bushings)
        self.force = slice(self.deflection.stop, self.deflection.stop + bushings)
        self.closure_error = self.force.stop
        self.size = self.closure_error + 1

    def of(self, name: str) -> int:
        """The column of the quantity ``name`` of ``head``."""
        return self.head.index(name)

    def wheel(self, name: str) -> np.ndarray:
        """The four columns (order of CORNERS) of the wheel quantity ``name``."""
        return self.wheels_start + np.arange(4) * len(self.wheel_fields) + self.wheel_fields.index(name)


@dataclass(frozen=True)
class SampleBlock:
    """Consecutive recorded instants of one phase of a case, one row each (SI)."""

    time_s: np.ndarray             #: (n,) times in the run [s]
    case: int                      #: 1-based
    phase: int                     #: index in the run's phases
    input_time_s: np.ndarray       #: (n,) time since the case's input started [s] (negative before)
    inputs: np.ndarray             #: (n, inputs) the mounting's inputs: the rig's (order of INPUT_CHANNELS);
                                   #: on the road the steering-wheel angle [rad, + to the left] and the
                                   #: driver's target speed [m/s] (NaN: the throttle held)
    measured: np.ndarray           #: (n, columns) what the car measured (:class:`MeasuredColumns`)
    body_pos: np.ndarray           #: (n, bodies, 3) world positions [m] (no bodies: not kept)
    body_quat_wxyz: np.ndarray     #: (n, bodies, 4) world orientations

    def upto(self, row: int) -> SampleBlock:
        """The block's first ``row + 1`` instants."""
        n = row + 1
        return SampleBlock(self.time_s[:n], self.case, self.phase, self.input_time_s[:n], self.inputs[:n],
                           self.measured[:n], self.body_pos[:n], self.body_quat_wxyz[:n])
