"""Values of a vehicle file set by their place in it, as a sweep varies them.

A place is the dotted key of a number in the file (``front.spring.rate``,
``rear.beam_torsional_stiffness``), a coordinate of a point by ``x``, ``y``, ``z`` or its index
(``front.hardpoints.tie_rod_inner.z``), or a bushing direction's parameter through the bushing's
name (``bushings.e2_front.y.Kr``, ``bushings.e1_rear.z.effects.mullins``), in the file's units
(bushing parameters in the thesis's N, mm). A direction that names a parameter set gets that set's
parameters and effects written inline, with the new value among them: the set's file is never
changed, and both sides of the car (one bushing entry) take the value.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any, Mapping

from elastokin.bushings.frequency import lossier
from elastokin.bushings.parameter_sets import load_parameter_set
from elastokin.bushings.parameters import MODELS
from elastokin.vehicle.model.definition import DIRECTIONS, VehicleDefinition
from elastokin.vehicle.model.vehicle_file import parse_vehicle
from elastokin.core.documents import Document, dump_yaml

_AXES = {"x": 0, "y": 1, "z": 2}


class PlaceError(LookupError):
    """A place that is not a number of the vehicle file (the message says why)."""


def _bushing_direction(data: Any, name: str, direction: str) -> dict[str, Any]:
    """The direction mapping of bushing ``name``, its set's parameters written inline."""
    entries = [b for b in data.get("bushings") or [] if isinstance(b, dict) and b.get("name") == name]
    if not entries:
        known = [b.get("name") for b in data.get("bushings") or [] if isinstance(b, dict)]
        raise PlaceError(f"no bushing {name!r}; the file has {', '.join(map(str, known))}")
    directions = entries[0].get("directions")
    if not isinstance(directions, dict) or not isinstance(directions.get(direction), dict):
        raise PlaceError(f"bushing {name!r} has no direction {direction!r}")
    d = directions[direction]
    if "set" in d:
        pset = load_parameter_set(d["set"])
        if d.get("model", pset.model) != pset.model:
            raise PlaceError(f"bushings.{name}.{direction} reads set {d['set']!r} as {d['model']!r}: its parameters "
                             f"are not that model's; write the direction's parameters inline to vary them")
        d = {"model": pset.model, "params": dict(pset.values),
             **({"effects": {**pset.effects, **d.get("effects", {})}} if pset.effects or d.get("effects") else {})}
        directions[direction] = d
    return d


def _container(data: Any, place: str) -> tuple[Any, Any]:
    """(the mapping or list that holds the value at ``place``, its key there) in ``data`` (changed in
    place when a bushing set must be written inline)."""
    parts = place.split(".")
    if len(parts) >= 4 and parts[0] == "bushings" and parts[2] in DIRECTIONS:
        node: Any = _bushing_direction(data, parts[1], parts[2])
        if parts[3] == "effects":
            node.setdefault("effects", {})
            rest = parts[3:]
        else:
            names = MODELS.get(node.get("model"), ((), ()))
            if len(parts) != 4 or parts[3] not in (*names[0], *names[1]):
                raise PlaceError(f"the {node.get('model')} law has no parameter {'.'.join(parts[3:])!r}; its "
                                 f"parameters are {', '.join((*names[0], *names[1]))}")
            rest = ["params", parts[3]]
    else:
        node, rest = data, parts
        if parts[0] == "bushings" and len(parts) > 1:
            entries = [b for b in data.get("bushings") or [] if isinstance(b, dict) and b.get("name") == parts[1]]
            if not entries:
                raise PlaceError(f"no bushing {parts[1]!r}")
            node, rest = entries[0], parts[2:]
    if not rest:
        raise PlaceError("names a bushing, not one of its numbers")
    for i, part in enumerate(rest):
        last = i == len(rest) - 1
        if isinstance(node, list):
            point = len(node) == 3 and all(isinstance(v, (int, float)) for v in node)
            index = _AXES.get(part) if point else None
            index = int(part) if part.isdecimal() and part.isascii() else index
            if index is None or index >= len(node):
                raise PlaceError(f"{'.'.join(rest[:i]) or place} is a list of {len(node)}: expected an index "
                                 f"0..{len(node) - 1}{' or x, y, z' if len(node) == 3 else ''}, got {part!r}")
            key = index
        elif isinstance(node, dict):
            if part not in node and not last:
                raise PlaceError(f"no key {part!r} where it is looked for; the keys there are "
                                 f"{', '.join(map(str, node))}")
            key = part
        else:
            raise PlaceError(f"{'.'.join(rest[:i])} holds {node!r}, not a mapping or a list")
        if last:
            return node, key
        node = node[key]
    raise AssertionError("unreachable: the loop returns at the last part")


def file_value(data: Any, place: str) -> float | None:
    """The number at ``place`` in the vehicle file's ``data`` (None where the file leaves the key to
    its default); :class:`PlaceError` when the place is not a number of the file."""
    node, key = _container(copy.deepcopy(data), place)
    value = node.get(key) if isinstance(node, dict) else node[key]
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise PlaceError(f"holds {value!r}, not a number")
    return float(value)


def with_values(data: Any, values: Mapping[str, float]) -> Any:
    """A copy of the vehicle file's ``data`` with each place of ``values`` set to its number."""
    out = copy.deepcopy(data)
    for place, value in values.items():
        node, key = _container(out, place)
        node[key] = float(value)
    return out


def vehicle_with(text: str, path: Path, values: Mapping[str, float], source: str) -> VehicleDefinition:
    """The vehicle of the file ``text`` (standing at ``path``) with ``values`` set at their places;
    its errors name ``source``. The definition's text is the changed file's."""
    if not values:
        return parse_vehicle(text, path)
    data = with_values(Document(text, str(path)).data, values)
    return parse_vehicle(dump_yaml(data, sort_keys=False), path, source)


def lossier_places(vehicle: VehicleDefinition, direction: str, amplitude_m: float, frequency_hz: float,
                   factor: float = 2.0) -> dict[str, float]:
    """The places and values (the file's units, for :func:`vehicle_with`) that give the bushing
    direction ``direction`` (``"e1_front.y"``) of ``vehicle`` its law with the ladder ``factor``
    times as stiff and the same |K*| at (``amplitude_m``, ``frequency_hz``): a lossier part of the
    same stiffness there (:func:`elastokin.bushings.frequency.lossier`; for a rotation, in rad for m).
    :class:`PlaceError` for a direction without a ladder."""
    bushing, _, axis = direction.partition(".")
    found = [b for b in vehicle.bushings if b.name == bushing and axis in b.directions]
    if not found:
        raise PlaceError(f"no bushing direction {direction!r} in {vehicle.name}")
    d = found[0].directions[axis]
    own = load_parameter_set(d.set_name).values if d.set_name is not None else d.params
    old = d.channel()
    if not old.Kpa or not own.get("K0"):
        raise PlaceError(f"{direction} has no ladder law (K0 and Kpa) to make lossier: {old.model}")
    new = lossier(old, amplitude_m, frequency_hz, factor)
    return {f"bushings.{direction}.Kpa": float(own["Kpa"] * new.Kpa / old.Kpa),
            f"bushings.{direction}.K0": float(own["K0"] * new.K0 / old.K0)}
