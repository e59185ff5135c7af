"""Importing a K&C rig's CSV export (format: ``data/README.md``) as a measured rig recording.

META.yaml says which scenario was played, which CSV column holds the time, and for every imported
column the run channel, the unit and the sign (and optionally an offset) it is written in. Units
and signs are converted once, here, to the run's units and ISO 8855 signs; the recording itself is
written by :func:`elastokin.recordings.rig_recordings.write_rig_recording`.
"""

from __future__ import annotations

import dataclasses
import os
import re
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from elastokin.vehicle.scenarios.channels import CORNER_TAGS
from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.vehicle.scenarios.scenario_file import load_scenario, parse_scenario
from elastokin.core import units
from elastokin.core.documents import Document, Fields, dump_yaml
from elastokin.core.errors import InputError
from elastokin.core.files import is_file, read_text
from elastokin.core.tables import read_csv_columns
from elastokin.recordings.rig_recordings import TIME_NAME, measured_channels, write_rig_recording

_META_KEYS = ("scenario", "duration_scale", "rig", "notes", "time", "columns")
_TIME_KEYS = ("column", "unit", "offset")
_COLUMN_KEYS = ("channel", "unit", "sign", "offset")


@dataclasses.dataclass(frozen=True)
class _Column:
    """One CSV column and how it becomes a run channel: (value + offset) × factor."""

    name: str          #: CSV header
    channel: str       #: run channel (``elastokin.recordings.rig_recordings.TIME_NAME`` for the time)
    factor: float      #: run units per column unit, times the sign
    offset: float      #: added to the column's values [column unit]
    limit: float       #: largest plausible magnitude [column unit]

    def convert(self, values: np.ndarray) -> np.ndarray:
        """The column's values in the run's unit and sign."""
        return (values + self.offset) * self.factor


def _factor(f: Fields, channel: str, unit: str) -> float:
    """Run units per the unit declared at ``f``'s ``unit`` key, for ``channel`` recorded in ``unit``."""
    declared = f.text("unit")
    if declared not in units.UNITS:
        raise f.fail("unit", f"unknown unit {declared!r}; expected one of {', '.join(units.UNITS)}")
    if units.dimension(declared) != units.dimension(unit):
        fits = ", ".join(u for u in units.UNITS if units.dimension(u) == units.dimension(unit))
        raise f.fail("unit", f"unit mismatch: {declared!r} does not convert to {unit}, the unit of {channel}; "
                             f"expected one of {fits}")
    return units.factor(declared, unit)


def _channel_patterns(names: list[str]) -> str:
    corners = "|".join(CORNER_TAGS.values())
    patterns = dict.fromkeys(re.sub(f"_({corners})$", "_<c>", n) for n in names)
    return f"{', '.join(patterns)} (<c>: {', '.join(CORNER_TAGS.values())})"


def _column(doc: Document, name: str, item: Any, known: Mapping[str, str]) -> _Column:
    f = Fields.of(doc, ("columns", name), item, _COLUMN_KEYS)
    channel = f.text("channel")
    if channel not in known:
        raise f.fail("channel", f"unknown channel {channel!r}; expected a channel a K&C rig measures: "
                                f"{_channel_patterns(list(known))}")
    factor = _factor(f, channel, known[channel])
    sign = f.number("sign", 1.0)
    if sign not in (1.0, -1.0):
        raise f.fail("sign", f"expected +1 or -1, got {sign!r}")
    return _Column(str(name), channel, sign * factor, f.number("offset", 0.0), units.plausible(f.text("unit")))


def _scenario(top: Fields, meta: Path) -> Scenario:
    """The scenario file named relative to ``meta``, or the inline scenario mapping."""
    raw = top.raw("scenario")
    if isinstance(raw, str):
        path = meta.parent / raw
        if not is_file(path):
            raise top.fail("scenario", f"no such scenario file {str(path)!r}")
        return load_scenario(path)
    if not isinstance(raw, Mapping):
        raise top.fail("scenario", f"expected a scenario file (relative to this file) or an inline scenario "
                                   f"mapping, got {raw!r}")
    try:  # as if written in a file beside META: relative paths are taken from there
        return parse_scenario(dump_yaml(dict(raw), sort_keys=False), meta, source="inline scenario")
    except InputError as exc:
        raise top.fail("scenario", f"inline scenario{f', {exc.key}' if exc.key else ''}: {exc.bare}") from None


def import_csv(data: str | os.PathLike[str], meta: str | os.PathLike[str], output: str | os.PathLike[str], *,
               overwrite: bool = False) -> Path:
    """Convert the rig CSV ``data`` as the META file ``meta`` declares into the rig recording ``output``.

    Raises :class:`InputError` naming the file, line, key or column, the value and what was
    expected: unknown META keys, channels or units, a unit that does not convert to the channel's,
    a bad sign, a declared column missing from the CSV, a non-number or NaN, and whatever
    :func:`elastokin.recordings.rig_recordings.write_rig_recording` refuses (missing required channels, time not
    increasing, sampling gaps, time not covering the scenario, an existing output). Nothing is
    written on error.
    """
    meta = Path(meta)
    doc = Document(read_text(meta), str(meta))
    top = doc.top(_META_KEYS)
    scenario = _scenario(top, meta)
    duration_scale = top.number("duration_scale", 1.0, positive=True)
    rig = {"name": top.text("rig"), "notes": top.text("notes", ""),
           "imported_from": {"csv": Path(data).name, "meta_yaml": doc.text}}
    time_fields = Fields.of(doc, ("time",), top.raw("time"), _TIME_KEYS)
    time = _Column(time_fields.text("column"), TIME_NAME, _factor(time_fields, "the time", "s"),
                   time_fields.number("offset", 0.0), units.plausible(time_fields.text("unit")))
    raw = top.raw("columns")
    if not isinstance(raw, Mapping) or not raw:
        raise top.fail("columns", f"expected a mapping of CSV columns to {{{', '.join(_COLUMN_KEYS)}}}, got {raw!r}")
    if time.name in raw:
        raise doc.error(("columns", time.name), "this is the time column (key `time`); it cannot be a signal too")
    known = measured_channels()
    columns = [_column(doc, name, item, known) for name, item in raw.items()]
    header = {TIME_NAME: time.name}   # channel → CSV column, the time first (read_csv_columns checks it increases)
    for c in columns:
        if c.channel in header:
            raise doc.error(("columns", c.name, "channel"), f"channel {c.channel} is already given by column "
                                                            f"{header[c.channel]!r}")
        header[c.channel] = c.name
    limits = {c.name: c.limit for c in (time, *columns)}
    values = read_csv_columns(data, list(header.values()), min_rows=2, limits=limits)
    return write_rig_recording(
        output, scenario, time.convert(values[time.name]), {c.channel: c.convert(values[c.name]) for c in columns},
        {c.channel: known[c.channel] for c in columns}, rig=rig, duration_scale=duration_scale, overwrite=overwrite,
        source=str(data), where=lambda i, channel: f"line {i + 2}, column {header[channel]}")
