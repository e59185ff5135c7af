"""A sweep's table on disk: ``sweep.csv`` (one row a run: its number, parameter values, metrics and,
for a failed run, the reason) and ``sweep.json`` (the inputs it was made from).

Rows are appended as runs finish, one whole line per write, so that a sweep stopped by Ctrl-C, a
batch scheduler or a crash leaves a valid table of the runs finished so far; at the end, and on
an interruption, the table is rewritten in run order (atomically). Numbers are written with
``repr`` (they read back to the same bits); a metric a run's cases did not give is ``nan``.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
from pathlib import Path
from typing import Mapping, Sequence

from elastokin.cluster.executor import WORKERS_DIED
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output, read_text
from elastokin.core.provenance import software_version
from elastokin.sweeps.sweep_file import Sweep

TABLE = "sweep.csv"
INPUTS = "sweep.json"
FAILED = "failed"


def header(sweep: Sweep) -> list[str]:
    """The table's columns: ``run``, the parameters' places, the metric columns, ``failed``."""
    return ["run", *(p.place for p in sweep.parameters), *(c.name for c in sweep.columns), FAILED]


def inputs_record(sweep: Sweep) -> dict:
    """What the sweep was made from: the path and text of every file its runs read (the sweep, the
    vehicle, the scenarios, the vehicle's bushing parameter sets and tyre), the software version,
    and their fingerprint (a resumed sweep must have the same)."""
    version = software_version()
    digest = hashlib.sha256("\0".join([version, *(f"{f.path}\0{f.text}" for f in sweep.inputs)]).encode()).hexdigest()
    return {"sweep_file": str(sweep.path), "inputs_sha256": digest, "software_version": version,
            "runs": sweep.runs, "files": [{"path": f.path, "text": f.text} for f in sweep.inputs]}


def format_row(run: int, values: Sequence[float], metrics: Mapping[str, float], names: Sequence[str],
               failed: str) -> list[str]:
    """The cells of run number ``run`` (1-based)."""
    return [str(run), *(repr(float(v)) for v in values),
            *(repr(float(metrics.get(n, math.nan))) for n in names), failed]


def _line(cells: Sequence[str]) -> str:
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow(cells)
    return buffer.getvalue()


def read_table(path: Path, sweep: Sweep, points: Sequence[Sequence[float]]) -> dict[int, list[str]]:
    """The rows of an existing table by run number, checked against ``sweep`` and its design
    ``points``; InputError naming the file, line and column when they do not belong to this sweep.
    A last line cut short (the process killed while writing it) is dropped, and so is a run whose
    workers died under it (:data:`~elastokin.cluster.executor.WORKERS_DIED`): those runs are redone."""
    source = str(path)
    lines = read_text(path).splitlines()
    rows = list(csv.reader(lines))
    expected = header(sweep)
    if not rows or rows[0] != expected:
        raise InputError(f"its columns are not this sweep's ({len(expected)} columns from run to failed): "
                         f"the sweep file changed since; remove the folder or write elsewhere", source=source,
                         key="line 1")
    out: dict[int, list[str]] = {}
    places = len(sweep.parameters)
    for number, row in enumerate(rows[1:], start=2):
        if len(row) != len(expected):
            if number == len(rows):
                break
            raise InputError(f"{len(row)} fields; expected {len(expected)}", source=source, key=f"line {number}")
        run = int(row[0]) if row[0].isdigit() else 0
        if not 1 <= run <= len(points):
            raise InputError(f"run {row[0]!r} is not a run of this sweep (1..{len(points)})", source=source,
                             key=f"line {number}, column run")
        if [repr(float(v)) for v in points[run - 1]] != row[1:1 + places]:
            raise InputError(f"run {run} was made with other parameter values than this sweep's design gives: "
                             f"the design changed since", source=source, key=f"line {number}")
        if not row[-1].startswith(WORKERS_DIED):
            out[run] = row
    return out


class TableWriter:
    """Appends rows to the table as runs finish; :meth:`finish` rewrites it in run order."""

    def __init__(self, folder: Path, sweep: Sweep, done: Mapping[int, list[str]]):
        """Start the table in ``folder`` with the rows already ``done`` (a resumed sweep's)."""
        self.path = folder / TABLE
        self.header = header(sweep)
        self.rows = dict(done)
        self._write_ordered()
        self.stream = open(self.path, "a", encoding="utf-8", newline="")

    def add(self, cells: list[str]) -> None:
        """Append one run's row (one write, flushed: a reader or a crash sees whole lines)."""
        self.rows[int(cells[0])] = cells
        self.stream.write(_line(cells))
        self.stream.flush()

    def _write_ordered(self) -> None:
        with atomic_output(self.path) as tmp:
            tmp.write_text("".join(_line(r) for r in [self.header, *(self.rows[k] for k in sorted(self.rows))]),
                           encoding="utf-8")

    def finish(self) -> None:
        """Close the table, its rows in run order."""
        self.stream.close()
        self._write_ordered()

    def records(self) -> list[dict[str, str]]:
        """The table's rows in run order, each by column name (cells as written)."""
        return [dict(zip(self.header, self.rows[k])) for k in sorted(self.rows)]


def write_inputs(folder: Path, sweep: Sweep) -> None:
    """``sweep.json`` of :func:`inputs_record` (atomically)."""
    with atomic_output(folder / INPUTS) as tmp:
        tmp.write_text(json.dumps(inputs_record(sweep), indent=1) + "\n", encoding="utf-8")


def check_inputs(folder: Path, sweep: Sweep) -> None:
    """InputError unless the sweep in ``folder`` was made from the same inputs as ``sweep``."""
    path = folder / INPUTS
    try:
        made = json.loads(read_text(path)).get("inputs_sha256")
    except (InputError, ValueError, AttributeError):
        made = None
    if made != inputs_record(sweep)["inputs_sha256"]:
        raise InputError(f"the sweep there was not made from the same sweep, vehicle and scenario files as "
                         f"{sweep.path} with this software version (a text differs, or {INPUTS} is missing): --resume "
                         f"completes only the same sweep; use --overwrite or another folder", source=str(path))

