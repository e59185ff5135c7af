"""Sweeps as the API hands them out: a design of runs over vehicle-file numbers, on a cluster."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from elastokin.cluster.executor import executor as cluster
from elastokin.sweeps.sweep import SweepProgress, SweepReport, check_folder, run_sweep
from elastokin.sweeps.sweep_file import load_sweep


def sweep(name_or_path: str | Path, folder: str | Path | None = None, *, scheduler: str | None = None,
          workers: int | None = None, resume: bool = False, overwrite: bool = False,
          progress: Callable[[SweepProgress], None] | None = None) -> SweepReport:
    """Run a sweep file's design (format: ``scenarios/sweeps/README.md``): every point's scenarios
    on the vehicle with the point's values set, one table of inputs and metrics.

    Args:
        name_or_path: a sweep file, or a built-in sweep's name (``e2_front_kr_co``).
        folder: where ``sweep.csv``, ``sweep.json`` (and for a Sobol' design ``sensitivity.csv``)
            go; default ``out/sweep_<name>``.
        scheduler: a Dask scheduler's address, ``local`` or ``serial`` (default ``$VSIM_SCHEDULER``,
            else a cluster on this machine).
        workers: worker processes of a local cluster (default: one per core).
        resume: complete the table in ``folder``: make only the missing runs.
        overwrite: start the table in ``folder`` again.
        progress: called with a :class:`~elastokin.sweeps.sweep.SweepProgress` as runs finish.

    Returns:
        The :class:`~elastokin.sweeps.sweep.SweepReport` (its ``table``: one row a run, by column).

    Raises:
        InputError: a bad sweep file, or a ``folder`` holding another table (without ``resume``
            or ``overwrite``).
        elastokin.cluster.executor.ClusterLost: the cluster was lost (the table keeps the runs finished).
    """
    plan = load_sweep(name_or_path)
    out = Path(folder) if folder is not None else Path("out") / f"sweep_{plan.name}"
    check_folder(plan, out, resume=resume, overwrite=overwrite)
    with cluster(scheduler, workers) as ex:
        return run_sweep(plan, out, ex, resume=resume, overwrite=overwrite, progress=progress)
