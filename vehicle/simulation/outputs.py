"""What the K&C rig measures (ISO 8855: toe-in positive, camber positive when the wheel top leans
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
class RigOutputs:
    """One sample of the rig."""

    time: float                              #: [s]
    wheels: dict[str, WheelOutputs]
    bushing_names: tuple[str, ...]           #: ``bushing_side.direction``
    bushing_deflection: np.ndarray           #: [m or rad] in each bushing's frame
    bushing_force: np.ndarray                #: [N or N·m], resisting the deflection
    spring_force: dict[str, float]           #: [N], pushing apart
    damper_force: dict[str, float]           #: [N], pushing apart
    closure_error: float                     #: largest loop-closure position error [m]


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
