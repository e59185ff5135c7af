"""`vsim rig measure TRUTH.yaml -o DIR`: a measured dataset made by the virtual bench or K&C rig."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from elastokin.cli.arguments import output_folder


def _measure(args: argparse.Namespace) -> int:
    from elastokin.diagnosis.truths import load_truth, measure
    from elastokin.diagnosis.virtual_kc_rig import KCTruth

    truth = load_truth(args.truth)
    kc = isinstance(truth, KCTruth)

    def progress(i: int, n: int, name: str) -> None:
        print(f"  {'scenario' if kc else 'test'} {i + 1}/{n}: {name}", file=sys.stderr, flush=True)

    out = measure(truth, args.output, overwrite=args.overwrite, progress=progress)
    print(f"wrote {out} (measured {'K&C' if kc else 'bench'} dataset, no trace of the truth)")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``measure`` (of the ``rig`` group)."""
    p = subparsers.add_parser(
        "measure", help="play the standard campaign on a truth model and write what a rig would measure",
        description="Virtual rig: a truth model (a baseline + effects from the catalogue or outside it + "
                    "measurement imperfections) played through the standard campaign and written as a measured "
                    "dataset that carries no trace of the truth. level: bench (a parameter set on the bushing "
                    "bench; format in elastokin/diagnosis/virtual_bench.py) writes rig.yaml + CSVs; level: kc (a "
                    "vehicle on the K&C rig, the scenarios of scenarios/kc; format in "
                    "elastokin/diagnosis/virtual_kc_rig.py) writes rig.yaml + MCAP rig recordings (data/README.md).")
    p.add_argument("truth", type=Path, metavar="TRUTH.yaml")
    p.add_argument("-o", "--output", type=output_folder, required=True, metavar="DIR", help="measured dataset to write")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output directory")
    p.set_defaults(func=_measure, compiles=True)
