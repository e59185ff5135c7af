"""Importing a K&C rig's CSV export (format: ``data/README.md``) as a measured rig recording.

META.yaml says which scenario was played, which CSV column holds the time, and for every imported
column the run channel, the unit and the sign (and optionally an offset) it is written in. Units
and signs are converted once, here, to the run's units and ISO 8855 signs; the recording itself is
written by :func:`elastokin.recordings.rig_recordings.write_rig_recording`.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Mapping

from elastokin.vehicle.scenarios.channels import CORNER_TAGS, channel_quantity, channel_wheel
from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.vehicle.scenarios.scenario_file import load_scenario, parse_scenario
from elastokin.core.csv_channels import TIME_KEYS, Column, declared_columns, time_column
from elastokin.core.documents import Document, Fields, dump_yaml
from elastokin.core.errors import InputError
from elastokin.core.files import is_file, read_text
from elastokin.core.tables import read_csv_columns
from elastokin.recordings.rig_recordings import TIME_NAME, measured_channels, write_rig_recording

_META_KEYS = ("scenario", "duration_scale", "rig", "notes", "time", "columns")


def _channel_patterns(names: list[str]) -> str:
    patterns = dict.fromkeys(f"{channel_quantity(n)}_<c>" if channel_wheel(n) else n for n in names)
    return f"{', '.join(patterns)} (<c>: {', '.join(CORNER_TAGS.values())})"


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


def read_meta(meta: Path) -> tuple[Document, Fields, Column, list[Column]]:
    """The META file ``meta``: its document, its top-level fields, and its time and signal columns
    (InputError naming the key for an unknown key, channel or unit, a unit that does not convert, a
    bad sign, a channel given twice)."""
    doc = Document(read_text(meta), str(meta))
    top = doc.top(_META_KEYS)
    time = time_column(Fields.of(doc, ("time",), top.raw("time"), TIME_KEYS))
    known = measured_channels()
    columns = declared_columns(doc, ("columns",), top.raw("columns"), time, known,
                               f"a channel a K&C rig measures: {_channel_patterns(list(known))}")
    return doc, top, time, columns


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
    doc, top, time, columns = read_meta(meta)
    scenario = _scenario(top, meta)
    duration_scale = top.number("duration_scale", 1.0, positive=True)
    rig = {"name": top.text("rig"), "notes": top.text("notes", ""),
           "imported_from": {"csv": Path(data).name, "meta_yaml": doc.text}}
    known = measured_channels()
    header = {TIME_NAME: time.name, **{c.channel: c.name for c in columns}}   # the time first: read_csv_columns checks it increases
    limits = {c.name: c.limit for c in (time, *columns)}
    values = read_csv_columns(data, list(header.values()), min_rows=2, limits=limits)
    return write_rig_recording(
        output, scenario, time.convert(values[time.name]), {c.channel: c.convert(values[c.name]) for c in columns},
        {c.channel: known[c.channel] for c in columns}, rig=rig, duration_scale=duration_scale, overwrite=overwrite,
        source=str(data), where=lambda i, channel: f"line {i + 2}, column {header[channel]}")
