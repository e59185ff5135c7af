"""`vsim rig export SOURCE -o DIR [--convention sae|iso]`: rig recordings as a K&C rig's CSV exports."""

from __future__ import annotations

import argparse
from pathlib import Path

from elastokin.cli.arguments import output_folder


def _export(args: argparse.Namespace) -> int:
    from elastokin.recordings.csv_export import export_csv_folder

    written = export_csv_folder(args.source, args.output, convention=args.convention, overwrite=args.overwrite)
    print(f"wrote {args.output}: {len(written)} CSV export(s) with their META files, {args.convention} signs "
          f"(vsim rig import DATA.csv --meta DATA.meta.yaml reads each back)")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``export`` (of the ``rig`` group)."""
    p = subparsers.add_parser(
        "export", help="write rig recordings as a K&C rig's CSV exports (CSV + META.yaml, SAE or ISO signs)",
        description="Write a rig recording (.mcap), or every recording of a K&C dataset folder, as the CSV a rig "
                    "exports and the META file `vsim rig import` reads it with: <stem>.csv and <stem>.meta.yaml "
                    "in DIR, the run's units, the convention's signs (data/README.md). Nothing is written on error.")
    p.add_argument("source", type=Path, metavar="SOURCE", help="a rig recording (.mcap) or a K&C dataset folder")
    p.add_argument("-o", "--output", type=output_folder, required=True, metavar="DIR", help="folder to write")
    p.add_argument("--convention", default="sae", metavar="NAME",
                   help="sign convention: sae (SAE J670, y right, z down; default) or iso (ISO 8855)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output folder")
    p.set_defaults(func=_export)
