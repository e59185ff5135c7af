"""What a built car model is made of besides MuJoCo's own objects: the options it was built with, its
bushing channels (a joint and its force law), their cross stiffnesses, and its spring and damper
elements. Readers of a model's parts need no MuJoCo."""

from __future__ import annotations

import math
from dataclasses import dataclass

from elastokin.bushings.effects import NO_EFFECTS, Effects
from elastokin.bushings.parameters import ChannelParams
from elastokin.vehicle.model.definition import DIRECTIONS, Curve, Spring


@dataclass(frozen=True)
class RigMechanics:
    """What the K&C rig's own structure does between its commands and the car (SI; all zero: the
    ideal rig, pads floating without friction, the body held rigidly).

    The pads float in x and y on bearings whose Coulomb friction each carriage feels (``pad_friction_n``),
    through the pad's own compliance in x and y in series with it (``pad_compliance_m_per_n``: a
    Jenkins element, the compliance taking the force before the bearing slips); a lateral force
    commanded at a pad reaches the contact patch less that friction. The body's clamps yield
    (``clamp_*``: about the body's centre of mass, in y, z, roll and pitch): the body moves with the
    loads the pads put through the car, while the rig measures the wheels against its bedplate."""

    pad_friction_n: float = 0.0                    #: each pad's bearing friction, x and y [N]
    pad_compliance_m_per_n: float = 0.0            #: each pad's compliance in x and y in series with it [m/N]
    clamp_lateral_m_per_n: float = 0.0             #: the body clamp's compliance in y [m/N]
    clamp_vertical_m_per_n: float = 0.0            #: in z [m/N]
    clamp_roll_rad_per_nm: float = 0.0             #: about x [rad/(N·m)]
    clamp_pitch_rad_per_nm: float = 0.0            #: about y [rad/(N·m)]

    def __post_init__(self):
        bad = [f"{k} = {v!r}" for k, v in vars(self).items() if not (math.isfinite(v) and v >= 0.0)]
        if bad:
            raise ValueError(f"rig mechanics: {bad[0]}; expected a finite value >= 0")

    @property
    def ideal(self) -> bool:
        """Whether the rig adds nothing (the default rig's model)."""
        return not any(vars(self).values())

    def clamp(self) -> tuple[tuple[str, str, float], ...]:
        """The body clamp's compliant directions: (joint type, axis, compliance) of each one not rigid."""
        return tuple((kind, axis, c) for kind, axis, c in (
            ("slide", "y", self.clamp_lateral_m_per_n), ("slide", "z", self.clamp_vertical_m_per_n),
            ("hinge", "x", self.clamp_roll_rad_per_nm), ("hinge", "y", self.clamp_pitch_rad_per_nm)) if c > 0.0)


@dataclass(frozen=True)
class BuildOptions:
    """How to build: rig or road, clamped or free body, bushing model override, time step."""

    rig: bool = True                    #: add the K&C rig (pads, rack drive, wheel locks)
    clamped: bool = True                #: body fixed to the world; otherwise a free joint
    road: bool = False                  #: on a flat road: free body, rack drive, ground plane (tyres: elastokin.vehicle.simulation.road)
    bushing_model: str | None = None    #: read every named bushing set as this model
    #: the directions ``bushing_model`` applies to (the others keep the vehicle file's law):
    #: ``("x", "y", "z")`` gives the thesis's 18 STVS models (Bourgeteau 2009, §6.3)
    bushing_model_directions: tuple[str, ...] = DIRECTIONS
    rigid_bushings: bool = False        #: translations rigid (kinematics); rotations unchanged
    #: [s]: the longest step of a run (a scenario's divides its output interval and resolves its
    #: inputs: elastokin.vehicle.scenarios.schedule.timestep). At 2 ms the rig's camber loop moves by
    #: < 0.005° and the road's yaw-rate response time by < 0.1 ms when it halves (tools/benchmarks).
    timestep: float = 2e-3
    #: the K&C rig's pads and body clamp (``rig`` only)
    rig_mechanics: RigMechanics = RigMechanics()

    def __post_init__(self):
        unknown = sorted(set(self.bushing_model_directions) - set(DIRECTIONS))
        if unknown:
            raise ValueError(f"unknown bushing direction(s) {', '.join(unknown)}; expected some of {', '.join(DIRECTIONS)}")


@dataclass
class Channel:
    """One bushing direction: a joint of the model and its force law."""

    name: str                            #: e.g. ``e1_front_left.y``
    joint: str
    params: ChannelParams                #: the law (SI)
    effects: Effects = NO_EFFECTS        #: state extensions of the law (elastokin.bushings.effects, SI)

    @property
    def linear(self) -> bool:
        """True when the whole law fits in the joint's stiffness and damping."""
        p = self.params
        return (p.model == "linear" and not math.isfinite(p.S_sup) and not math.isfinite(p.S_inf)
                and not self.effects.active)


@dataclass(frozen=True)
class CrossTerm:
    """A cross stiffness between two bushing joints: τ_a += −k·q_b, τ_b += −k·q_a (explicit)."""

    joint_a: str
    joint_b: str
    stiffness: float                     #: k [N/m or N·m/rad], this side's sign included


@dataclass
class Element:
    """A spring or damper acting along a scalar coordinate (a slide joint or a tendon)."""

    name: str
    kind: str                            #: "joint" or "tendon"
    target: str                          #: joint or tendon name
    sign: float                          #: compression = sign × (coordinate − design value)
    spring: Spring | None = None
    preload: float = 0.0                 #: [N]
    damper_curve: Curve | None = None    #: compression speed [m/s] → force [N]


def joint_stiffness(channel: Channel) -> float:
    """Stiffness to put in a bushing joint: the whole law if linear (implicit), else the
    reference tangent K0 + Kpa (the rest is applied explicitly by :mod:`elastokin.vehicle.simulation.coupling`)."""
    p = channel.params
    return p.K0 if channel.linear else p.K0 + p.Kpa
