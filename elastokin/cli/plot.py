"""`vsim plot RUN.mcap -o DIR`: PNG pictures of a run."""

from __future__ import annotations

import argparse
from pathlib import Path

from elastokin.cli.arguments import add_strict_option, output_folder


def _plot(args: argparse.Namespace) -> int:
    from elastokin.presentation.run_plots import plot_run
    from elastokin.recordings.run_reader import check_samples, load_run

    run = load_run(args.run, strict=args.strict)
    check_samples(run, "plot")
    for path in plot_run(run, args.output, log_time=args.log_time, t0_s=args.t0):   # a figure at a time
        print(f"wrote {path}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``plot``."""
    plot = subparsers.add_parser(
        "plot",
        help="write PNGs of a run (.mcap): signal pairs, bushing loops, time histories",
        description="Pictures of a run with matplotlib: one PNG per group of signal pairs or bushing loops, "
        "one per signal group against time.",
    )
    plot.add_argument("run", type=Path, metavar="RUN.mcap")
    plot.add_argument("-o", "--output", type=output_folder, required=True, metavar="DIR", help="directory for the PNGs")
    plot.add_argument("--log-time", action="store_true", help="time axis in log scale (relaxations), from --t0 on")
    plot.add_argument("--t0", type=float, default=0.0, metavar="SECONDS", help="time origin (e.g. of the step)")
    add_strict_option(plot)
    plot.set_defaults(func=_plot)
