"""Keys every scenario file has, rig or road (format: scenarios/README.md): its name, its vehicle,
its output rate and its divergence limits, read and checked one way for both."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Iterator

from elastokin.vehicle.scenarios.scenario import MAX_OUTPUT_RATE_HZ, NAME_PATTERN, Limits
from elastokin.core.documents import Fields
from elastokin.core.errors import InputError
from elastokin.core.shipped import DEFAULT_VEHICLE, VEHICLE_DIR, resolve
from elastokin.core.units import MM, MM_PER_M

#: Keys of a ``limits`` mapping that every scenario accepts.
LIMIT_KEYS = ("translation_mm", "rotation_deg", "closure_error_mm")


def vehicle_file(top: Fields, path: Path) -> Path:
    """The scenario's ``vehicle`` (a path from the scenario's folder or a built-in name; default the
    built-in default car)."""
    try:
        return resolve(top.text("vehicle", str(DEFAULT_VEHICLE)), VEHICLE_DIR, "vehicle", base=path.parent)
    except InputError as error:
        raise top.fail("vehicle", f"{error.source}: {error.bare}") from None


def scenario_name(top: Fields, path: Path) -> str:
    """The scenario's ``name`` (default: the file's stem), plain, for it names out/<name>.mcap."""
    name = top.text("name", path.stem)
    if not NAME_PATTERN.fullmatch(name):
        raise top.fail("name", f"expected a plain name (letters, digits, '_', '.', '-'; the run file is "
                               f"out/<name>.mcap), got {name!r}")
    return name


def output_rate(top: Fields) -> float:
    """``output_rate_hz`` [Hz] (default 100), at most MAX_OUTPUT_RATE_HZ (the run's time step divides
    its interval)."""
    return top.number("output_rate_hz", 100.0, positive=True, at_most=MAX_OUTPUT_RATE_HZ, unit="Hz")


def limit_values(lim: Fields) -> dict[str, float]:
    """The suspension's divergence limits of a ``limits`` mapping, SI, as :class:`Limits` fields."""
    return {"translation_m": lim.number("translation_mm", Limits.translation_m * MM_PER_M, positive=True) * MM,
            "rotation_rad": math.radians(lim.number("rotation_deg", math.degrees(Limits.rotation_rad), positive=True)),
            "closure_error_m": lim.number("closure_error_mm", Limits.closure_error_m * MM_PER_M, positive=True) * MM}


def case_fields(top: Fields, allowed: tuple[str, ...]) -> Iterator[tuple[int, Fields]]:
    """Each item of ``cases`` (a non-empty list) merged over ``defaults``, both checked against the
    ``allowed`` keys, with its index."""
    doc = top.doc
    defaults = Fields.of(doc, ("defaults",), top.raw("defaults", {}), allowed)
    raw = top.raw("cases")
    if not isinstance(raw, list) or not raw:
        raise top.fail("cases", f"expected a non-empty list of cases, got {raw!r}")
    for i, item in enumerate(raw):
        own = Fields.of(doc, ("cases", i), item, allowed)
        yield i, Fields(doc, {**defaults.values, **own.values}, ("cases", i))
