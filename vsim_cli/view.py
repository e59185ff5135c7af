"""`vsim view` (replay a run in Rerun) and `vsim plot` (PNG pictures of a run)."""

from __future__ import annotations

import argparse
from pathlib import Path

from vsim_core.errors import InputError

# The commands import their modules when run, so that `vsim --help` does not load rerun,
# matplotlib, mujoco and foxglove.


def _view(args: argparse.Namespace) -> int:
    from vsim_recordings.run_reader import load_run
    from vsim_presentation.replay import replay

    if args.save is not None and args.save.exists() and not args.overwrite:
        raise InputError("the output exists; pass --overwrite to replace it", source=str(args.save))
    run = load_run(args.run)
    replay(run, save=args.save, spawn=args.spawn or args.save is None)
    if args.save is not None:
        print(f"wrote {args.save}")
    return 0


def _plot(args: argparse.Namespace) -> int:
    from vsim_recordings.run_reader import load_run
    from vsim_presentation.run_plots import plot_run

    run = load_run(args.run)
    for path in plot_run(run, args.output, log_time=args.log_time, t0_s=args.t0):
        print(f"wrote {path}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``view`` and ``plot`` sub-commands."""
    view = subparsers.add_parser(
        "view",
        help="replay a run (.mcap) in Rerun: 3D car, signals against time, signal pairs",
        description="Build a Rerun recording from a run file alone. Without --save a viewer is spawned.",
    )
    view.add_argument("run", type=Path, metavar="RUN.mcap")
    view.add_argument("--save", type=Path, metavar="RUN.rrd", help="write the recording (with its layout) to this file")
    view.add_argument("--spawn", action="store_true", help="also show it in a Rerun viewer when saving")
    view.add_argument("--overwrite", action="store_true", help="replace an existing --save file")
    view.set_defaults(func=_view)

    plot = subparsers.add_parser(
        "plot",
        help="write PNGs of a run (.mcap): signal pairs, bushing loops, time histories",
        description="Pictures of a run with matplotlib: one PNG per group of signal pairs or bushing loops, "
        "one per signal group against time.",
    )
    plot.add_argument("run", type=Path, metavar="RUN.mcap")
    plot.add_argument("-o", "--output", type=Path, required=True, metavar="DIR", help="directory for the PNGs")
    plot.add_argument("--log-time", action="store_true", help="time axis in log scale (relaxations), from --t0 on")
    plot.add_argument("--t0", type=float, default=0.0, metavar="SECONDS", help="time origin (e.g. of the step)")
    plot.set_defaults(func=_plot)
