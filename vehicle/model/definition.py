"""Vehicle definition: load and validate a vehicle YAML file (format: models/vehicles/README.md).

Everything returned is SI (m, kg, N, s, rad) and ISO 8855 (x forward, y left, z up); hardpoints
are the left side's, the right side being their mirror image. Bushing directions keep their
parameters in the bushing library's user-facing form and are converted by
:meth:`DirectionDef.channel` (and their law extensions by :meth:`DirectionDef.effects_si`). Bad
input raises :class:`InputError` naming file, key and value.

The catalogue's extensions (spec measured-data.md §2) are parameters of the definition, off by
default: bushing law effects and directional coupling per bushing, the front struts' friction and a
factor on the twist beam's torsion; :func:`with_extensions` sets them without a file (a truth
vehicle and its hypotheses from one baseline).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence

import numpy as np
import yaml

from vsim_core.errors import InputError
from vsim_core.shipped import DEFAULT_VEHICLE

if TYPE_CHECKING:
    from bushings.effects import Effects

#: Folder of the vehicle files shipped with the project.

FRONT_POINTS = ("wheel_centre", "lower_ball_joint", "wishbone_front_pivot", "wishbone_rear_pivot",
                "strut_top", "strut_lower", "tie_rod_outer", "tie_rod_inner")
REAR_POINTS = ("wheel_centre", "arm_pivot", "beam_centre", "spring_lower", "spring_upper",
               "damper_lower", "damper_upper")
FRONT_MASSES = ("wishbone", "knuckle", "strut_rod", "rack")
REAR_MASSES = ("arm", "hub")
#: Bushing directions: translations along, then rotations about, the bushing's own x, y, z axes.
DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")
#: Parts a bushing may connect (`child`); the parent is always the body.
BUSHING_PARTS = ("front.wishbone", "rear.arm")
Vec3 = tuple[float, float, float]
#: Source named in the errors of :func:`with_extensions`.
EXTENSIONS_SOURCE = "with_extensions"


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
    """Laws read when ``--bushings`` names a model a direction's own law has no parameters for.

    ``sets`` maps a model to a translation parameter set of models/bushings/ (``stvs: fig5_9``);
    the set is scaled to the direction's own large-amplitude stiffness K0 (:func:`scaled_like`),
    a rotation through the lever arm ``rotation_lever_arm`` [m] (θ [rad] ≡ ℓ·θ [m]).
    """

    sets: Mapping[str, str]
    rotation_lever_arm: float           #: [m]


NO_FAMILIES = Families({}, 1.0)


def scaled_like(reference, K0: float, lever_arm: float = 1.0):
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
    source: str                         #: file and key, for error messages
    families: Families = NO_FAMILIES    #: laws for run-time models this one cannot be read as
    #: state extensions of the law (:mod:`bushings.effects`, parameter-set units), over the set's own
    effects: Mapping[str, Any] = field(default_factory=dict)

    def effects_si(self) -> Effects:
        """The law's :class:`bushings.effects.Effects` (SI): its set's ``effects`` with this
        direction's own ``effects`` keys over them. They apply whatever model the law is read as."""
        from bushings.effects import effects_to_si
        from bushings.parameters import load_parameter_set

        own = load_parameter_set(self.set_name).effects if self.set_name is not None else {}
        return effects_to_si({**own, **self.effects}, self.quantity, self.source)

    def channel(self, override_model: str | None = None):
        """SI :class:`bushings.ChannelParams` of this direction, optionally read as another model.

        ``override_model`` (run-time ``--bushings``) reads the direction's own set or inline
        parameters as that model when they hold its parameters (an STVS set read as ``sts``
        drops Co and pw; anything read as ``linear`` keeps K0); otherwise the vehicle's family
        set of that model is scaled to the direction's own K0 (:class:`Families`).
        """
        from bushings.parameters import MODELS, load_parameter_set, to_si

        pset = load_parameter_set(self.set_name) if self.set_name is not None else None
        if pset is not None and pset.quantity != self.quantity:
            raise InputError(f"parameter set {self.set_name!r} is a {pset.quantity} set; this "
                             f"direction needs a {self.quantity} set", source=self.source, key="set")
        own = pset.values if pset is not None else self.params
        target = override_model or self.model
        if target is not None and target not in MODELS:
            raise InputError(f"unknown model {target!r}; expected one of {', '.join(MODELS)}",
                             source=self.source, key="model")
        if target is None or set(MODELS[target][0]) <= set(own):
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
    radius: float                        #: loaded radius [m]
    wheel_mass: float                    #: [kg]
    wheel_inertia: tuple[float, float]   #: about the spin axis and a diameter [kg·m²]


@dataclass(frozen=True)
class Body:
    mass: float                          #: sprung mass [kg]
    cg: Vec3                             #: [m]
    inertia: Vec3                        #: principal inertias about the CG [kg·m²]
    ride_height_point: Vec3              #: reference point on the body [m]
    design_ride_height: float            #: its height above ground at design [m]


@dataclass(frozen=True)
class FrontAxle:
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
    hardpoints: Mapping[str, Vec3]
    static_toe: float                    #: [rad]
    static_camber: float                 #: [rad]
    masses: Mapping[str, float]
    beam_torsional_stiffness: float      #: [N·m/rad]
    spring: Spring
    damper: Damper
    beam_torsion_scale: float = 1.0      #: factor on beam_torsional_stiffness (an error of the beam's design value)

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

    def point(self, ref: str) -> np.ndarray:
        """A left-side hardpoint by its dotted name (``front.strut_top``) [m]."""
        axle, _, name = ref.partition(".")
        return np.array(getattr(self, axle).hardpoints[name])


class _Reader:
    """Checks one mapping of the file: typed getters that name the dotted key on error."""

    def __init__(self, data: Any, source: str, key: str, allowed: tuple[str, ...]):
        self.source, self.key = source, key
        if not isinstance(data, Mapping):
            raise InputError(f"expected a mapping, got {data!r}", source=source, key=key or None)
        unknown = sorted(set(data) - set(allowed))
        if unknown:
            raise InputError(f"unknown key {unknown[0]!r}; expected one of {', '.join(allowed)}",
                             source=source, key=self.sub(unknown[0]))
        self.data = data

    def sub(self, name: str) -> str:
        return f"{self.key}.{name}" if self.key else name

    def raw(self, name: str, default: Any = ...) -> Any:
        if name not in self.data:
            if default is ...:
                raise InputError("missing key", source=self.source, key=self.sub(name))
            return default
        return self.data[name]

    def number(self, name: str, *, positive: bool = False, nonneg: bool = False, default: Any = ...) -> float:
        value = self.raw(name, default)
        return _number(value, self.source, self.sub(name), positive=positive, nonneg=nonneg)

    def vector(self, name: str, n: int = 3) -> tuple[float, ...]:
        return _vector(self.raw(name), self.source, self.sub(name), n)

    def reader(self, name: str, allowed: tuple[str, ...]) -> "_Reader":
        return _Reader(self.raw(name), self.source, self.sub(name), allowed)


def _number(value: Any, source: str, key: str, *, positive: bool = False, nonneg: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"expected a finite number, got {value!r}", source=source, key=key)
    if positive and value <= 0:
        raise InputError(f"expected a positive number, got {value!r}", source=source, key=key)
    if nonneg and value < 0:
        raise InputError(f"expected a non-negative number, got {value!r}", source=source, key=key)
    return float(value)


def _vector(value: Any, source: str, key: str, n: int) -> tuple[float, ...]:
    if not isinstance(value, (list, tuple)) or len(value) != n:
        raise InputError(f"expected a list of {n} numbers, got {value!r}", source=source, key=key)
    return tuple(_number(v, source, f"{key}[{i}]") for i, v in enumerate(value))


def _curve(value: Any, source: str, key: str) -> Curve:
    if not isinstance(value, (list, tuple)) or len(value) < 2:
        raise InputError(f"expected a list of at least two [x, F] points, got {value!r}", source=source, key=key)
    pts = [_vector(p, source, f"{key}[{i}]", 2) for i, p in enumerate(value)]
    xs = [p[0] for p in pts]
    if any(b <= a for a, b in zip(xs, xs[1:])):
        raise InputError(f"expected strictly increasing x values, got {xs}", source=source, key=key)
    return Curve(tuple(xs), tuple(p[1] for p in pts))


def _spring(r: _Reader) -> Spring:
    if ("rate" in r.data) == ("curve" in r.data):
        raise InputError("give exactly one of `rate` [N/m] or `curve` [[compression m, force N], ...]",
                         source=r.source, key=r.key)
    if "rate" in r.data:
        k = r.number("rate", positive=True)
        curve = Curve((-1.0, 1.0), (-k, k))
    else:
        curve = _curve(r.raw("curve"), r.source, r.sub("curve"))
    preload = r.raw("preload", "auto")
    if preload == "auto":
        return Spring(curve, None)
    return Spring(curve, _number(preload, r.source, r.sub("preload")))


def _points(r: _Reader, names: tuple[str, ...]) -> dict[str, Vec3]:
    points = {name: r.vector(name) for name in names}
    for name, p in points.items():
        if p[1] <= 0 and name != "beam_centre":
            raise InputError(f"expected a left-side point (y > 0), got {list(p)}", source=r.source, key=r.sub(name))
    return points


def _masses(r: _Reader, names: tuple[str, ...]) -> dict[str, float]:
    return {name: r.number(name, positive=True) for name in names}


def _per_side(value: Any, source: str, key: str) -> tuple[float, float]:
    """A non-negative value for both sides, or ``{left: a, right: b}``: (left, right)."""
    if isinstance(value, Mapping):
        r = _Reader(value, source, key, ("left", "right"))
        return r.number("left", nonneg=True), r.number("right", nonneg=True)
    v = _number(value, source, key, nonneg=True)
    return v, v


def _mapping(value: Any, source: str, key: str) -> dict[str, Any]:
    if not isinstance(value, Mapping):
        raise InputError(f"expected a mapping, got {value!r}", source=source, key=key)
    return dict(value)


def _checked(d: DirectionDef, source: str, key: str) -> DirectionDef:
    """``d`` after building its law and effects once, so that errors name ``source`` and ``key``."""
    try:
        d.channel()
        d.effects_si()
    except InputError as exc:
        if exc.source and exc.source.startswith(source):
            raise
        raise InputError(str(exc), source=source, key=key) from exc
    return d


def _direction(value: Any, source: str, key: str, quantity: str, families: Families) -> DirectionDef:
    r = _Reader(value, source, key, ("set", "model", "params", "effects"))
    if ("set" in r.data) == ("params" in r.data):
        raise InputError("give either `set` (a parameter set of models/bushings/) or `model` with `params`",
                         source=source, key=key)
    model = r.raw("model", None)
    if model is not None and not isinstance(model, str):
        raise InputError(f"expected a model name, got {model!r}", source=source, key=r.sub("model"))
    effects = _mapping(r.raw("effects", {}), source, r.sub("effects"))
    if "set" in r.data:
        name = r.raw("set")
        if not isinstance(name, str):
            raise InputError(f"expected a parameter-set name, got {name!r}", source=source, key=r.sub("set"))
        d = DirectionDef(quantity, name, model, None, f"{source}: {key}", families, effects)
    else:
        if model is None:
            raise InputError("missing key (inline parameters need a model)", source=source, key=r.sub("model"))
        if not isinstance(r.raw("params"), Mapping):
            raise InputError(f"expected a mapping of parameters, got {r.raw('params')!r}",
                             source=source, key=r.sub("params"))
        d = DirectionDef(quantity, None, model, dict(r.raw("params")), f"{source}: {key}", families, effects)
    return _checked(d, source, key)


def _coupling(value: Any, source: str, key: str, directions: Mapping[str, DirectionDef]) -> tuple[CrossStiffness, ...]:
    """A bushing's ``coupling`` list: ``[{directions: [a, b], stiffness: k}]``, k in N/mm between two
    translations or N·m/deg between two rotations (mixed pairs are refused: no common unit)."""
    from bushings.parameters import LENGTH_UNIT_SI, UNIT_LABELS

    if not isinstance(value, (list, tuple)):
        raise InputError(f"expected a list of {{directions: [a, b], stiffness: k}}, got {value!r}", source=source,
                         key=key)
    terms: list[CrossStiffness] = []
    for i, item in enumerate(value):
        r = _Reader(item, source, f"{key}[{i}]", ("directions", "stiffness"))
        pair = r.raw("directions")
        if (not isinstance(pair, (list, tuple)) or len(pair) != 2 or any(p not in DIRECTIONS for p in pair)
                or pair[0] == pair[1] or any({pair[0], pair[1]} == set(t.directions) for t in terms)):
            raise InputError(f"expected two different directions of {', '.join(DIRECTIONS)}, not coupled "
                             f"already, got {pair!r}", source=source, key=r.sub("directions"))
        a, b = directions[pair[0]], directions[pair[1]]
        if a.quantity != b.quantity:
            raise InputError(f"cannot couple a translation with a rotation ({pair[0]}, {pair[1]}): their "
                             f"stiffness has no common unit", source=source, key=r.sub("directions"))
        unit = LENGTH_UNIT_SI[a.quantity]
        k = r.number("stiffness") / unit
        # the coupled tangent [[K0_a, k], [k, K0_b]] must stay positive definite at large amplitude
        bound = math.sqrt(a.channel().K0 * b.channel().K0)
        if not abs(k) < bound:
            force, length = UNIT_LABELS[a.quantity]
            raise InputError(f"expected |stiffness| < sqrt(K0_{pair[0]}·K0_{pair[1]}) = {bound * unit:.6g} "
                             f"{force}/{length} (the coupled law must stay positive definite), got {k * unit!r}",
                             source=source, key=r.sub("stiffness"))
        terms.append(CrossStiffness((pair[0], pair[1]), k))
    return tuple(terms)


def _axis(value: Any, source: str, key: str, points: Mapping[str, np.ndarray]) -> np.ndarray:
    if isinstance(value, Mapping):
        r = _Reader(value, source, key, ("from", "to"))
        ends = []
        for end in ("from", "to"):
            ref = r.raw(end)
            if ref not in points:
                raise InputError(f"unknown hardpoint {ref!r}; expected one of {', '.join(sorted(points))}",
                                 source=source, key=r.sub(end))
            ends.append(points[ref])
        v = ends[1] - ends[0]
    else:
        v = np.array(_vector(value, source, key, 3))
    if np.linalg.norm(v) < 1e-9:
        raise InputError(f"expected a non-zero direction, got {value!r}", source=source, key=key)
    return v / np.linalg.norm(v)


def _bushing(value: Any, source: str, key: str, points: Mapping[str, np.ndarray], families: Families) -> BushingDef:
    r = _Reader(value, source, key, ("name", "parent", "child", "location", "axes", "directions", "coupling"))
    name = r.raw("name")
    if not isinstance(name, str) or not name.isidentifier():
        raise InputError(f"expected an identifier, got {name!r}", source=source, key=r.sub("name"))
    if r.raw("parent") != "body":
        raise InputError(f"expected 'body', got {r.raw('parent')!r}", source=source, key=r.sub("parent"))
    child = r.raw("child")
    if child not in BUSHING_PARTS:
        raise InputError(f"expected one of {', '.join(BUSHING_PARTS)}, got {child!r}", source=source,
                         key=r.sub("child"))
    loc = r.raw("location")
    if isinstance(loc, str):
        if loc not in points:
            raise InputError(f"unknown hardpoint {loc!r}; expected one of {', '.join(sorted(points))}",
                             source=source, key=r.sub("location"))
        location = tuple(float(v) for v in points[loc])
    else:
        location = _vector(loc, source, r.sub("location"), 3)
    ax = r.reader("axes", ("x", "y"))
    x = _axis(ax.raw("x"), source, ax.sub("x"), points)
    y = _axis(ax.raw("y"), source, ax.sub("y"), points)
    y = y - x * float(x @ y)
    if np.linalg.norm(y) < 1e-6:
        raise InputError("axes.y is parallel to axes.x", source=source, key=ax.sub("y"))
    y /= np.linalg.norm(y)
    z = np.cross(x, y)
    dr = r.reader("directions", DIRECTIONS)
    directions = {}
    for d in DIRECTIONS:
        quantity = "translation" if len(d) == 1 else "rotation"
        directions[d] = _direction(dr.raw(d), source, dr.sub(d), quantity, families)
    coupling = _coupling(r.raw("coupling", []), source, r.sub("coupling"), directions)
    return BushingDef(name, "body", child, location,
                      (tuple(x.tolist()), tuple(y.tolist()), tuple(z.tolist())), directions, coupling)


def _families(top: _Reader) -> Families:
    if "bushing_families" not in top.data:
        return NO_FAMILIES
    from bushings.parameters import MODELS, load_parameter_set

    r = top.reader("bushing_families", ("sets", "rotation_lever_arm"))
    sets = r.raw("sets")
    if not isinstance(sets, Mapping) or any(m not in MODELS or not isinstance(n, str) for m, n in sets.items()):
        raise InputError(f"expected a mapping of model ({', '.join(MODELS)}) to parameter-set name, got {sets!r}",
                         source=r.source, key=r.sub("sets"))
    for m, n in sets.items():
        try:
            load_parameter_set(n).channel(m)
        except InputError as exc:
            raise InputError(str(exc), source=r.source, key=r.sub(f"sets.{m}")) from exc
    return Families(dict(sets), r.number("rotation_lever_arm", positive=True))


def load_vehicle(path: str | Path = DEFAULT_VEHICLE) -> VehicleDefinition:
    """Load and validate a vehicle file; raises :class:`InputError` naming file, key and value."""
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputError("no such vehicle file", source=source)
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise InputError(f"not valid YAML: {exc}", source=source) from exc
    top = _Reader(data, source, "", ("name", "description", "tyre", "body", "front", "rear", "bushing_families",
                                     "bushings"))

    t = top.reader("tyre", ("radius", "wheel_mass", "wheel_inertia"))
    inertia = t.vector("wheel_inertia", 2)
    if min(inertia) <= 0:
        raise InputError(f"expected positive inertias, got {list(inertia)}", source=source, key=t.sub("wheel_inertia"))
    tyre = Tyre(t.number("radius", positive=True), t.number("wheel_mass", positive=True), inertia)

    b = top.reader("body", ("mass", "cg", "inertia", "ride_height_point", "design_ride_height"))
    body = Body(b.number("mass", positive=True), b.vector("cg"), b.vector("inertia"),
                b.vector("ride_height_point"), b.number("design_ride_height"))

    f = top.reader("front", ("hardpoints", "static_toe", "static_camber", "masses", "spring", "damper",
                             "anti_roll_bar", "steering", "strut_friction"))
    front = FrontAxle(
        hardpoints=_points(f.reader("hardpoints", FRONT_POINTS), FRONT_POINTS),
        static_toe=math.radians(f.number("static_toe")), static_camber=math.radians(f.number("static_camber")),
        masses=_masses(f.reader("masses", FRONT_MASSES), FRONT_MASSES),
        spring=_spring(f.reader("spring", ("rate", "curve", "preload"))),
        damper=Damper(_curve(f.reader("damper", ("curve",)).raw("curve"), source, "front.damper.curve")),
        anti_roll_rate=f.reader("anti_roll_bar", ("rate",)).number("rate", nonneg=True),
        rack_travel_per_rev=f.reader("steering", ("rack_travel_per_rev",)).number("rack_travel_per_rev",
                                                                                  positive=True),
        strut_friction=_per_side(f.raw("strut_friction", 0.0), source, f.sub("strut_friction")))
    rr = top.reader("rear", ("hardpoints", "static_toe", "static_camber", "masses", "beam_torsional_stiffness",
                             "beam_torsion_scale", "spring", "damper"))
    rear = RearAxle(
        hardpoints=_points(rr.reader("hardpoints", REAR_POINTS), REAR_POINTS),
        static_toe=math.radians(rr.number("static_toe")), static_camber=math.radians(rr.number("static_camber")),
        masses=_masses(rr.reader("masses", REAR_MASSES), REAR_MASSES),
        beam_torsional_stiffness=rr.number("beam_torsional_stiffness", positive=True),
        spring=_spring(rr.reader("spring", ("rate", "curve", "preload"))),
        damper=Damper(_curve(rr.reader("damper", ("curve",)).raw("curve"), source, "rear.damper.curve")),
        beam_torsion_scale=rr.number("beam_torsion_scale", positive=True, default=1.0))

    points = {f"front.{k}": np.array(v) for k, v in front.hardpoints.items()}
    points |= {f"rear.{k}": np.array(v) for k, v in rear.hardpoints.items()}
    raw = top.raw("bushings")
    if not isinstance(raw, list) or not raw:
        raise InputError(f"expected a non-empty list of bushings, got {raw!r}", source=source, key="bushings")
    families = _families(top)
    bushings = tuple(_bushing(v, source, f"bushings[{i}]", points, families) for i, v in enumerate(raw))
    names = [bu.name for bu in bushings]
    if len(set(names)) != len(names):
        raise InputError(f"duplicate bushing names in {names}", source=source, key="bushings")
    for part in BUSHING_PARTS:
        if not any(bu.child == part for bu in bushings):
            raise InputError(f"no bushing connects {part} to the body", source=source, key="bushings")
    name = top.raw("name")
    if not isinstance(name, str):
        raise InputError(f"expected a name, got {name!r}", source=source, key="name")
    return VehicleDefinition(name, str(top.raw("description", "")), path, tyre, body, front, rear, bushings)


def with_extensions(v: VehicleDefinition, *, strut_friction: float | Mapping[str, float] | None = None,
                    beam_torsion_scale: float | None = None,
                    effects: Mapping[str, Mapping[str, float]] | None = None,
                    coupling: Mapping[str, Sequence[Mapping[str, Any]]] | None = None,
                    laws: Mapping[str, Any] | None = None) -> VehicleDefinition:
    """``v`` with the catalogue's extensions set, without writing a file (None keeps one as it is).

    ``strut_friction`` [N] and ``beam_torsion_scale`` as the keys ``front.strut_friction`` (a number
    for both struts or ``{left: a, right: b}``) and ``rear.beam_torsion_scale``; ``effects`` maps
    ``"bushing.direction"`` to effect keys in parameter-set units (``{"e1_rear.z": {"mullins": 0.2}}``),
    laid over the direction's own; ``coupling`` maps a bushing name to its new ``coupling`` list
    (``{"e1_rear": [{"directions": ["x", "z"], "stiffness": 50.0}]}``, N/mm or N·m/deg), which
    replaces the old one; ``laws`` maps ``"bushing.direction"`` to a
    :class:`bushings.parameters.ParameterSet` that replaces the direction's law, its effects included
    (a catalogue cause applied to the direction's own set). Values are checked as in a vehicle file;
    errors name ``with_extensions``.
    """
    src = EXTENSIONS_SOURCE
    front, rear = v.front, v.rear
    if strut_friction is not None:
        front = replace(front, strut_friction=_per_side(strut_friction, src, "strut_friction"))
    if beam_torsion_scale is not None:
        rear = replace(rear, beam_torsion_scale=_number(beam_torsion_scale, src, "beam_torsion_scale", positive=True))
    bushings = {b.name: b for b in v.bushings}

    def bushing(name: str, key: str) -> BushingDef:
        if name not in bushings:
            raise InputError(f"unknown bushing {name!r}; expected one of {', '.join(bushings)}", source=src, key=key)
        return bushings[name]

    def set_direction(target: str, key: str, change: Callable[[DirectionDef], DirectionDef]) -> None:
        name, _, direction = str(target).partition(".")
        b = bushing(name, key)
        if direction not in DIRECTIONS:
            raise InputError(f"expected 'bushing.direction' with a direction of {', '.join(DIRECTIONS)}, got "
                             f"{target!r}", source=src, key=key)
        d = _checked(change(b.directions[direction]), src, key)
        bushings[name] = replace(b, directions={**b.directions, direction: d})

    for target, pset in (laws or {}).items():
        key = f"laws.{target}"

        def law(d: DirectionDef) -> DirectionDef:
            if pset.quantity != d.quantity:
                raise InputError(f"parameter set {pset.name!r} is a {pset.quantity} set; {target} needs a "
                                 f"{d.quantity} set", source=src, key=key)
            return replace(d, set_name=None, model=pset.model, params=dict(pset.values), source=f"{src}: {key}",
                           effects=dict(pset.effects))
        set_direction(target, key, law)
    for target, values in (effects or {}).items():
        key = f"effects.{target}"
        set_direction(target, key, lambda d: replace(d, effects={**d.effects, **_mapping(values, src, key)}))
    for name, terms in (coupling or {}).items():
        b = bushing(name, f"coupling.{name}")
        bushings[name] = replace(b, coupling=_coupling(terms, src, f"coupling.{name}", b.directions))
    return replace(v, front=front, rear=rear, bushings=tuple(bushings.values()))
