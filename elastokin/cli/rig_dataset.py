"""`vsim rig dataset DIR [RIG.mcap ...] [--vehicle TEXT]`: a folder of imported rig recordings made a
K&C dataset (its rig.yaml), ready for `vsim diagnose`."""

from __future__ import annotations

import argparse
from pathlib import Path


def _dataset(args: argparse.Namespace) -> int:
    from elastokin.recordings.kc_dataset import assemble_kc_dataset

    dataset = assemble_kc_dataset(args.folder, args.recordings or None, vehicle_text=args.vehicle,
                                  overwrite=args.overwrite)
    print(f"wrote {dataset.path / 'rig.yaml'}: {len(dataset.tests)} test(s), "
          f"{', '.join(t.name for t in dataset.tests)}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``dataset`` (of the ``rig`` group)."""
    p = subparsers.add_parser(
        "dataset", help="make a folder of rig recordings (vsim rig import's) a K&C dataset: write its rig.yaml",
        description="Write DIR/rig.yaml listing the rig recordings of one car in the order played (default: every "
                    ".mcap in DIR, by name), after reading each as vsim diagnose will (data/README.md). Nothing is "
                    "written on error.")
    p.add_argument("folder", type=Path, metavar="DIR", help="the folder holding the recordings")
    p.add_argument("recordings", nargs="*", metavar="RIG.mcap", help="their file names in DIR, in the order played")
    p.add_argument("--vehicle", default="", metavar="TEXT", help="the car measured (free text)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing rig.yaml")
    p.set_defaults(func=_dataset)
