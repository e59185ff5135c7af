"""The one table of units: every unit a file, a recording or the command line may use, its
dimension and its size, and the conversions between units of one dimension.

Sizes are kept relative to the recordings' units (mm, deg, N, N·m, s), so that the common factors
come out exact: 1000 mm per m, 57.29577951308232 deg per rad (``math.degrees(1)``), 1e-3 m per mm.
"""

from __future__ import annotations

import math

#: unit -> (dimension, size in the dimension's recording unit)
_SIZES: dict[str, tuple[str, float]] = {
    "deg": ("angle", 1.0), "rad": ("angle", 180.0 / math.pi), "arcmin": ("angle", 1.0 / 60.0),
    "mm": ("length", 1.0), "cm": ("length", 10.0), "m": ("length", 1e3),
    "N": ("force", 1.0), "daN": ("force", 10.0), "kN": ("force", 1e3),
    **{f"{prefix}N{dot}m": ("torque", size) for prefix, size in (("", 1.0), ("da", 10.0), ("k", 1e3))
       for dot in ("·", ".", "")},
    "s": ("time", 1.0), "ms": ("time", 1e-3),
    "km/h": ("speed", 1.0), "m/s": ("speed", 3.6),
    "deg/s": ("angular_rate", 1.0), "rad/s": ("angular_rate", 180.0 / math.pi),
    "m/s²": ("acceleration", 1.0), "m/s2": ("acceleration", 1.0), "g": ("acceleration", 9.80665),
}
#: The largest magnitude a measured or commanded value may take, per dimension, in SI: far beyond a
#: car on a K&C rig or a part on a bushing bench, far below what a unit or typing error gives.
_PLAUSIBLE_SI = {"length": 10.0, "angle": 2.0 * math.pi, "force": 1e7, "torque": 1e6, "time": 1e6, "speed": 100.0,
                "angular_rate": 20.0, "acceleration": 100.0}
#: The SI unit of each dimension.
SI_UNIT = {"length": "m", "angle": "rad", "force": "N", "torque": "N·m", "time": "s", "speed": "m/s",
           "angular_rate": "rad/s", "acceleration": "m/s²"}
#: Every unit known, in the table's order.
UNITS = tuple(_SIZES)


def dimension(unit: str) -> str:
    """``length``, ``angle``, ``force``, ``torque``, ``time``, ``speed``, ``angular_rate`` or
    ``acceleration``; KeyError for an unknown unit."""
    return _SIZES[unit][0]


def factor(from_unit: str, to_unit: str) -> float:
    """``to_unit`` per ``from_unit`` (a value in ``from_unit`` times this is in ``to_unit``);
    ValueError across dimensions."""
    (a, size_a), (b, size_b) = _SIZES[from_unit], _SIZES[to_unit]
    if a != b:
        raise ValueError(f"{from_unit} ({a}) does not convert to {to_unit} ({b})")
    return size_a / size_b


def si(unit: str) -> float:
    """SI per ``unit``: 1e-3 for mm, π/180 for deg."""
    return factor(unit, SI_UNIT[dimension(unit)])


def per_si(unit: str) -> float:
    """``unit`` per SI: 1000 for mm, 180/π for deg."""
    return factor(SI_UNIT[dimension(unit)], unit)


def in_si(unit: str) -> tuple[str, float]:
    """(the SI unit, SI per ``unit``) of a recorded signal's unit: ``("rad", π/180)`` for ``deg``,
    ``("rad/s", π/180)`` for ``deg/s``, ``("m/s", 1/3.6)`` for ``km/h``; a unit of no dimension
    here (``1/s``, ``-``) or already SI is kept, factor 1."""
    if unit in _SIZES:
        return SI_UNIT[dimension(unit)], si(unit)
    top, slash, below = unit.partition("/")
    if top not in _SIZES:
        return unit, 1.0
    return SI_UNIT[dimension(top)] + slash + below, si(top)


def plausible(unit: str) -> float:
    """The largest magnitude plausible for a value in ``unit`` (10 m, 360°, 10 MN, 1 MN·m, 1e6 s)."""
    return _PLAUSIBLE_SI[dimension(unit)] * per_si(unit)


#: Metres per millimetre and radians per degree (the thesis's units at the boundary), and their inverses.
MM, DEG = si("mm"), si("deg")
MM_PER_M, DEG_PER_RAD = per_si("mm"), per_si("deg")
