"""The catalogue at the K&C level: where each cause can sit in a vehicle, and the vehicle it makes.

A *bushing* cause of :mod:`elastokin.diagnosis.catalogue` sits in one bushing direction (the left
one's, mirrored on the right as the vehicle mirrors every law) and extends that direction's law.
The vehicle adds causes of its own: ``coupling`` (a cross stiffness between two directions of one
bushing), ``strut_friction`` (Coulomb friction of the strut rods), ``beam_torsion`` (a factor on
the twist beam's torsional stiffness), and an axle's ``spring_rate``, ``damper_force`` and (front)
``anti_roll_bar`` off their design values by a factor, and a ``hardpoint`` a few millimetres off
along one coordinate (both sides, as the vehicle file mirrors them): the errors engineers find
first when they correlate a model with a K&C rig. Outside the catalogue, the virtual rig can hide
``backlash`` (a dead band in one bushing direction, as a worn ball joint would give).

``self_heating`` is not a K&C cause: the rig's triangles at 0.1 Hz dissipate a few joules per cycle
in a bushing, which warms it by far less than its resolution; it belongs to the bench, whose
endurance sines heat a part in minutes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Mapping

import numpy as np

from elastokin.bushings.parameter_sets import ParameterSet, load_parameter_set
from elastokin.vehicle.model.definition import BushingDef, Curve, Damper, DirectionDef, VehicleDefinition
from elastokin.vehicle.model.file_overrides import vehicle_with
from elastokin.vehicle.model.vehicle_file import parse_vehicle, with_extensions
from elastokin.core.documents import Document, dump_yaml
from elastokin.core.errors import InputError
from elastokin.core.units import DEG_PER_RAD, MM_PER_M
from elastokin.core.shipped import TYRE_DIR
from elastokin.diagnosis.catalogue import CAUSES, Entry, Parameter, draw_parameters

#: Bushing causes at the K&C level (see the module docstring for self_heating).
BUSHING_CAUSES = tuple(c for c in CAUSES if c != "self_heating")
#: Bushing directions a cause can sit in: the translations, where the thesis puts its laws.
DIRECTIONS = ("x", "y", "z")


@dataclass(frozen=True)
class VehicleCause(Entry):
    """A cause the vehicle holds outside its bushing laws."""

    located: bool            #: sits in one bushing (``coupling``) rather than in the whole axle
    axles: tuple[str, ...] = ()   #: the axles it can sit in, one at a time (none: the place is fixed)


def _scale(name: str, what: str) -> Parameter:
    """A factor on an axle's design value, from a few to 40 per cent off (either way)."""
    return Parameter(name, "-", (0.3, 3.0), (1.05, 1.4), log=True, factor=True,
                     description=f"factor on the design {what} (drawn above or below 1)")


VEHICLE_CAUSES: dict[str, VehicleCause] = {c.id: c for c in (
    VehicleCause("coupling", "a cross stiffness between two directions of one bushing (voids, inclined layers): "
                 "F_a += k·e_b, F_b += k·e_a",
                 "responses in a direction the input does not load in the baseline; mismatch in combined loading",
                 (Parameter("stiffness", "N/mm", (-500.0, 500.0), (40.0, 120.0), signed=True, even_part=True,
                            description="cross stiffness"),), located=True),
    VehicleCause("strut_friction", "Coulomb friction of the piston rod sliding in the strut tube",
                 "pad-force and camber loops wider than the bushings explain, width independent of speed",
                 (Parameter("strut_friction", "N", (0.0, 1000.0), (100.0, 300.0), description="sliding force"),),
                 located=False),
    VehicleCause("beam_torsion", "the twist beam's torsional stiffness differs from the design value",
                 "roll gradient and rear roll steer error without any change of loop width",
                 (Parameter("beam_torsion_scale", "-", (0.2, 5.0), (1.3, 2.0), log=True, factor=True,
                            description="factor on the design torsional stiffness (drawn above or below 1)"),),
                 located=False),
    VehicleCause("spring_rate", "an axle's coil springs are stiffer or softer than designed (wire, coils, supplier)",
                 "pad-force gradients in pumping and roll off on one axle, loops unchanged",
                 (_scale("spring_rate_scale", "spring rate"),), located=True, axles=("front", "rear")),
    VehicleCause("anti_roll_bar", "the front anti-roll bar is stiffer or softer than designed",
                 "roll stiffness and its front/rear split off, pumping unchanged",
                 (_scale("anti_roll_bar_scale", "anti-roll bar rate"),), located=True, axles=("front",)),
    VehicleCause("damper_force", "an axle's dampers give more or less force than their curve (valving, oil)",
                 "loops that widen with the input's speed on one axle",
                 (_scale("damper_scale", "damper curve's forces"),), located=True, axles=("front", "rear")),
    VehicleCause("hardpoint", "a suspension hardpoint of the model off where the car has it (drawing, tolerances "
                 "of the build, the measurement of the car), along one coordinate, both sides alike",
                 "kinematic gradients (bump and roll steer, camber gain) and compliance steer off on one axle, "
                 "loop widths unchanged",
                 (Parameter("offset", "mm", (-25.0, 25.0), (1.0, 4.0), signed=True,
                            description="the hardpoint's displacement along its coordinate (the right side mirrored)"),),
                 located=True, axles=("front", "rear")),
)}
#: Coordinates of a hardpoint, in the order of the vehicle file's [x, y, z] (ISO 8855, metres).
COORDINATES = ("x", "y", "z")
#: The vehicle file's section of each axle factor cause (its `rate` or its `curve`'s forces are multiplied).
AXLE_SCALES = {"spring_rate": "spring", "anti_roll_bar": "anti_roll_bar", "damper_force": "damper"}
#: The model error in excess of the noise (RMS over the K&C campaign of the change of every compared
#: channel, its mean per recording removed, in noise units: what the diagnosis must explain) that
#: makes a cause observable: the baseline's held-out error is then √2 × the noise, well above the
#: 1.11 × below which the diagnosis can name nothing.
MIN_EXCESS = 1.0
#: Where the K&C campaign (scenarios/kc, at the tests' 4× speed) sees each cause on the default car,
#: with the magnitude of its first parameter above which it does (MIN_EXCESS; measured with
#: ``python tools/kc_observability.py --duration-scale 0.25``; a cause screened on both signs by its weaker).
#: The virtual rig's draws take these places, their magnitudes in the observable part of the
#: realistic range; elsewhere a cause is still a hypothesis of the diagnosis. Kept: places whose
#: floor leaves at least the top fifth of the range (in the coordinate its effect grows with: a factor's
#: logarithm). Missing: viscoelasticity_excess (the 0.1 Hz
#: triangles are too slow for the STVS dampers: floor 14.8 N of 5-15; damper_force likewise: floors
#: 1.23 front, 1.17 rear of 1.05-1.4), preload (the car has no direction with a nonlinear elastic
#: law for it to act on), and places such as the asymmetry of the front pivot's y direction (floor
#: 0.26 of 0.05-0.15) where the campaign sees too little.
OBSERVABLE: dict[str, dict[tuple[str, ...], float]] = {
    "viscoelasticity_missing": {("e1_front", "y"): 20.8},
    "asymmetry": {("e1_rear", "x"): 0.043},
    "mullins": {("e1_front", "y"): 0.125, ("e1_rear", "x"): 0.167},
    # a factor, either way: its floor is its magnitude's above 1 (the front pivot's lateral ladder, the
    # rear pivot's linear axial direction and its longitudinal ladder; elsewhere 1.75, E2 front y, or
    # more: beyond the range)
    "stiffness": {("e1_front", "y"): 1.053, ("e1_rear", "x"): 1.055, ("e1_rear", "y"): 1.092},
    "broad_relaxation": {("e1_front", "y"): 50.0},
    "coupling": {("e1_rear", "x", "y"): 27.6, ("e1_rear", "x", "z"): 57.1},   # x/z: 43.6 on its positive sign
    "strut_friction": {(): 27.2},
    "beam_torsion": {(): 1.106},
    "spring_rate": {("front",): 1.048, ("rear",): 1.060},
    "anti_roll_bar": {("front",): 1.096},
    # the heights that set bump steer and camber gain, the tie rod's lever, the strut's inclination
    # (the rear wheel centre's height too, floor 2.17 mm, but that is no hardpoint's: see locations);
    # the rest (the pivots' x and y, spring and damper mounts: floors of 7 to over 100 mm) hardly
    # shows in quasi-static K&C tests
    "hardpoint": {("front", "tie_rod_inner", "z"): 0.416, ("front", "wishbone_front_pivot", "z"): 0.467,
                  ("front", "tie_rod_outer", "z"): 0.470, ("front", "lower_ball_joint", "z"): 0.510,
                  ("front", "tie_rod_outer", "x"): 1.261, ("front", "lower_ball_joint", "x"): 1.277,
                  ("front", "strut_lower", "y"): 1.905, ("front", "strut_top", "y"): 1.944,
                  ("front", "wishbone_rear_pivot", "z"): 2.174, ("rear", "arm_pivot", "z"): 1.763,
                  ("rear", "beam_centre", "z"): 2.495},
    "backlash": {("e1_front", "y"): 0.049, ("e1_rear", "x"): 0.103, ("e1_rear", "y"): 0.057},
}
#: Where the campaign still sees each catalogue cause through a rig's errors (issue 53): what the
#: cause's change leaves once every rig error the diagnosis fits beside the causes has taken what
#: it can of it (a transducer's gain or cross-talk and an input's gain, each within ±2.5 %; the
#: zeros' drifts; the acquisition's lags; the rig's mechanics) reaches MIN_EXCESS from the magnitude
#: given, the larger of that and OBSERVABLE's (measured with ``python tools/kc_observability.py
#: --duration-scale 0.25 --through-rig``, a cause's weakest way; kept as OBSERVABLE's are). The draws
#: of data measured through a rig's chain take these. Missing: below MIN_EXCESS over their whole
#: range, missing viscoelasticity and a broad relaxation (0.65 and 0.77 × the noise left at the top
#: of 1.49 and 1.74: the front pads' lateral load cells' gains take the rest), the tie rod's outer
#: end and the lower ball joint moved in x (0.37 and 0.71 left at 4 mm); above it only in the top
#: fifth of their range, the rear pivot's Mullins softening (from 0.216 of 0.08-0.25), the strut's
#: points in y and the beam's centre in z (from 3.2-3.8 mm of 1-4).
THROUGH_A_RIG: dict[str, dict[tuple[str, ...], float]] = {
    "asymmetry": {("e1_rear", "x"): 0.0763},
    "mullins": {("e1_front", "y"): 0.1795},
    "stiffness": {("e1_front", "y"): 1.102, ("e1_rear", "x"): 1.098, ("e1_rear", "y"): 1.141},
    "coupling": {("e1_rear", "x", "y"): 59.5, ("e1_rear", "x", "z"): 72.6},
    "strut_friction": {(): 27.2},
    "beam_torsion": {(): 1.195},
    "spring_rate": {("front",): 1.109, ("rear",): 1.113},
    "anti_roll_bar": {("front",): 1.185},
    "hardpoint": {("front", "tie_rod_inner", "z"): 0.5045, ("front", "wishbone_front_pivot", "z"): 0.5932,
                  ("front", "tie_rod_outer", "z"): 0.5819, ("front", "lower_ball_joint", "z"): 0.6569,
                  ("front", "wishbone_rear_pivot", "z"): 2.482, ("rear", "arm_pivot", "z"): 2.597},
}
#: Outside the catalogue: a dead band in one bushing direction.
BACKLASH = Parameter("backlash", "mm", (0.0, 2.0), (0.15, 0.3),
                     description="half-width of a dead band in series with the bushing direction")


@dataclass(frozen=True)
class Hypothesis:
    """One cause at one location, with parameter values (``values``; parameter-set units)."""

    cause: str
    location: tuple[str, ...] = ()   #: (bushing, direction), (bushing, dir_a, dir_b) or () for an axle cause
    values: Mapping[str, float] | None = None

    @property
    def label(self) -> str:
        """``cause@bushing.direction`` (``coupling@bushing.a/b``, ``hardpoint@axle.point.coordinate``, or
        the axle cause alone), for people."""
        where = ".".join(self.location) if self.cause == "hardpoint" else \
            {1: "{0}", 2: "{0}.{1}", 3: "{0}.{1}/{2}"}.get(len(self.location), "").format(*self.location)
        return f"{self.cause}@{where}" if where else self.cause

    def location_json(self) -> dict[str, Any] | None:
        """The location as the diagnosis reports it."""
        if self.cause == "hardpoint":
            return dict(zip(("axle", "hardpoint", "coordinate"), self.location))
        if len(self.location) == 2:
            return {"bushing": self.location[0], "direction": self.location[1]}
        if len(self.location) == 3:
            return {"bushing": self.location[0], "directions": list(self.location[1:])}
        if len(self.location) == 1:
            return {"axle": self.location[0]}
        return {"axle": "front"} if self.cause == "strut_friction" else (
            {"axle": "rear"} if self.cause == "beam_torsion" else None)


#: The most parameters of a cause the K&C diagnosis fits (:func:`parameters`).
KC_FITTED_PARAMETERS = 2


def draw(cause: str, rng: np.random.Generator,
         floors: Mapping[str, Mapping[tuple[str, ...], float]] = OBSERVABLE) -> Hypothesis:
    """A random hypothesis of ``cause``: a place where the K&C campaign sees it (``floors``: each
    cause's places and the magnitude of its first parameter above which the campaign sees it there;
    :data:`OBSERVABLE`, or :data:`THROUGH_A_RIG` for data through a rig's errors) and values in the
    realistic range, the first parameter's magnitude mapped into the part of it that the campaign
    resolves at that place (a factor, such as a beam torsion or a bushing's stiffness scale, above
    or below 1: its floor is its magnitude's, above 1).

    Raises:
        KeyError: ``floors`` has no place for ``cause``.
    """
    where = list(floors[cause])
    location = where[int(rng.integers(len(where)))]
    values = draw_parameters(parameters(cause), rng)
    first = parameters(cause)[0]
    lo, hi = (math.log(x) for x in first.draw) if first.log else first.draw
    low = max(floors[cause][location], first.draw[0])
    low = math.log(low) if first.log else low
    v = abs(values[first.name])
    below = first.either_side and v < 1.0   # a factor drawn below 1: mapped by its inverse's magnitude
    v = 1.0 / v if below else v
    v = low + ((math.log(v) if first.log else v) - lo) / (hi - lo) * (hi - low)
    values[first.name] = math.copysign(math.exp(v) if first.log else v, values[first.name])
    if below or (cause in VEHICLE_CAUSES and first.factor and rng.random() < 0.5):   # off either way
        values[first.name] = 1.0 / values[first.name]
    return Hypothesis(cause, location, values)


def drawn_ways(cause: str, magnitude: float) -> tuple[float, ...]:
    """The values of ``cause``'s first parameter of size ``magnitude`` (a factor's above 1) that
    :func:`draw` gives: both signs of a signed one, a factor and its inverse where it is drawn either way."""
    first = parameters(cause)[0]
    if first.factor:
        return (magnitude, 1.0 / magnitude) if first.either_side or cause in VEHICLE_CAUSES else (magnitude,)
    return (magnitude, -magnitude) if first.signed else (magnitude,)


def parameters(cause: str) -> tuple[Parameter, ...]:
    """The fitted parameters of a K&C cause (``backlash`` included, for the virtual rig): of a bushing
    cause, its first two (:mod:`elastokin.diagnosis.kc_fits` fits a magnitude and one shape); a family's
    further shape (the asymmetry's power) stays at its first form, in the hypotheses and the draws."""
    if cause in VEHICLE_CAUSES:
        return VEHICLE_CAUSES[cause].parameters
    if cause in CAUSES:
        return CAUSES[cause].parameters[:KC_FITTED_PARAMETERS]
    if cause == "backlash":
        return (BACKLASH,)
    raise InputError(f"unknown cause {cause!r}; expected one of {', '.join([*BUSHING_CAUSES, *VEHICLE_CAUSES])} "
                     f"(or backlash, outside the catalogue)", key="cause")


def direction_law(vehicle: VehicleDefinition, bushing: str, direction: str) -> ParameterSet:
    """The law of a bushing direction as a parameter set (its set or inline parameters, effects included)."""
    d = _direction(vehicle, bushing, direction)
    if d.set_name is not None:
        base = load_parameter_set(d.set_name)
        return ParameterSet(base.name, d.model or base.model, base.quantity, base.values, base.source,
                            effects={**base.effects, **d.effects})
    return ParameterSet(f"{bushing}.{direction}", d.model or "linear", d.quantity, dict(d.params or {}), d.source,
                        effects=dict(d.effects))


def _direction(vehicle: VehicleDefinition, bushing: str, direction: str) -> DirectionDef:
    return _bushing(vehicle, bushing).directions[direction]


def _bushing(vehicle: VehicleDefinition, name: str) -> BushingDef:
    for b in vehicle.bushings:
        if b.name == name:
            return b
    raise InputError(f"unknown bushing {name!r}; expected one of {', '.join(b.name for b in vehicle.bushings)}",
                     key="location")


def locations(vehicle: VehicleDefinition, cause: str) -> list[tuple[str, ...]]:
    """Every place ``cause`` can sit in ``vehicle``: bushing directions whose law it applies to, pairs
    of translations of one bushing (coupling), an axle (``("front",)``) or a fixed place (``()``)."""
    if cause == "coupling":
        return [(b.name, a, c) for b in vehicle.bushings for i, a in enumerate(DIRECTIONS) for c in DIRECTIONS[i + 1:]]
    if cause == "hardpoint":
        # moved in the vehicle's file: none for a vehicle its text no longer describes (changed in
        # code); a point on the centre plane (the beam's centre) stays on it; the wheel centre's
        # height is the tyre's loaded radius's (the file holds them within 5 mm of each other): an
        # error there is one of ride height or radius, not of a hardpoint
        return [(axle, name, c) for axle in VEHICLE_CAUSES[cause].axles
                for name, point in getattr(vehicle, axle).hardpoints.items()
                for c in COORDINATES if not (c == "y" and point[1] == 0.0) and (name, c) != ("wheel_centre", "z")
                ] if _described(vehicle) else []
    if cause in VEHICLE_CAUSES:
        return [(a,) for a in VEHICLE_CAUSES[cause].axles] or [()]
    applies = CAUSES[cause].applies if cause in CAUSES else (lambda law: True)
    return [(b.name, d) for b in vehicle.bushings for d in DIRECTIONS if applies(direction_law(vehicle, b.name, d))]


def _si_per_file_unit(direction: str) -> float:
    """SI per vehicle-file unit of a cross stiffness: N/m per N/mm, N·m/rad per N·m/deg."""
    return DEG_PER_RAD if direction.startswith("r") else MM_PER_M


def extended_vehicle(vehicle: VehicleDefinition, hypotheses: list[Hypothesis]) -> VehicleDefinition:
    """``vehicle`` with every hypothesis switched on (the truth of the virtual rig, or a fitted model)."""
    vehicle = _moved_hardpoints(vehicle, [h for h in hypotheses if h.cause == "hardpoint"])
    laws: dict[str, ParameterSet] = {}
    coupling: dict[str, list[dict[str, Any]]] = {}
    strut = beam = None
    for h in hypotheses:
        v = dict(h.values or {})
        if h.cause == "strut_friction":
            strut = v["strut_friction"]
        elif h.cause == "beam_torsion":
            beam = v["beam_torsion_scale"]
        elif h.cause in AXLE_SCALES or h.cause == "hardpoint":
            continue   # set on the extended vehicle below
        elif h.cause == "coupling":
            name, a, b = h.location
            terms = coupling.setdefault(name, [{"directions": list(t.directions),
                                                "stiffness": t.stiffness / _si_per_file_unit(t.directions[0])}
                                               for t in _bushing(vehicle, name).coupling])
            terms.append({"directions": [a, b], "stiffness": v["stiffness"]})
        else:
            target = ".".join(h.location)
            law = laws.get(target) or direction_law(vehicle, *h.location)
            if h.cause == "backlash":
                law = ParameterSet(law.name, law.model, law.quantity, law.values, law.source,
                                   effects={**law.effects, "backlash": v["backlash"]})
            else:
                law = CAUSES[h.cause].apply(law, v)
            laws[target] = law
    out = with_extensions(vehicle, strut_friction=strut, beam_torsion_scale=beam, laws=laws, coupling=coupling)
    for h in hypotheses:
        if h.cause in AXLE_SCALES:
            out = _scaled_axle(out, h.cause, h.location[0], float(h.values[parameters(h.cause)[0].name]))
    return out


def _moved_hardpoints(vehicle: VehicleDefinition, moves: list[Hypothesis]) -> VehicleDefinition:
    """``vehicle`` with the hardpoints of ``moves`` (``hardpoint`` hypotheses) moved, as its file edited
    by hand: the bushings that sit on a hardpoint, and their axes through hardpoints, follow it.
    ValueError for a vehicle changed in code since its file was read (its text no longer says it)."""
    if not moves:
        return vehicle
    if not _described(vehicle):
        raise ValueError(f"{vehicle.name}: hardpoints are moved in the vehicle's file, which no longer describes it")
    places: dict[str, float] = {}
    for h in moves:
        axle, name, coordinate = h.location
        at = places.get(f"{axle}.hardpoints.{name}.{coordinate}",
                        getattr(vehicle, axle).hardpoints[name][COORDINATES.index(coordinate)])
        places[f"{axle}.hardpoints.{name}.{coordinate}"] = at + float(h.values["offset"]) / MM_PER_M
    return vehicle_with(vehicle.text, vehicle.path, places, "the diagnosis's hardpoint offsets")


def _described(vehicle: VehicleDefinition) -> bool:
    """Whether the vehicle's file text reads as ``vehicle`` (not so once changed in code, its
    preloads resolved included)."""
    return bool(vehicle.text) and parse_vehicle(vehicle.text, vehicle.path) == vehicle


def _scaled_axle(vehicle: VehicleDefinition, cause: str, axle: str, factor: float) -> VehicleDefinition:
    """``vehicle`` with the value of ``cause`` on ``axle`` multiplied by ``factor`` (:data:`AXLE_SCALES`)."""
    a = getattr(vehicle, axle)
    scaled = lambda c: Curve(tuple(c.x), tuple(y * factor for y in c.y))
    if cause == "spring_rate":
        a = replace(a, spring=replace(a.spring, curve=scaled(a.spring.curve)))
    elif cause == "damper_force":
        a = replace(a, damper=Damper(scaled(a.damper.curve)))
    else:
        a = replace(a, anti_roll_rate=a.anti_roll_rate * factor)
    return replace(vehicle, **{axle: a})



def extended_vehicle_yaml(baseline: VehicleDefinition, hypotheses: list[Hypothesis], note: str) -> str:
    """The baseline's vehicle file with the hypotheses written in (inline laws, ``coupling`` lists,
    ``front.strut_friction``, ``rear.beam_torsion_scale``), headed by ``note``: a file ``vsim run``
    reads. Comments of the baseline file are not kept; its values are."""
    data = Document.read(baseline.path, "no such vehicle file").data
    entries = {b["name"]: b for b in data["bushings"]}
    extended = extended_vehicle(baseline, hypotheses)
    for h in hypotheses:
        v = dict(h.values or {})
        if h.cause == "strut_friction":
            data["front"]["strut_friction"] = v["strut_friction"]
        elif h.cause == "beam_torsion":
            data["rear"]["beam_torsion_scale"] = v["beam_torsion_scale"]
        elif h.cause == "coupling":
            name, a, b = h.location
            entries[name].setdefault("coupling", []).append({"directions": [a, b], "stiffness": v["stiffness"]})
        elif h.cause == "hardpoint":
            axle, name, coordinate = h.location
            data[axle]["hardpoints"][name] = [float(x) for x in getattr(extended, axle).hardpoints[name]]
        elif h.cause in AXLE_SCALES:
            section, factor = data[h.location[0]][AXLE_SCALES[h.cause]], float(v[parameters(h.cause)[0].name])
            if "rate" in section:
                section["rate"] = float(section["rate"]) * factor
            if "curve" in section:
                section["curve"] = [[float(x), float(y) * factor] for x, y in section["curve"]]
        else:
            name, direction = h.location
            law = direction_law(extended, name, direction)
            entries[name]["directions"][direction] = {"model": law.model, "params": _plain(law.values),
                                                      **({"effects": _plain(law.effects)} if law.effects else {})}
    tyre = baseline.tyre.property_file
    if tyre is not None and tyre.resolve().parent != TYRE_DIR.resolve():
        data["tyre"]["property_file"] = str(tyre.resolve())   # the extended file is written elsewhere
    header = "".join(f"# {line}\n" for line in note.splitlines())
    return header + dump_yaml(data, sort_keys=False, allow_unicode=True)


def _plain(values: Mapping[str, Any]) -> dict[str, Any]:
    """Parameter values as YAML scalars and lists of floats."""
    return {k: [float(x) for x in v] if isinstance(v, (list, tuple)) else float(v) for k, v in values.items()}
