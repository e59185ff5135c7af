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
    wheel_centre: np.ndarray    #: [m], world (= body, clamped) frame
    pad_force: np.ndarray       #: force of the pad on the wheel (Fx, Fy, Fz) [N]
    pad_height: float           #: measured pad (contact-point) displacement [m], bump positive
    pad_torque: float = 0.0     #: aligning torque applied about the vertical [N·m]


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


@dataclass(frozen=True)
class Sample:
    """One recorded instant of a scenario run (SI)."""

    time_s: float                  #: time in the run [s]
    case: int                      #: 1-based
    phase: int                     #: index in PHASES
    input_time_s: float            #: time since the case's input started [s] (negative before)
    inputs: np.ndarray             #: rig inputs (order of INPUT_CHANNELS)
    outputs: RigOutputs
    design_centre_z: np.ndarray    #: wheel-centre heights of this case's rig at design (order of CORNERS) [m]
    body_pos: np.ndarray           #: (bodies, 3) world positions [m]
    body_quat_wxyz: np.ndarray     #: (bodies, 4) world orientations


@dataclass(frozen=True)
class RoadWheel:
    """What the car on the road measures at one wheel (angles relative to the body)."""

    camber: float               #: [rad], top outward positive
    toe: float                  #: [rad], toe-in positive
    steer: float                #: yaw of the wheel heading from the body's x axis [rad], to the left positive
    travel: float               #: wheel-centre height in the body frame from design [m], bump positive
    tyre: np.ndarray            #: the tyre's signals (vsim_tyres.road_contact.SIGNALS), SI


@dataclass(frozen=True)
class RoadOutputs(SuspensionOutputs):
    """One sample of the car on the road: the body's motion (ISO 8855 intermediate axes, at its
    centre of mass), the driver's inputs, the wheels and the suspension's forces."""

    position: tuple[float, float]            #: centre of mass on the road (x, y) [m]
    yaw: float                               #: heading [rad], to the left positive
    roll: float                              #: [rad], right side down positive
    pitch: float                             #: [rad], nose down positive
    speed: float                             #: forward speed [m/s]
    lateral_speed: float                     #: [m/s], to the left positive
    yaw_rate: float                          #: [rad/s], to the left positive
    longitudinal_acceleration: float         #: [m/s²], in the road's plane
    lateral_acceleration: float              #: [m/s²], in the road's plane, to the left positive
    sideslip: float                          #: atan2(lateral, forward speed) [rad] (0 below 0.5 m/s)
    rack: float                              #: rack displacement from design [m], to the left positive
    drive_force: float                       #: the driver's drive force [N]
    wheels: dict[str, RoadWheel]


@dataclass(frozen=True)
class RoadSample:
    """One recorded instant of a road scenario run (SI)."""

    time_s: float                  #: time in the run [s]
    case: int                      #: 1-based
    phase: int                     #: index in ROAD_PHASES
    input_time_s: float            #: time since the case's input started [s] (negative before)
    steering_wheel: float          #: steering-wheel angle [rad], + to the left
    target_speed: float            #: the driver's target speed [m/s] (NaN: the throttle held)
    outputs: RoadOutputs
    body_pos: np.ndarray           #: (bodies, 3) world positions [m]
    body_quat_wxyz: np.ndarray     #: (bodies, 4) world orientations
