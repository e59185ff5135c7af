"""Running a sweep: its runs submitted to an executor (a Dask cluster or this process), the table
written as they finish, Sobol' indices for a Sobol' design.

The folder holds ``sweep.csv`` and ``sweep.json`` (:mod:`elastokin.sweeps.sweep_table`), ``runs/`` when
the sweep records its runs, and ``sensitivity.csv`` for a Sobol' design. A folder with a table is
completed with ``resume`` (only the missing runs are made) or replaced with ``overwrite``.
"""

from __future__ import annotations

import math
import shutil
import time
from contextlib import closing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from elastokin.cluster.executor import Executor
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output, exclusive_folder
from elastokin.sweeps.designs import design_points
from elastokin.sweeps.sensitivity import sobol_indices
from elastokin.sweeps.sweep_file import Sweep
from elastokin.sweeps.sweep_runs import run_point, tasks
from elastokin.sweeps.sweep_table import INPUTS, TABLE, TableWriter, check_inputs, format_row, read_table, write_inputs

SENSITIVITY = "sensitivity.csv"


@dataclass(frozen=True)
class SweepProgress:
    """Where a sweep stands: runs finished (of this session's ``to_do``), failed, and the time left."""

    done: int
    to_do: int
    failed: int
    elapsed_s: float
    left_s: float             #: the runs left at the mean pace of those finished


@dataclass
class SweepReport:
    """A finished (or interrupted) sweep: its table and what the session computed."""

    runs: int                                  #: runs of the design
    finished: int                              #: rows in the table
    failed: int                                #: rows with a reason
    computed: int                              #: runs made by this session
    wall_s: float
    compute_s: float                           #: sum of the runs' own simulation times
    table: list[dict[str, str]]                #: the table's rows in run order, by column (as written)
    files: list[Path] = field(default_factory=list)


def check_folder(sweep: Sweep, folder: Path, *, resume: bool = False, overwrite: bool = False) -> None:
    """InputError if ``folder`` holds a table this session may not continue (module docstring):
    checked before a cluster starts."""
    table = Path(folder) / TABLE
    if table.exists() and not (resume or overwrite):
        raise InputError("a sweep's table is already there: --resume completes it, --overwrite starts again",
                         source=str(table))
    if table.exists() and resume:
        check_inputs(Path(folder), sweep)


def _prepared(sweep: Sweep, folder: Path, points: np.ndarray, resume: bool, overwrite: bool) -> dict[int, list[str]]:
    """The rows already in ``folder`` that this session keeps (module docstring)."""
    check_folder(sweep, folder, resume=resume, overwrite=overwrite)
    table = folder / TABLE
    if table.exists() and resume:
        return read_table(table, sweep, points)
    if overwrite:
        for name in (TABLE, INPUTS, SENSITIVITY):
            (folder / name).unlink(missing_ok=True)
        for name in ("runs", "plots"):
            shutil.rmtree(folder / name, ignore_errors=True)
    return {}


def run_sweep(sweep: Sweep, folder: Path, executor: Executor, *, resume: bool = False, overwrite: bool = False,
              progress: Callable[[SweepProgress], None] | None = None) -> SweepReport:
    """Make the runs of ``sweep`` that ``folder``'s table lacks on ``executor`` (module docstring).
    A cluster lost on the way raises :class:`elastokin.cluster.executor.ClusterLost`, the table holding
    the runs finished before; InputError if another process is sweeping into ``folder``."""
    folder = Path(folder)
    with exclusive_folder(folder, "vsim sweep"):   # two sessions on one table would interleave their rows
        return _run_sweep(sweep, folder, executor, resume, overwrite, progress)


def _run_sweep(sweep: Sweep, folder: Path, executor: Executor, resume: bool, overwrite: bool,
               progress: Callable[[SweepProgress], None] | None) -> SweepReport:
    started = time.perf_counter()
    points = design_points(sweep.design, np.array([p.low for p in sweep.parameters]),
                           np.array([p.high for p in sweep.parameters]))
    done = _prepared(sweep, folder, points, resume, overwrite)
    write_inputs(folder, sweep)
    record_dir = folder / "runs" if sweep.record else None
    if record_dir is not None:
        record_dir.mkdir(exist_ok=True)
    missing = [i for i in range(len(points)) if i + 1 not in done]
    names = [c.name for c in sweep.columns]
    writer = TableWriter(folder, sweep, done)
    compute_s, failed, count = 0.0, 0, 0
    try:
        # closed on leaving (Ctrl-C too): the runs not finished are cancelled on the cluster at once
        with closing(executor.each(run_point, tasks(sweep, points, missing, record_dir))) as outcomes:
            for outcome in outcomes:
                run = missing[outcome.index]
                metrics = {} if outcome.error else outcome.result.metrics
                compute_s += 0.0 if outcome.error else outcome.result.compute_s
                failed += bool(outcome.error)
                count += 1
                writer.add(format_row(run + 1, points[run], metrics, names, outcome.error))
                if progress is not None:
                    elapsed = time.perf_counter() - started
                    progress(SweepProgress(count, len(missing), failed, elapsed,
                                           elapsed / count * (len(missing) - count)))
    finally:
        writer.finish()
    files = [writer.path, folder / INPUTS]
    if sweep.design.type == "sobol" and len(writer.rows) == len(points):
        files.append(_write_sensitivity(folder, sweep, writer.rows))
    return SweepReport(len(points), len(writer.rows), sum(1 for r in writer.rows.values() if r[-1]), count,
                       time.perf_counter() - started, compute_s, writer.records(), files)


def _write_sensitivity(folder: Path, sweep: Sweep, rows: dict[int, list[str]]) -> Path:
    """``sensitivity.csv``: per metric column and parameter, S_i and S_Ti and the samples they rest on."""
    first = 1 + len(sweep.parameters)
    ordered = [rows[k] for k in sorted(rows)]
    lines = ["metric,parameter,first_order,total,samples"]
    for j, column in enumerate(sweep.columns):
        values = np.array([float(r[first + j]) if not r[-1] else math.nan for r in ordered])
        s = sobol_indices(values, len(sweep.parameters))
        lines += [f"{column.name},{p.place},{float(s.first[i])!r},{float(s.total[i])!r},{s.samples}"
                  for i, p in enumerate(sweep.parameters)]
    path = folder / SENSITIVITY
    with atomic_output(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path

