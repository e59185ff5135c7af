"""The vehicle definition: what a vehicle file holds, validated, in SI and ISO 8855 (x forward, y left,
z up); hardpoints are the left side's, the right side being their mirror image.

Bushing directions keep their parameters in the bushing library's user-facing form and are
converted by :meth:`DirectionDef.channel` (and their law extensions by :meth:`DirectionDef.effects_si`).
The file is read by :mod:`elastokin.vehicle.model.vehicle_file`, which also sets the catalogue's extensions
(spec measured-data.md §2) without a file.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from elastokin.bushings.effects import Effects, effects_to_si
from elastokin.bushings.parameter_sets import ParameterSet, load_parameter_set
from elastokin.bushings.parameters import MODELS, ChannelParams, to_si
from elastokin.core.errors import InputError

FRONT_POINTS = ("wheel_centre", "lower_ball_joint", "wishbone_front_pivot", "wishbone_rear_pivot",
                "strut_top", "strut_lower", "tie_rod_outer", "tie_rod_inner")
REAR_POINTS = ("wheel_centre", "arm_pivot", "beam_centre", "spring_lower", "spring_upper",
               "damper_lower", "damper_upper")
FRONT_MASSES = ("wishbone", "knuckle", "strut_rod", "rack")
REAR_MASSES = ("arm", "hub")
#: The car's sides (+1 left, −1 right for mirroring) and its corners.
SIDES = (("left", 1.0), ("right", -1.0))
CORNERS = ("front_left", "front_right", "rear_left", "rear_right")
#: +1 for a left corner, −1 for a right one (a right part is the mirror image of the left: y → −y).
SIDE_SIGN = {c: 1.0 if c.endswith("left") else -1.0 for c in CORNERS}
#: Models ``--bushing-model`` may put on every bushing direction (:meth:`DirectionDef.channel`).
BUSHING_MODELS = ("linear", "sts", "rt", "stvs")
#: Bushing directions: translations along, then rotations about, the bushing's own x, y, z axes.
DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")
#: Parts a bushing may connect (`child`); the parent is always the body.
BUSHING_PARTS = ("front.wishbone", "rear.arm")
Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Curve:
    """A piecewise-linear characteristic, extrapolated linearly beyond its end points."""

    x: tuple[float, ...]
    y: tuple[float, ...]

    def __call__(self, x: float) -> float:
        xs, ys = np.asarray(self.x), np.asarray(self.y)
        i = int(np.clip(np.searchsorted(xs, x) - 1, 0, len(xs) - 2))
        return float(ys[i] + (ys[i + 1] - ys[i]) / (xs[i + 1] - xs[i]) * (x - xs[i]))


@dataclass(frozen=True)
class Spring:
    """Coil spring: force pushing apart [N] = preload + curve(compression) − curve(0).

    ``curve`` maps compression from design [m] (positive in bump) to force [N]; a linear spring
    is the two-point curve of its rate. ``preload`` is None when it is to be computed so that
    the spring carries the static load at design height.
    """

    curve: Curve
    preload: float | None

    @property
    def rate(self) -> float:
        """Stiffness at design [N/m] (slope of the curve at zero compression)."""
        eps = 1e-6
        return (self.curve(eps) - self.curve(-eps)) / (2 * eps)


@dataclass(frozen=True)
class Damper:
    """Damper: ``curve`` maps compression speed [m/s] to the force pushing apart [N]."""

    curve: Curve


@dataclass(frozen=True)
class Families:
    """Laws read when ``--bushing-model`` names a model a direction's own law has no parameters for.

    ``sets`` maps a model to a translation parameter set of models/bushings/ (``stvs: fig5_9``);
    the set is scaled to the direction's own large-amplitude stiffness K0 (:func:`scaled_like`),
    a rotation through the lever arm ``rotation_lever_arm`` [m] (θ [rad] ≡ ℓ·θ [m]).
    """

    sets: Mapping[str, str]
    rotation_lever_arm: float           #: [m]


NO_FAMILIES = Families({}, 1.0)


def scaled_like(reference: ChannelParams, K0: float, lever_arm: float = 1.0) -> ChannelParams:
    """``reference`` (SI :class:`bushings.ChannelParams` of a translation) scaled to stiffness ``K0``.

    Forces scale by ``a`` at equal deflections; with ``lever_arm`` ℓ the result is a rotation law
    T(θ) = ℓ·a·F(ℓ·θ) [N·m, rad]. ``a`` is chosen so that the result's K0 is ``K0``; the shape
    (Kpa/K0, Kr/K0, deflection at which sliders slip, power-law exponent) is the reference's.
    """
    l = lever_arm
    a = K0 / (l * l * reference.K0)
    k = l * l * a  # stiffness and viscous factor
    quantity = "translation" if l == 1.0 else "rotation"
    return reference.replace(
        quantity=quantity, K0=K0, C=k * reference.C, Kpa=k * reference.Kpa, Kr=k * reference.Kr,
        Ff=l * a * reference.Ff, Co=a * reference.Co * l ** (1.0 + reference.pw),
        Ct=(l * a) ** reference.n_root * l * reference.Ct,
        N_sup=reference.N_sup / l, N_inf=reference.N_inf / l, S_sup=reference.S_sup / l,
        S_inf=reference.S_inf / l, P_sup=l * a * reference.P_sup, P_inf=l * a * reference.P_inf,
        maxwell_k=tuple(k * v for v in reference.maxwell_k), maxwell_c=tuple(k * v for v in reference.maxwell_c))


@dataclass(frozen=True)
class DirectionDef:
    """The force law of one bushing direction, as written in the vehicle file."""

    quantity: str                       #: "translation" or "rotation"
    set_name: str | None                #: named parameter set in models/bushings/, or None
    model: str | None                   #: model to read the set as, or the inline model
    params: Mapping[str, Any] | None    #: inline parameters (thesis units), or None
    source: str = field(compare=False)  #: file and key, for error messages (not what the law is)
    families: Families = NO_FAMILIES    #: laws for run-time models this one cannot be read as
    #: state extensions of the law (:mod:`elastokin.bushings.effects`, parameter-set units), over the set's own
    effects: Mapping[str, Any] = field(default_factory=dict)

    @functools.cached_property
    def named_set(self) -> ParameterSet | None:
        """The named parameter set, read once for this direction (every build reads it for both
        sides; a diagnosis builds hundreds of cars), or None for inline parameters. Read it, never
        change it; a change to its file after it was first read is not seen here (load the vehicle again)."""
        return load_parameter_set(self.set_name) if self.set_name is not None else None

    def effects_si(self) -> Effects:
        """The law's :class:`elastokin.bushings.effects.Effects` (SI): its set's ``effects`` with this
        direction's own ``effects`` keys over them. They apply whatever model the law is read as."""
        own = self.named_set.effects if self.named_set is not None else {}
        return effects_to_si({**own, **self.effects}, self.quantity, self.source)

    def channel(self, override_model: str | None = None) -> ChannelParams:
        """SI :class:`bushings.ChannelParams` of this direction, optionally read as another model.

        ``override_model`` (run-time ``--bushing-model``) reads the direction's own set or inline
        parameters as that model when they hold its parameters (an STVS set read as ``sts``
        drops Co and pw; anything read as ``linear`` keeps K0); otherwise the vehicle's family
        set of that model is scaled to the direction's own K0 (:class:`Families`). Read as its own
        model, a direction's law always comes from its own parameters (a missing one is an error).
        """
        pset = self.named_set
        if pset is not None and pset.quantity != self.quantity:
            raise InputError(f"parameter set {self.set_name!r} is a {pset.quantity} set; this "
                             f"direction needs a {self.quantity} set", source=self.source, key="set")
        own = pset.values if pset is not None else self.params
        target = override_model or self.model
        if target is not None and (not isinstance(target, str) or target not in MODELS):
            raise InputError(f"unknown model {target!r}; expected one of {', '.join(MODELS)}",
                             source=self.source, key="model")
        if target is None or target == self.model or set(MODELS[target][0]) <= set(own):
            if pset is not None:
                return pset.channel(target)
            values = dict(own)
            if target != self.model:  # reading inline parameters as another model keeps its own
                values = {k: v for k, v in values.items() if k in MODELS[target][0] + MODELS[target][1]}
            return to_si(target, values, self.quantity, source=self.source)
        family = self.families.sets.get(target)
        if family is None:
            raise InputError(f"this direction's law has no {target} parameters and the vehicle names no "
                             f"`bushing_families.sets.{target}`", source=self.source)
        reference = load_parameter_set(family).channel(target)
        if reference.quantity != "translation":
            raise InputError(f"family set {family!r} must be a translation set", source=self.source)
        lever = 1.0 if self.quantity == "translation" else self.families.rotation_lever_arm
        return scaled_like(reference, self.channel().K0, lever)


@dataclass(frozen=True)
class CrossStiffness:
    """A symmetric stiffness between two directions of one bushing (directional coupling).

    It adds F_a += k·e_b and F_b += k·e_a, the forces of the energy k·e_a·e_b, so it stores and
    returns energy but never dissipates it. Both directions have the same quantity.
    """

    directions: tuple[str, str]          #: two of DIRECTIONS, both translations or both rotations
    stiffness: float                     #: k [N/m] or [N·m/rad]


@dataclass(frozen=True)
class BushingDef:
    """A 6-direction bushing between the body and a suspension part (left side)."""

    name: str
    parent: str                          #: always "body"
    child: str                           #: one of BUSHING_PARTS
    location: Vec3                       #: centre [m]
    axes: tuple[Vec3, Vec3, Vec3]        #: the bushing's x, y, z axes (orthonormal, right-handed)
    directions: Mapping[str, DirectionDef]
    coupling: tuple[CrossStiffness, ...] = ()   #: cross stiffnesses between its directions


@dataclass(frozen=True)
class Tyre:
    """The wheel and tyre: loaded radius, the wheel's mass and inertia, the tyre's property file."""

    radius: float                        #: loaded radius at design [m] (the rig's contact points)
    wheel_mass: float                    #: [kg]
    wheel_inertia: tuple[float, float]   #: about the spin axis and a diameter [kg·m²]
    property_file: Path | None = None    #: the tyre's .tir file (the road needs one), or None


@dataclass(frozen=True)
class Body:
    """The sprung body: mass, CG, inertia and where its ride height is measured."""

    mass: float                          #: sprung mass [kg]
    cg: Vec3                             #: [m]
    inertia: Vec3                        #: principal inertias about the CG [kg·m²]
    ride_height_point: Vec3              #: reference point on the body [m]
    design_ride_height: float            #: its height above ground at design [m]


@dataclass(frozen=True)
class FrontAxle:
    """The pseudo-McPherson front axle (left side): hardpoints, alignment, masses, spring, damper, bar, steering."""

    hardpoints: Mapping[str, Vec3]       #: left side [m]
    static_toe: float                    #: toe-in [rad]
    static_camber: float                 #: top outward positive [rad]
    masses: Mapping[str, float]          #: [kg]
    spring: Spring
    damper: Damper
    anti_roll_rate: float                #: [N/m] of left-minus-right strut length
    rack_travel_per_rev: float           #: [m] per steering-wheel revolution
    strut_friction: tuple[float, float] = (0.0, 0.0)   #: Coulomb friction of the rod in the tube [N], (left, right)


@dataclass(frozen=True)
class RearAxle:
    """The twist-beam rear axle (left side): hardpoints, alignment, masses, the beam's torsion, spring, damper."""

    hardpoints: Mapping[str, Vec3]
    static_toe: float                    #: [rad]
    static_camber: float                 #: [rad]
    masses: Mapping[str, float]
    beam_torsional_stiffness: float      #: [N·m/rad]
    spring: Spring
    damper: Damper
    beam_torsion_scale: float = 1.0      #: factor on beam_torsional_stiffness (an error of the beam's design value)
    #: [N·m/rad] of relative arm rotation about the car's x axis at the beam centre: the beam bending in
    #: the vertical plane, which cambers both wheels alike in parallel bump; None: rigid in bending
    beam_bending_stiffness: float | None = None

    @property
    def beam_torsion(self) -> float:
        """Torsional stiffness of the beam as built [N·m/rad]."""
        return self.beam_torsional_stiffness * self.beam_torsion_scale


@dataclass(frozen=True)
class VehicleDefinition:
    """A validated vehicle file, SI and ISO 8855."""

    name: str
    description: str
    path: Path
    tyre: Tyre
    body: Body
    front: FrontAxle
    rear: RearAxle
    bushings: tuple[BushingDef, ...]
    text: str = ""                        #: the vehicle file's text ("" when changed in code)

    def point(self, ref: str) -> np.ndarray:
        """A left-side hardpoint by its dotted name (``front.strut_top``) [m]."""
        axle, _, name = ref.partition(".")
        return np.array(getattr(self, axle).hardpoints[name])


def is_rotation(channel: str) -> bool:
    """Whether a bushing channel (``e1_front_left.rx``: a bushing and one of :data:`DIRECTIONS`) is a rotation."""
    return channel.split(".")[1].startswith("r")
