"""`vsim rig`: K&C rig measurements. `vsim rig import DATA.csv --meta META.yaml -o RIG.mcap` turns a
rig's CSV export into a measured rig recording (formats: ``data/README.md``); `vsim rig measure
TRUTH.yaml -o DIR` writes a measured dataset with the virtual rig (bench or K&C level).

META.yaml says which scenario was played, which CSV column holds the time, and for every imported
column the run channel, the unit and the sign (and optionally an offset) it is written in. Units
and signs are converted once, here, to the run's units and ISO 8855 signs; the recording itself is
written by :func:`vsim_recordings.rig_recordings.write_rig_recording`.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import re
import sys
import tempfile
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import yaml

from vsim_core.errors import InputError
from bushings.bench.records import read_csv_columns
from vehicle.scenarios.scenario_file import CORNER_TAGS, Scenario, _Document, _Fields, load_scenario

#: Units a CSV column may be written in: the run unit it converts to, and run units per column unit.
UNITS = {
    "deg": ("deg", 1.0), "rad": ("deg", math.degrees(1.0)), "arcmin": ("deg", 1.0 / 60.0),
    "mm": ("mm", 1.0), "cm": ("mm", 10.0), "m": ("mm", 1e3),
    "N": ("N", 1.0), "daN": ("N", 10.0), "kN": ("N", 1e3),
    **{f"{prefix}N{dot}m": ("N·m", factor) for prefix, factor in (("", 1.0), ("da", 10.0), ("k", 1e3))
       for dot in ("·", ".", "")},
    "s": ("s", 1.0), "ms": ("s", 1e-3),
}
_META_KEYS = ("scenario", "duration_scale", "rig", "notes", "time", "columns")
_TIME_KEYS = ("column", "unit", "offset")
_COLUMN_KEYS = ("channel", "unit", "sign", "offset")


@dataclasses.dataclass(frozen=True)
class _Column:
    """One CSV column and how it becomes a run channel: (value + offset) × factor."""

    name: str          #: CSV header
    channel: str       #: run channel (``vsim_recordings.rig_recordings.TIME_NAME`` for the time)
    factor: float      #: run units per column unit, times the sign
    offset: float      #: added to the column's values [column unit]

    def convert(self, values: np.ndarray) -> np.ndarray:
        return (values + self.offset) * self.factor


def _factor(f: _Fields, channel: str, unit: str) -> float:
    """Run units per the unit declared at ``f``'s ``unit`` key, for ``channel`` recorded in ``unit``."""
    declared = f.text("unit")
    if declared not in UNITS:
        raise f.fail("unit", f"unknown unit {declared!r}; expected one of {', '.join(UNITS)}")
    target, factor = UNITS[declared]
    if target != unit:
        fits = ", ".join(u for u, (t, _) in UNITS.items() if t == unit)
        raise f.fail("unit", f"unit mismatch: {declared!r} does not convert to {unit}, the unit of {channel}; "
                             f"expected one of {fits}")
    return factor


def _channel_patterns(names: list[str]) -> str:
    corners = "|".join(CORNER_TAGS.values())
    patterns = dict.fromkeys(re.sub(f"_({corners})$", "_<c>", n) for n in names)
    return f"{', '.join(patterns)} (<c>: {', '.join(CORNER_TAGS.values())})"


def _column(doc: _Document, name: str, item: Any, known: Mapping[str, str]) -> _Column:
    f = _Fields.of(doc, ("columns", name), item, _COLUMN_KEYS)
    channel = f.text("channel")
    if channel not in known:
        raise f.fail("channel", f"unknown channel {channel!r}; expected a channel a K&C rig measures: "
                                f"{_channel_patterns(list(known))}")
    factor = _factor(f, channel, known[channel])
    sign = f.number("sign", 1.0)
    if sign not in (1.0, -1.0):
        raise f.fail("sign", f"expected +1 or -1, got {sign!r}")
    return _Column(str(name), channel, sign * factor, f.number("offset", 0.0))


def _scenario(top: _Fields, meta: Path) -> Scenario:
    """The scenario file named relative to ``meta``, or the inline scenario mapping."""
    raw = top.raw("scenario")
    if isinstance(raw, str):
        path = meta.parent / raw
        if not path.is_file():
            raise top.fail("scenario", f"no such scenario file {str(path)!r}")
        return load_scenario(path)
    if not isinstance(raw, Mapping):
        raise top.fail("scenario", f"expected a scenario file (relative to this file) or an inline scenario "
                                   f"mapping, got {raw!r}")
    # load_scenario reads files: a temporary one beside META resolves the scenario's relative paths from there.
    with tempfile.NamedTemporaryFile("w", dir=meta.parent, prefix=f".{meta.stem}.", suffix=".yaml") as tmp:
        tmp.write(yaml.safe_dump(dict(raw), sort_keys=False))
        tmp.flush()
        try:
            scenario = load_scenario(tmp.name)
        except InputError as exc:
            where = ": ".join(part for part in (exc.source, exc.key) if part)
            raise top.fail("scenario", f"inline scenario{f', {exc.key}' if exc.key else ''}: "
                                       f"{str(exc).removeprefix(where + ': ')}") from None
    return dataclasses.replace(scenario, name=raw.get("name", meta.stem), path=meta)


def import_csv(data: str | os.PathLike[str], meta: str | os.PathLike[str], output: str | os.PathLike[str], *,
               overwrite: bool = False) -> Path:
    """Convert the rig CSV ``data`` as the META file ``meta`` declares into the rig recording ``output``.

    Raises :class:`InputError` naming the file, line, key or column, the value and what was
    expected: unknown META keys, channels or units, a unit that does not convert to the channel's,
    a bad sign, a declared column missing from the CSV, a non-number or NaN, and whatever
    :func:`vsim_recordings.rig_recordings.write_rig_recording` refuses (missing required channels, time not
    increasing, sampling gaps, time not covering the scenario, an existing output). Nothing is
    written on error.
    """
    from vsim_recordings.rig_recordings import TIME_NAME, measured_channels, write_rig_recording  # not loaded by `vsim --help`

    meta = Path(meta)
    try:
        text = meta.read_text()
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", source=str(meta)) from exc
    doc = _Document(text, str(meta))
    top = _Fields.of(doc, (), doc.data, _META_KEYS)
    scenario = _scenario(top, meta)
    duration_scale = top.number("duration_scale", 1.0, positive=True)
    rig = {"name": top.text("rig"), "notes": top.text("notes", ""),
           "imported_from": {"csv": Path(data).name, "meta_yaml": text}}
    time_fields = _Fields.of(doc, ("time",), top.raw("time"), _TIME_KEYS)
    time = _Column(time_fields.text("column"), TIME_NAME, _factor(time_fields, "the time", "s"),
                   time_fields.number("offset", 0.0))
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
    values = read_csv_columns(data, list(header.values()), min_rows=2)
    return write_rig_recording(
        output, scenario, time.convert(values[time.name]), {c.channel: c.convert(values[c.name]) for c in columns},
        {c.channel: known[c.channel] for c in columns}, rig=rig, duration_scale=duration_scale, overwrite=overwrite,
        source=str(data), where=lambda i, channel: f"line {i + 2}, column {header[channel]}")


# -- the command ------------------------------------------------------------------------------------
def _import(args: argparse.Namespace) -> int:
    from vsim_recordings.run_reader import load_run

    run = load_run(import_csv(args.data, args.meta, args.output, overwrite=args.overwrite))
    measured = [s.name for s in run.specs if s.group != "run"]
    print(f"wrote {run.path}: {run.t_s.size} samples over {run.t_s[-1]:.3f} s, {len(measured)} channels, "
          f"{len(run.metadata.extra['cases'])} case(s) of {run.metadata.extra['scenario']}")
    return 0


def _add_import(commands: argparse._SubParsersAction) -> None:
    p = commands.add_parser(
        "import", help="convert a rig's CSV export into a measured rig recording (.mcap)",
        description="Read DATA.csv as META.yaml declares it (the scenario played, the time column, each "
                    "column's run channel, unit, sign and offset; format: data/README.md), convert it to the "
                    "run's units and ISO 8855 signs and write one MCAP rig recording, read by vsim plot and "
                    "vsim view like a simulated run. Nothing is written on error.")
    p.add_argument("data", type=Path, metavar="DATA.csv")
    p.add_argument("--meta", type=Path, required=True, metavar="META.yaml", help="how to read DATA.csv")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="RIG.mcap", help="rig recording to write")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    p.set_defaults(func=_import)


def _measure(args: argparse.Namespace) -> int:
    from vsim_diagnosis.virtual_kc_rig import KCTruth, measure_kc
    from vsim_diagnosis.virtual_bench import load_truth, measure_bench

    truth = load_truth(args.truth)
    kc = isinstance(truth, KCTruth)

    def progress(i: int, n: int, name: str) -> None:
        print(f"  {'scenario' if kc else 'test'} {i + 1}/{n}: {name}", file=sys.stderr, flush=True)

    measure = measure_kc if kc else measure_bench
    out = measure(truth, args.output, overwrite=args.overwrite, progress=progress)
    print(f"wrote {out} (measured {'K&C' if kc else 'bench'} dataset, no trace of the truth)")
    return 0


def _add_measure(commands: argparse._SubParsersAction) -> None:
    p = commands.add_parser(
        "measure", help="play the standard campaign on a truth model and write what a rig would measure",
        description="Virtual rig: a truth model (a baseline + effects from the catalogue or outside it + "
                    "measurement imperfections) played through the standard campaign and written as a measured "
                    "dataset that carries no trace of the truth. level: bench (a parameter set on the bushing "
                    "bench; format in vsim_diagnosis/virtual_bench.py) writes rig.yaml + CSVs; level: kc (a "
                    "vehicle on the K&C rig, the scenarios of scenarios/kc; format in "
                    "vsim_diagnosis/virtual_kc_rig.py) writes rig.yaml + MCAP rig recordings (data/README.md).")
    p.add_argument("truth", type=Path, metavar="TRUTH.yaml")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="DIR", help="measured dataset to write")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output directory")
    p.set_defaults(func=_measure)


#: The sub-commands of `vsim rig`, each added to the group's sub-parsers by one function.
SUBCOMMANDS = (_add_import, _add_measure)


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``rig`` command group and its sub-commands."""
    rig = subparsers.add_parser("rig", help="measured data: import a K&C rig's CSV export, or measure on the virtual rig",
                                description="Measured K&C rig data (data/README.md).")
    commands = rig.add_subparsers(dest="rig_command", required=True)
    for add in SUBCOMMANDS:
        add(commands)
