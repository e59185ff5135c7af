"""`vsim rig import DATA.csv --meta META.yaml -o RIG.mcap`: a rig's CSV export as a measured rig recording."""

from __future__ import annotations

import argparse
from pathlib import Path

from elastokin.cli.arguments import output_file


def _import(args: argparse.Namespace) -> int:
    from elastokin.recordings.csv_import import import_csv
    from elastokin.recordings.run_reader import load_run

    run = load_run(import_csv(args.data, args.meta, args.output, overwrite=args.overwrite))
    measured = [s.name for s in run.specs if s.group != "run"]
    print(f"wrote {run.path}: {run.t_s.size} samples over {run.t_s[-1]:.3f} s, {len(measured)} channels, "
          f"{len(run.metadata.extra['cases'])} case(s) of {run.metadata.extra['scenario']}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``import`` (of the ``rig`` group)."""
    p = subparsers.add_parser(
        "import", help="convert a rig's CSV export into a measured rig recording (.mcap)",
        description="Read DATA.csv as META.yaml declares it (the scenario played, the time column, each "
                    "column's run channel, unit, sign and offset; format: data/README.md), convert it to the "
                    "run's units and ISO 8855 signs and write one MCAP rig recording, read by vsim plot and "
                    "vsim view like a simulated run. Nothing is written on error.")
    p.add_argument("data", type=Path, metavar="DATA.csv")
    p.add_argument("--meta", type=Path, required=True, metavar="META.yaml", help="how to read DATA.csv")
    p.add_argument("-o", "--output", type=output_file, required=True, metavar="RIG.mcap", help="rig recording to write")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    p.set_defaults(func=_import)
