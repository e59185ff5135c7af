"""`vsim sweep SWEEP.yaml`: a design of runs over vehicle-file parameters on a Dask cluster (local by
default), one table of inputs and metrics, plots of each metric against each parameter, Sobol'
indices for a Sobol' design."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from elastokin.cli.arguments import add_scheduler_options, output_folder


def _clock(seconds: float) -> str:
    minutes, s = divmod(int(round(seconds)), 60)
    return f"{minutes} min {s:02d} s" if minutes else f"{s} s"


def _sweep(args: argparse.Namespace) -> int:
    from elastokin.cluster.executor import ClusterLost, executor
    from elastokin.presentation.sweep_figures import metric_plots
    from elastokin.sweeps.sweep import check_folder, run_sweep
    from elastokin.sweeps.sweep_file import load_sweep

    sweep = load_sweep(args.sweep)
    folder = (args.output or Path("out") / f"sweep_{sweep.name}").resolve()
    check_folder(sweep, folder, resume=args.resume, overwrite=args.overwrite)

    def show(p) -> None:
        print(f"  runs {p.done}/{p.to_do} done ({p.failed} failed), {_clock(p.elapsed_s)} elapsed, "
              f"~{_clock(p.left_s)} left",
              file=sys.stderr, flush=True)

    try:
        with executor(args.scheduler, args.workers) as ex:
            print(f"sweep {sweep.name}: {sweep.runs} runs ({sweep.design.type}, {len(sweep.parameters)} parameters, "
                  f"{len(sweep.columns)} metric columns) on {ex.description}", file=sys.stderr, flush=True)
            report = run_sweep(sweep, folder, ex, resume=args.resume, overwrite=args.overwrite, progress=show)
    except ClusterLost as exc:
        print(f"vsim: {exc}; {folder / 'sweep.csv'} holds the runs finished: --resume completes it", file=sys.stderr)
        return 1
    plots = [] if args.no_plots else metric_plots(report.table, [p.place for p in sweep.parameters],
                                                  [c.name for c in sweep.columns], folder / "plots")
    print(f"{report.finished}/{report.runs} runs in the table ({report.failed} failed; {report.computed} made now in "
          f"{_clock(report.wall_s)})")
    for path in report.files:
        print(f"wrote {path}")
    if plots:
        print(f"wrote {len(plots)} PNG(s) in {folder / 'plots'}")
    return 1 if report.finished and report.failed == report.finished else 0   # every run failed


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``sweep``."""
    cmd = subparsers.add_parser(
        "sweep", help="vary vehicle-file parameters over a design (grid, Latin hypercube, Sobol'), on a cluster",
        description="Run the scenarios of a sweep file (format: scenarios/sweeps/README.md) for every point of its "
                    "design, on a Dask cluster started on this machine (one worker per core) or an existing one "
                    "(--scheduler or VSIM_SCHEDULER); write DIR/sweep.csv (one row a run: parameters, metrics, "
                    "the reason of a failed run), DIR/sweep.json (its inputs), DIR/plots/ and, for a Sobol' "
                    "design, DIR/sensitivity.csv. Ctrl-C leaves the table of the runs finished; --resume makes "
                    "only the missing ones.")
    cmd.add_argument("sweep", metavar="SWEEP", help="sweep file, or a built-in one (scenarios/sweeps/)")
    cmd.add_argument("-o", "--output", type=output_folder, metavar="DIR",
                     help="output folder (default out/sweep_<name>)")
    add_scheduler_options(cmd)
    group = cmd.add_mutually_exclusive_group()
    group.add_argument("--resume", action="store_true", help="complete the table in DIR: make only the missing runs")
    group.add_argument("--overwrite", action="store_true", help="start again in DIR")
    cmd.add_argument("--no-plots", action="store_true", help="write no PNGs")
    cmd.set_defaults(func=_sweep)
