"""Reading a vehicle file (format: models/vehicles/README.md) into a :class:`VehicleDefinition`, and
setting the catalogue's extensions on a definition without a file (:func:`with_extensions`: a truth
vehicle and its hypotheses from one baseline).

Values are converted to SI and ISO 8855 here, once. Bad input raises :class:`InputError` naming
file:line, the dotted key, the value and what was expected; the extensions set in code are checked
by the same readers, their errors naming ``with_extensions``.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from elastokin.bushings.adams_bus import BusFile, read_bus
from elastokin.bushings.parameter_sets import ParameterSet, load_parameter_set
from elastokin.bushings.parameters import LENGTH_UNIT_SI, MODELS, UNIT_LABELS
from elastokin.vehicle.model.definition import (BUSHING_PARTS, DIRECTIONS, FRONT_MASSES, FRONT_POINTS, NO_FAMILIES, REAR_MASSES,
                                      REAR_POINTS, Body, BushingDef, CrossStiffness, Curve, Damper, DirectionDef,
                                      Families, FrontAxle, RearAxle, Spring, Tyre, Vec3, VehicleDefinition)
from elastokin.vehicle.model.plausibility import (MAX_BODY_MASS_KG, MAX_CAMBER_DEG, MAX_COORDINATE_M, MAX_FRICTION_N,
                                        MAX_INERTIA_KGM2, MAX_PART_MASS_KG, MAX_PRELOAD_N, MAX_RACK_TRAVEL_M,
                                        MAX_RADIUS_M, MAX_SCALE, MAX_STIFFNESS_N_PER_M, MAX_TOE_DEG,
                                        MAX_TORSION_NM_PER_RAD, check_geometry)
from elastokin.core.documents import Document, Fields, KeyPath, check_number, check_vector, dotted
from elastokin.core.errors import InputError
from elastokin.core.files import is_file, read_text
from elastokin.core.shipped import DEFAULT_VEHICLE, PARAMETER_SET_DIR, TYRE_DIR, VEHICLE_DIR, resolve

#: Source named in the errors of :func:`with_extensions`.
EXTENSIONS_SOURCE = "with_extensions"
_TOP = ("name", "description", "tyre", "body", "front", "rear", "bushing_families", "bushings")


def load_vehicle(path: str | Path = DEFAULT_VEHICLE) -> VehicleDefinition:
    """Load and validate a vehicle file, or a built-in vehicle by name (``c_segment``); raises
    :class:`InputError` naming file:line, key and value."""
    path = resolve(path, VEHICLE_DIR, "vehicle")
    return parse_vehicle(Document.read(path, "no such vehicle file").text, path)


def as_filed(vehicle: VehicleDefinition) -> bool:
    """Whether ``vehicle`` is its file as it stands (not changed in code since it was read)."""
    return bool(vehicle.text) and is_file(vehicle.path) and read_text(vehicle.path) == vehicle.text


def parse_vehicle(text: str, path: Path, source: str | None = None) -> VehicleDefinition:
    """Validate the text of a vehicle file; ``path`` is where it stands (the tyre file's folder),
    ``source`` what errors name (default: ``path``; another source's errors name no line, the text
    being made rather than the user's). The definition keeps the text."""
    doc = Document(text, source or str(path))
    if source is not None:
        doc.lines.clear()
    top = doc.top(_TOP)
    t = top.fields("tyre", ("radius", "wheel_mass", "wheel_inertia", "property_file"))
    tyre = Tyre(t.number("radius", positive=True, at_most=MAX_RADIUS_M, unit="m"),
                t.number("wheel_mass", positive=True, at_most=MAX_PART_MASS_KG, unit="kg"),
                _inertias(t, "wheel_inertia", 2), _tyre_file(t, path.parent))
    b = top.fields("body", ("mass", "cg", "inertia", "ride_height_point", "design_ride_height"))
    body = Body(b.number("mass", positive=True, at_most=MAX_BODY_MASS_KG, unit="kg"), _point(b, "cg"),
                _inertias(b, "inertia", 3), _point(b, "ride_height_point"),
                b.number("design_ride_height", positive=True, at_most=MAX_COORDINATE_M, unit="m"))

    f = top.fields("front", ("hardpoints", "static_toe", "static_camber", "masses", "spring", "damper",
                             "anti_roll_bar", "steering", "strut_friction"))
    front = FrontAxle(
        hardpoints=_points(f.fields("hardpoints", FRONT_POINTS), FRONT_POINTS),
        static_toe=_angle(f, "static_toe", MAX_TOE_DEG), static_camber=_angle(f, "static_camber", MAX_CAMBER_DEG),
        masses=_masses(f.fields("masses", FRONT_MASSES), FRONT_MASSES),
        spring=_spring(f.fields("spring", ("rate", "curve", "preload"))),
        damper=Damper(_curve(f.fields("damper", ("curve",)), "curve")),
        anti_roll_rate=f.fields("anti_roll_bar", ("rate",)).number("rate", nonneg=True, at_most=MAX_STIFFNESS_N_PER_M,
                                                                    unit="N/m"),
        rack_travel_per_rev=f.fields("steering", ("rack_travel_per_rev",)).number(
            "rack_travel_per_rev", positive=True, at_most=MAX_RACK_TRAVEL_M, unit="m"),
        strut_friction=_per_side(f, "strut_friction", 0.0))
    rr = top.fields("rear", ("hardpoints", "static_toe", "static_camber", "masses", "beam_torsional_stiffness",
                             "beam_torsion_scale", "beam_bending_stiffness", "spring", "damper"))
    rear = RearAxle(
        hardpoints=_points(rr.fields("hardpoints", REAR_POINTS), REAR_POINTS),
        static_toe=_angle(rr, "static_toe", MAX_TOE_DEG), static_camber=_angle(rr, "static_camber", MAX_CAMBER_DEG),
        masses=_masses(rr.fields("masses", REAR_MASSES), REAR_MASSES),
        beam_torsional_stiffness=rr.number("beam_torsional_stiffness", positive=True, at_most=MAX_TORSION_NM_PER_RAD,
                                           unit="N·m/rad"),
        spring=_spring(rr.fields("spring", ("rate", "curve", "preload"))),
        damper=Damper(_curve(rr.fields("damper", ("curve",)), "curve")),
        beam_torsion_scale=rr.number("beam_torsion_scale", 1.0, positive=True, at_most=MAX_SCALE),
        beam_bending_stiffness=rr.number("beam_bending_stiffness", positive=True, at_most=MAX_TORSION_NM_PER_RAD,
                                         unit="N·m/rad") if rr.has("beam_bending_stiffness") else None)

    points = {f"front.{k}": np.array(v) for k, v in front.hardpoints.items()}
    points |= {f"rear.{k}": np.array(v) for k, v in rear.hardpoints.items()}
    raw = top.raw("bushings")
    if not isinstance(raw, list) or not raw:
        raise top.fail("bushings", f"expected a non-empty list of bushings, got {raw!r}")
    families = _families(top)
    bushings = tuple(_bushing(doc, top.path("bushings") + (i,), v, points, families) for i, v in enumerate(raw))
    names = [bu.name for bu in bushings]
    if len(set(names)) != len(names):
        raise top.fail("bushings", f"duplicate bushing names in {names}")
    for part in BUSHING_PARTS:
        if not any(bu.child == part for bu in bushings):
            raise top.fail("bushings", f"no bushing connects {part} to the body")
    name = top.raw("name")
    if not isinstance(name, str):
        raise top.fail("name", f"expected a name, got {name!r}")
    vehicle = VehicleDefinition(name, top.text("description", ""), path, tyre, body, front, rear, bushings, text)
    check_geometry(vehicle, doc)
    return vehicle


def with_extensions(v: VehicleDefinition, *, strut_friction: float | Mapping[str, float] | None = None,
                    beam_torsion_scale: float | None = None,
                    effects: Mapping[str, Mapping[str, float]] | None = None,
                    coupling: Mapping[str, Sequence[Mapping[str, Any]]] | None = None,
                    laws: Mapping[str, ParameterSet] | None = None) -> VehicleDefinition:
    """``v`` with the catalogue's extensions set, without writing a file (None keeps one as it is).

    ``strut_friction`` [N] and ``beam_torsion_scale`` as the keys ``front.strut_friction`` (a number
    for both struts or ``{left: a, right: b}``) and ``rear.beam_torsion_scale``; ``effects`` maps
    ``"bushing.direction"`` to effect keys in parameter-set units (``{"e1_rear.z": {"mullins": 0.2}}``),
    laid over the direction's own; ``coupling`` maps a bushing name to its new ``coupling`` list
    (``{"e1_rear": [{"directions": ["x", "z"], "stiffness": 50.0}]}``, N/mm or N·m/deg), which
    replaces the old one; ``laws`` maps ``"bushing.direction"`` to a
    :class:`elastokin.bushings.parameter_sets.ParameterSet` that replaces the direction's law, its effects
    included (a catalogue cause applied to the direction's own set). Values are checked as in a
    vehicle file; errors name ``with_extensions``.
    """
    given = {"strut_friction": strut_friction, "beam_torsion_scale": beam_torsion_scale, "effects": effects or {},
             "coupling": coupling or {}, "laws": laws or {}}
    doc = Document.of_data(given, EXTENSIONS_SOURCE)
    ext = doc.top(tuple(given))
    front, rear = v.front, v.rear
    if strut_friction is not None:
        front = replace(front, strut_friction=_per_side(ext, "strut_friction"))
    if beam_torsion_scale is not None:
        rear = replace(rear, beam_torsion_scale=ext.number("beam_torsion_scale", positive=True, at_most=MAX_SCALE))
    bushings = {b.name: b for b in v.bushings}

    def bushing(name: str, path: KeyPath) -> BushingDef:
        if name not in bushings:
            raise doc.error(path, f"unknown bushing {name!r}; expected one of {', '.join(bushings)}")
        return bushings[name]

    def set_direction(path: KeyPath, change: Callable[[DirectionDef], DirectionDef]) -> None:
        name, _, direction = str(path[-1]).partition(".")
        b = bushing(name, path)
        if direction not in DIRECTIONS:
            raise doc.error(path, f"expected 'bushing.direction' with a direction of {', '.join(DIRECTIONS)}, got "
                                  f"{path[-1]!r}")
        d = _checked(change(b.directions[direction]), doc, path)
        bushings[name] = replace(b, directions={**b.directions, direction: d})

    for target, pset in given["laws"].items():
        path = ("laws", target)

        def law(d: DirectionDef) -> DirectionDef:
            if pset.quantity != d.quantity:
                raise doc.error(path, f"parameter set {pset.name!r} is a {pset.quantity} set; {target} needs a "
                                      f"{d.quantity} set")
            return replace(d, set_name=None, model=pset.model, params=dict(pset.values),
                           source=f"{EXTENSIONS_SOURCE}: {dotted(path)}", effects=dict(pset.effects))
        set_direction(path, law)
    for target, values in given["effects"].items():
        path = ("effects", target)
        set_direction(path, lambda d: replace(d, effects={**d.effects, **_mapping(doc, path, values)}))
    for name, terms in given["coupling"].items():
        b = bushing(name, ("coupling", name))
        bushings[name] = replace(b, coupling=_coupling(ext.fields("coupling", tuple(given["coupling"])), name,
                                                       b.directions))
    return replace(v, front=front, rear=rear, bushings=tuple(bushings.values()), text="")


# -- the readers of the parts of a file --------------------------------------------------------------
def _curve(f: Fields, key: str) -> Curve:
    value = f.raw(key)
    if not isinstance(value, (list, tuple)) or len(value) < 2:
        raise f.fail(key, f"expected a list of at least two [x, F] points, got {value!r}")
    pts = [check_vector(f.doc, f.path(key) + (i,), p, 2) for i, p in enumerate(value)]
    xs = [p[0] for p in pts]
    if any(b <= a for a, b in zip(xs, xs[1:])):
        raise f.fail(key, f"expected strictly increasing x values, got {xs}")
    return Curve(tuple(xs), tuple(p[1] for p in pts))


def _spring(f: Fields) -> Spring:
    if f.has("rate") == f.has("curve"):
        raise f.doc.error(f.where, "give exactly one of `rate` [N/m] or `curve` [[compression m, force N], ...]")
    if f.has("rate"):
        k = f.number("rate", positive=True, at_most=MAX_STIFFNESS_N_PER_M, unit="N/m")
        curve = Curve((-1.0, 1.0), (-k, k))
    else:
        curve = _curve(f, "curve")
    if f.raw("preload", "auto") == "auto":
        return Spring(curve, None)
    return Spring(curve, f.number("preload", nonneg=True, at_most=MAX_PRELOAD_N, unit="N"))


def _point(f: Fields, key: str) -> Vec3:
    """A point [m] of the car, within :data:`MAX_COORDINATE_M` of its origin (a value in mm is refused)."""
    return f.vector(key, at_most=MAX_COORDINATE_M, unit="m")


def _angle(f: Fields, key: str, at_most_deg: float) -> float:
    """An alignment angle written in degrees, in radians."""
    return math.radians(f.number(key, at_most=at_most_deg, unit="deg"))


def _tyre_file(t: Fields, base: Path) -> Path | None:
    """The tyre's property file: a path from the vehicle file's folder, or a shipped tyre's name."""
    if not t.has("property_file"):
        return None
    try:
        return resolve(t.text("property_file"), TYRE_DIR, "tyre property", base=base, suffix=".tir")
    except InputError as error:
        raise t.fail("property_file", f"{error.source}: {error.bare}") from None


def _inertias(f: Fields, key: str, n: int) -> tuple[float, ...]:
    inertia = f.vector(key, n, at_most=MAX_INERTIA_KGM2, unit="kg·m²")
    if min(inertia) <= 0:
        raise f.fail(key, f"expected positive inertias, got {list(inertia)}")
    return inertia


def _points(f: Fields, names: tuple[str, ...]) -> dict[str, Vec3]:
    points = {name: _point(f, name) for name in names}
    for name, p in points.items():
        if p[1] <= 0 and name != "beam_centre":
            raise f.fail(name, f"expected a left-side point (y > 0), got {list(p)}")
    return points


def _masses(f: Fields, names: tuple[str, ...]) -> dict[str, float]:
    return {name: f.number(name, positive=True, at_most=MAX_PART_MASS_KG, unit="kg") for name in names}


def _per_side(f: Fields, key: str, default: Any = ...) -> tuple[float, float]:
    """A non-negative value for both sides, or ``{left: a, right: b}``: (left, right)."""
    if isinstance(f.raw(key, default), Mapping):
        sides = f.fields(key, ("left", "right"))
        return tuple(sides.number(side, nonneg=True, at_most=MAX_FRICTION_N, unit="N") for side in ("left", "right"))
    v = check_number(f.doc, f.path(key), f.raw(key, default), nonneg=True, at_most=MAX_FRICTION_N, unit="N")
    return v, v


def _mapping(doc: Document, path: KeyPath, value: Any) -> dict[str, Any]:
    if not isinstance(value, Mapping):
        raise doc.error(path, f"expected a mapping, got {value!r}")
    return dict(value)


def _checked(d: DirectionDef, doc: Document, path: KeyPath) -> DirectionDef:
    """``d`` after building its law and effects once, so that errors name this file and key."""
    try:
        d.channel()
        d.effects_si()
    except InputError as exc:
        if exc.source and exc.source.startswith(doc.source):
            raise
        raise doc.error(path, str(exc)) from exc
    return d


def _bus_file(f: Fields, key: str) -> BusFile:
    """The Adams bushing property file named at ``f``'s ``key``: a path from the vehicle file's
    folder, or a shipped one of models/bushings/ by name; errors name both files."""
    try:
        return read_bus(resolve(f.text(key), PARAMETER_SET_DIR, "bushing property", base=Path(f.doc.source).parent,
                                suffix=".bus"))
    except InputError as error:
        raise f.fail(key, str(error)) from None


def _from_bus(f: Fields, key: str, d: str, quantity: str, families: Families,
              effects: Mapping[str, Any] | None = None) -> DirectionDef:
    """Direction ``d``'s law from the property file at ``f``'s ``key``: its curve and damping."""
    bus = _bus_file(f, key)
    try:
        pset = bus.parameter_set(d)
    except InputError as error:
        raise f.fail(key, str(error)) from None
    source = f"{f.doc.where(f.path(key))}: {dotted(f.path(key))} ({pset.source})"
    return _checked(DirectionDef(quantity, None, "curve", dict(pset.values), source, families, dict(effects or {})),
                    f.doc, f.path(key))


def _direction(f: Fields, d: str, quantity: str, families: Families) -> DirectionDef:
    r = f.fields(d, ("set", "model", "params", "effects", "property_file"))
    path = f.path(d)
    if r.has("property_file"):
        if r.has("set") or r.has("params") or r.has("model"):
            raise f.doc.error(path, "give one of `set`, `model` with `params`, or `property_file` (a .bus file)")
        return _from_bus(r, "property_file", d, quantity, families, _mapping(f.doc, r.path("effects"),
                                                                             r.raw("effects", {})))
    if r.has("set") == r.has("params"):
        raise f.doc.error(path, "give either `set` (a parameter set of models/bushings/), `model` with `params`, or "
                                "`property_file` (an Adams .bus file)")
    model = r.raw("model", None)
    if model is not None and not isinstance(model, str):
        raise r.fail("model", f"expected a model name, got {model!r}")
    effects = _mapping(f.doc, r.path("effects"), r.raw("effects", {}))
    source = f"{f.doc.where(path)}: {dotted(path)}"
    if r.has("set"):
        name = r.raw("set")
        if not isinstance(name, str):
            raise r.fail("set", f"expected a parameter-set name, got {name!r}")
        direction = DirectionDef(quantity, name, model, None, source, families, effects)
    else:
        if model is None:
            raise r.fail("model", "missing key (inline parameters need a model)")
        if not isinstance(r.raw("params"), Mapping):
            raise r.fail("params", f"expected a mapping of parameters, got {r.raw('params')!r}")
        direction = DirectionDef(quantity, None, model, dict(r.raw("params")), source, families, effects)
    return _checked(direction, f.doc, path)


def _coupling(f: Fields, key: str, directions: Mapping[str, DirectionDef]) -> tuple[CrossStiffness, ...]:
    """A bushing's ``coupling`` list: ``[{directions: [a, b], stiffness: k}]``, k in N/mm between two
    translations or N·m/deg between two rotations (mixed pairs are refused: no common unit)."""
    value = f.raw(key, [])
    if not isinstance(value, (list, tuple)):
        raise f.fail(key, f"expected a list of {{directions: [a, b], stiffness: k}}, got {value!r}")
    terms: list[CrossStiffness] = []
    for i, item in enumerate(value):
        r = Fields.of(f.doc, f.path(key) + (i,), item, ("directions", "stiffness"))
        pair = r.raw("directions")
        if (not isinstance(pair, (list, tuple)) or len(pair) != 2 or any(p not in DIRECTIONS for p in pair)
                or pair[0] == pair[1] or any({pair[0], pair[1]} == set(t.directions) for t in terms)):
            raise r.fail("directions", f"expected two different directions of {', '.join(DIRECTIONS)}, not coupled "
                                       f"already, got {pair!r}")
        a, b = directions[pair[0]], directions[pair[1]]
        if a.quantity != b.quantity:
            raise r.fail("directions", f"cannot couple a translation with a rotation ({pair[0]}, {pair[1]}): their "
                                       f"stiffness has no common unit")
        unit = LENGTH_UNIT_SI[a.quantity]
        k = r.number("stiffness") / unit
        # the coupled tangent [[K0_a, k], [k, K0_b]] must stay positive definite at large amplitude
        bound = math.sqrt(a.channel().K0 * b.channel().K0)
        if not abs(k) < bound:
            force, length = UNIT_LABELS[a.quantity]
            raise r.fail("stiffness", f"expected |stiffness| < sqrt(K0_{pair[0]}·K0_{pair[1]}) = {bound * unit:.6g} "
                                      f"{force}/{length} (the coupled law must stay positive definite), got {k * unit!r}")
        terms.append(CrossStiffness((pair[0], pair[1]), k))
    return tuple(terms)


def _axis(f: Fields, key: str, points: Mapping[str, np.ndarray]) -> np.ndarray:
    value = f.raw(key)
    if isinstance(value, Mapping):
        r = f.fields(key, ("from", "to"))
        ends = []
        for end in ("from", "to"):
            ref = r.raw(end)
            if not isinstance(ref, str) or ref not in points:
                raise r.fail(end, f"unknown hardpoint {ref!r}; expected one of {', '.join(sorted(points))}")
            ends.append(points[ref])
        v = ends[1] - ends[0]
    else:
        v = np.array(check_vector(f.doc, f.path(key), value, 3))
    if np.linalg.norm(v) < 1e-9:
        raise f.fail(key, f"expected a non-zero direction, got {value!r}")
    return v / np.linalg.norm(v)


def _bushing(doc: Document, path: KeyPath, value: Any, points: Mapping[str, np.ndarray],
             families: Families) -> BushingDef:
    r = Fields.of(doc, path, value, ("name", "parent", "child", "location", "axes", "directions", "coupling",
                                     "property_file"))
    name = r.raw("name")
    if not isinstance(name, str) or not name.isidentifier():
        raise r.fail("name", f"expected an identifier, got {name!r}")
    if r.raw("parent") != "body":
        raise r.fail("parent", f"expected 'body', got {r.raw('parent')!r}")
    child = r.raw("child")
    if child not in BUSHING_PARTS:
        raise r.fail("child", f"expected one of {', '.join(BUSHING_PARTS)}, got {child!r}")
    loc = r.raw("location")
    if isinstance(loc, str):
        if loc not in points:
            raise r.fail("location", f"unknown hardpoint {loc!r}; expected one of {', '.join(sorted(points))}")
        location = tuple(float(v) for v in points[loc])
    else:
        location = _point(r, "location")
    ax = r.fields("axes", ("x", "y"))
    x = _axis(ax, "x", points)
    y = _axis(ax, "y", points)
    y = y - x * float(x @ y)
    if np.linalg.norm(y) < 1e-6:
        raise ax.fail("y", "axes.y is parallel to axes.x")
    y /= np.linalg.norm(y)
    z = np.cross(x, y)
    dr = r.fields("directions", DIRECTIONS) if r.has("directions") or not r.has("property_file") else None
    directions = {}
    for d in DIRECTIONS:
        quantity = "translation" if len(d) == 1 else "rotation"
        if r.has("property_file") and (dr is None or not dr.has(d)):   # the file gives what directions do not
            directions[d] = _from_bus(r, "property_file", d, quantity, families)
        else:
            directions[d] = _direction(dr, d, quantity, families)
    coupling = _coupling(r, "coupling", directions)
    return BushingDef(name, "body", child, location,
                      (tuple(x.tolist()), tuple(y.tolist()), tuple(z.tolist())), directions, coupling)


def _families(top: Fields) -> Families:
    if not top.has("bushing_families"):
        return NO_FAMILIES
    r = top.fields("bushing_families", ("sets", "rotation_lever_arm"))
    sets = r.raw("sets")
    if not isinstance(sets, Mapping) or any(m not in MODELS or not isinstance(n, str) for m, n in sets.items()):
        raise r.fail("sets", f"expected a mapping of model ({', '.join(MODELS)}) to parameter-set name, got {sets!r}")
    for m, n in sets.items():
        try:
            load_parameter_set(n).channel(m)
        except InputError as exc:
            raise r.doc.error(r.path("sets") + (m,), str(exc)) from exc
    return Families(dict(sets), r.number("rotation_lever_arm", positive=True, at_most=MAX_RADIUS_M, unit="m"))
