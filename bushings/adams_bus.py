"""Adams/Car bushing property files (``.bus``): read into one tabulated law per direction, and written.

A ``.bus`` file is a TeimOrbit file (:mod:`elastokin.core.teim_orbit`): ``[MDI_HEADER]`` (``FILE_TYPE =
'bus'``), ``[UNITS]`` (``LENGTH``, ``FORCE``, ``ANGLE``, ``MASS``, ``TIME`` in any of Adams's unit
names, :data:`ADAMS_UNITS`), ``[SHAPE]`` (the graphic's radius and width, read through), ``[DAMPING]``
(one viscous coefficient per direction) and ``[FX_CURVE]`` ... ``[TZ_CURVE]`` (force against
deflection along the bushing's x, y, z axes, torque against rotation about them), each a table of
two columns with or without its ``{disp force}`` line.

Read, each direction becomes a ``curve`` law (:func:`elastokin.bushings.parameters.curve_nodes`: the
monotone cubic through the points, straight on beyond them) with its damping as a linear dashpot,
in the parameter sets' units (N, mm, s; N·m, deg, s), converted once here. The damping keys are
``FX_DAMPING`` ... ``TZ_DAMPING`` (as this module writes them); ``TDX``/``RDX``-style keys
(``TDX, TDY, TDZ, RDX, RDY, RDZ``) are read as the same. Directions map one to one: FX, FY, FZ →
x, y, z; TX, TY, TZ → rx, ry, rz, about the bushing's own axes as a vehicle file sets them.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

from elastokin.bushings.parameter_sets import ParameterSet
from elastokin.bushings.parameters import curve_nodes
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output
from elastokin.core.teim_orbit import TeimOrbitFile, read_teim_orbit

#: The file's curve sections and the bushing directions they give.
CURVES = {"FX": "x", "FY": "y", "FZ": "z", "TX": "rx", "TY": "ry", "TZ": "rz"}
#: [DAMPING] keys, each direction's two spellings.
DAMPING_KEYS = {**{f"{c}_DAMPING": d for c, d in CURVES.items()},
                **{f"{'T' if len(d) == 1 else 'R'}D{d[-1].upper()}": d for d in CURVES.values()}}
#: Adams's unit names (lower case) and their size in SI, per [UNITS] key.
ADAMS_UNITS: dict[str, dict[str, float]] = {
    "LENGTH": {"mm": 1e-3, "millimeter": 1e-3, "millimeters": 1e-3, "cm": 1e-2, "centimeter": 1e-2, "meter": 1.0,
               "meters": 1.0, "m": 1.0, "km": 1e3, "kilometer": 1e3, "inch": 0.0254, "in": 0.0254, "foot": 0.3048,
               "ft": 0.3048, "mile": 1609.344},
    "FORCE": {"newton": 1.0, "n": 1.0, "kilonewton": 1e3, "kn": 1e3, "millinewton": 1e-3, "dyne": 1e-5,
              "pound_force": 4.4482216152605, "lbf": 4.4482216152605, "kilogram_force": 9.80665, "kgf": 9.80665,
              "ounce_force": 0.27801385095378125},
    "ANGLE": {"degrees": math.pi / 180.0, "degree": math.pi / 180.0, "deg": math.pi / 180.0, "radians": 1.0,
              "radian": 1.0, "rad": 1.0},
    "MASS": {"kg": 1.0, "kilogram": 1.0, "gram": 1e-3, "g": 1e-3, "tonne": 1e3, "megagram": 1e3,
             "pound_mass": 0.45359237, "lbm": 0.45359237, "slug": 14.593902937206364, "ounce_mass": 0.028349523125},
    "TIME": {"second": 1.0, "sec": 1.0, "s": 1.0, "millisecond": 1e-3, "ms": 1e-3, "minute": 60.0, "min": 60.0,
             "hour": 3600.0},
}
#: The sections a file may have (others are refused, naming the file's line).
SECTIONS = ("MDI_HEADER", "UNITS", "SHAPE", "DAMPING") + tuple(f"{c}_CURVE" for c in CURVES)
_MM, _DEG = 1e-3, math.pi / 180.0   # the parameter sets' length units, in SI


@dataclass(frozen=True)
class BusDirection:
    """One direction of a bushing property file, in the parameter sets' units."""

    direction: str                             #: x, y, z, rx, ry or rz
    curve: tuple[tuple[float, float], ...]     #: [deflection, force]: [mm, N], or [deg, N·m] for a rotation
    damping: float = 0.0                       #: N·s/mm, or N·m·s/deg

    @property
    def quantity(self) -> str:
        """``translation`` or ``rotation``."""
        return "translation" if len(self.direction) == 1 else "rotation"


@dataclass(frozen=True)
class BusFile:
    """A read ``.bus`` file: its directions (those it has curves for) and its comment strings."""

    path: Path
    directions: dict[str, BusDirection]
    comments: tuple[str, ...] = ()

    def parameter_set(self, direction: str) -> ParameterSet:
        """The ``curve`` parameter set of ``direction``; InputError naming the file if it has none."""
        if direction not in self.directions:
            section = next(c for c, d in CURVES.items() if d == direction)
            raise InputError(f"no [{section}_CURVE] for direction {direction}; the file has "
                             f"{', '.join(self.directions) or 'no curve'}", source=str(self.path))
        d = self.directions[direction]
        values = {"curve": [list(p) for p in d.curve], **({"C": d.damping} if d.damping else {})}
        comment = f": {self.comments[0]}" if self.comments else ""
        return ParameterSet(f"{self.path.stem}_{direction}", "curve", d.quantity, values,
                            f"Adams bushing property file {self.path.name}, [{_section(direction)}] and [DAMPING]"
                            f"{comment}", self.path)


def _section(direction: str) -> str:
    return next(f"{c}_CURVE" for c, d in CURVES.items() if d == direction)


def read_bus(path: str | os.PathLike[str]) -> BusFile:
    """Read the bushing property file ``path``.

    Raises:
        InputError: naming the file, line, section and key: a malformed line, an unknown section or
            [DAMPING] key, FILE_TYPE other than 'bus', a unit Adams does not name, a curve that is
            not two columns of increasing deflections with a force that does not fall, zero at zero,
            a negative damping, or a file with no curve.
    """
    bus = read_teim_orbit(path, "bushing property file", headerless_tables=tuple(f"{c}_CURVE" for c in CURVES))
    for section in bus.values:
        if section not in SECTIONS:
            raise InputError(f"unknown section [{section}]; expected {', '.join(f'[{s}]' for s in SECTIONS)}",
                             source=_section_line(bus, section))
    kind = bus.text("MDI_HEADER", "FILE_TYPE", "bus").lower()
    if kind != "bus":
        raise bus.error("MDI_HEADER", "FILE_TYPE", f"'{kind}'; expected 'bus' (a bushing property file)")
    si = {key: _unit(bus, key) for key in ADAMS_UNITS}
    length, force, angle, time = si["LENGTH"], si["FORCE"], si["ANGLE"], si["TIME"]
    scale = {"translation": (length / _MM, force, force * time / length * _MM),
             "rotation": (angle / _DEG, force * length, force * length * time / angle * _DEG)}
    if "DAMPING" in bus.tables or "DAMPING" in bus.texts:
        raise InputError("a table; expected KEY = value lines (FX_DAMPING = 0.5, ...)",
                         source=_section_line(bus, "DAMPING"), key="[DAMPING]")
    damping: dict[str, float] = {}
    for key in bus.values.get("DAMPING", {}):
        if key not in DAMPING_KEYS:
            raise bus.error("DAMPING", key, f"unknown key; expected {', '.join(DAMPING_KEYS)}")
        c = bus.number("DAMPING", key)
        if c < 0.0:
            raise bus.error("DAMPING", key, f"{c:g}: expected a damping of at least 0 (a negative one creates energy)")
        if DAMPING_KEYS[key] in damping:
            raise bus.error("DAMPING", key, f"direction {DAMPING_KEYS[key]} already has its damping")
        damping[DAMPING_KEYS[key]] = c
    directions = {}
    for name, direction in CURVES.items():
        section = f"{name}_CURVE"
        if section not in bus.values:
            continue
        quantity = "translation" if len(direction) == 1 else "rotation"
        x_scale, f_scale, c_scale = scale[quantity]
        table = bus.tables.get(section)
        if table is None or table.shape[1] != 2:
            width = "no rows" if table is None else f"{table.shape[1]} columns"
            raise InputError(f"expected a table of two columns (deflection, force), got {width}",
                             source=_section_line(bus, section), key=f"[{section}]")
        try:   # the file's own numbers (the checks do not depend on the units), so that errors quote them
            curve_nodes(table.tolist(), 1.0, key="row")
        except InputError as exc:
            raise _at_row(bus, section, exc) from None
        curve = tuple((float(x) * x_scale, float(f) * f_scale) for x, f in table)
        directions[direction] = BusDirection(direction, curve, damping.get(direction, 0.0) * c_scale)
    if not directions:
        raise InputError(f"no curve; expected some of {', '.join(f'[{c}_CURVE]' for c in CURVES)}",
                         source=str(bus.path))
    return BusFile(bus.path, directions, tuple(bus.texts.get("MDI_HEADER", ())))


def _unit(bus: TeimOrbitFile, key: str) -> float:
    name = bus.text("UNITS", key).lower()
    known = ADAMS_UNITS[key]
    if name not in known:
        raise bus.error("UNITS", key, f"unknown unit '{name}'; expected one of {', '.join(known)}")
    return known[name]


def _section_line(bus: TeimOrbitFile, section: str) -> str:
    """``file:line`` of a section's header."""
    return f"{bus.path}:{bus.sections[section]}"


def _at_row(bus: TeimOrbitFile, section: str, exc: InputError) -> InputError:
    """A curve's error (key ``row[i]`` or ``row``) at the row's line of the file."""
    found = re.fullmatch(r"row\[(\d+)\]", exc.key or "")
    if found:
        return bus.row_error(section, int(found[1]), exc.bare)
    return InputError(exc.bare, source=_section_line(bus, section), key=f"[{section}]")


def write_bus(path: str | os.PathLike[str], directions: Mapping[str, BusDirection], comments: Sequence[str],
              notes: Sequence[str] = (), *, overwrite: bool = False) -> Path:
    """Write a bushing property file in mm, N, degrees, kg and seconds (a rotation's torque in N·mm
    and its damping in N·mm·s/deg, as Adams reads them in those units): ``comments`` go to the
    header's ``(COMMENTS)`` strings, ``notes`` to ``$`` comment lines above the curves. Nothing is
    written on error; InputError for an existing ``path`` without ``overwrite``."""
    path = Path(path)
    if path.exists() and not overwrite:
        raise InputError("the output exists; pass --overwrite (overwrite=True) to replace it", source=str(path))
    torque = 1e3   # N·mm per N·m
    lines = [_rule("MDI_HEADER"), "[MDI_HEADER]", " FILE_TYPE     =  'bus'", " FILE_VERSION  =  4.0",
             " FILE_FORMAT   =  'ASCII'", "(COMMENTS)", "{comment_string}",
             *(f"'{c.replace(chr(39), chr(96))}'" for c in comments),
             _rule("UNITS"), "[UNITS]", " LENGTH  =  'mm'", " FORCE   =  'newton'", " ANGLE   =  'degrees'",
             " MASS    =  'kg'", " TIME    =  'second'", *(f"$ {n}" for n in notes), _rule("DAMPING"), "[DAMPING]"]
    ordered = [(c, d) for c, d in CURVES.items() if d in directions]
    for name, d in ordered:
        scale = 1.0 if directions[d].quantity == "translation" else torque
        lines.append(f" {name}_DAMPING  =  {directions[d].damping * scale:.8g}")
    for name, d in ordered:
        scale = 1.0 if directions[d].quantity == "translation" else torque
        lines += [_rule(f"{name}_CURVE"), f"[{name}_CURVE]",
                  "{ disp  force }" if directions[d].quantity == "translation" else "{ angle  torque }"]
        lines += [f" {x:16.8g} {f * scale:16.8g}" for x, f in directions[d].curve]
    with atomic_output(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n")
    return path


def _rule(section: str) -> str:
    """Adams's ``$----...SECTION`` separator line, 80 characters."""
    return "$" + "-" * (79 - len(section)) + section
