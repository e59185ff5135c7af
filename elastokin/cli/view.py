"""`vsim view RUN.mcap [--save RUN.rrd]`: replay a run in Rerun."""

from __future__ import annotations

import argparse
from pathlib import Path

from elastokin.cli.arguments import add_strict_option, output_file
from elastokin.core.errors import InputError


def _view(args: argparse.Namespace) -> int:
    from elastokin.presentation.replay import replay
    from elastokin.recordings.run_reader import check_samples, load_run

    if args.save is not None and args.save.exists() and not args.overwrite:
        raise InputError("the output exists; pass --overwrite to replace it", source=str(args.save))
    run = load_run(args.run, strict=args.strict)
    check_samples(run, "replay")
    replay(run, save=args.save, spawn=args.spawn or args.save is None)
    if args.save is not None:
        print(f"wrote {args.save}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``view``."""
    view = subparsers.add_parser(
        "view",
        help="replay a run (.mcap) in Rerun: 3D car, signals against time, signal pairs",
        description="Build a Rerun recording from a run file alone. Without --save a viewer is spawned.",
    )
    view.add_argument("run", type=Path, metavar="RUN.mcap")
    view.add_argument("--save", type=output_file, metavar="RUN.rrd", help="write the recording (with its layout) to this file")
    view.add_argument("--spawn", action="store_true", help="also show it in a Rerun viewer when saving")
    view.add_argument("--overwrite", action="store_true", help="replace an existing --save file")
    add_strict_option(view)
    view.set_defaults(func=_view)
