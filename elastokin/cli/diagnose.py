"""`vsim diagnose DATASET`: what the baseline gets wrong on measured data, the cause, the gain."""

from __future__ import annotations

import argparse
import json
import sys

from elastokin.cli.arguments import add_scheduler_options, output_folder


def _diagnose(args: argparse.Namespace) -> int:
    from elastokin.api.built_ins import dataset
    from elastokin.cluster.executor import ClusterLost
    from elastokin.recordings.datasets import check_baseline, dataset_level

    folder = dataset(args.dataset)
    level = dataset_level(folder)
    check_baseline(folder, level, args.vehicle is not None, args.bushing_set is not None, args.use_damaged)
    progress = None if args.json else lambda s: print(f"  {s}", file=sys.stderr, flush=True)
    try:
        if level == "kc":   # the K&C diagnosis alone loads MuJoCo: a bench's does not
            from elastokin.api.kc_verdict import diagnose_kc_dataset

            found = diagnose_kc_dataset(folder, args.vehicle, scheduler=args.scheduler, workers=args.workers,
                                        progress=progress, use_damaged=args.use_damaged)
        else:
            from elastokin.api.bench_verdict import diagnose_bench_dataset

            found = diagnose_bench_dataset(folder, args.bushing_set, progress)
    except ClusterLost as exc:
        print(f"vsim: {exc}: the diagnosis stopped; run it again", file=sys.stderr)
        return 1
    written = found.write_report(args.output) if args.output is not None else []
    if args.json:
        print(json.dumps(found.summary()))
    else:
        print(found.verdict)
        for path in written:
            print(f"wrote {path}")
    if args.output is None:
        print("no report written: -o DIR writes report.md, its PNGs, diagnosis.json and the extended model there",
              file=sys.stderr)
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``diagnose`` sub-command."""
    p = subparsers.add_parser(
        "diagnose", help="name what the model misses in measured rig data (a directory with rig.yaml)",
        description="Run the baseline on exactly the tests found in the data, fit every applicable cause of the "
                    "catalogue on half of them, score it on the other half, and name the cause, or say that "
                    "nothing significant is missing, or that the mismatch is unexplained.")
    p.add_argument("dataset", metavar="DATASET",
                   help="a measured dataset folder (with rig.yaml, data/README.md), or a shipped example: kc, bench")
    group = p.add_mutually_exclusive_group()
    group.add_argument("--vehicle", metavar="VEHICLE",
                       help="baseline vehicle file or built-in name (K&C datasets; default: the built-in car)")
    group.add_argument("--bushing-set", metavar="SET",
                       help="baseline bushing parameter set, a name (`vsim list`) or a YAML path (bench datasets)")
    p.add_argument("-o", "--output", type=output_folder, metavar="REPORT_DIR",
                   help="write report.md, PNGs, diagnosis.json and the extended model here (extended_model.yaml for a bench, "
                        "extended_vehicle.yaml for K&C)")
    p.add_argument("--json", action="store_true", help="print the verdict as one JSON object")
    p.add_argument("--use-damaged", action="store_true",
                   help="diagnose a K&C dataset whose recordings are damaged or incomplete with the samples they hold "
                        "(default: refuse it; what they lack goes into the report)")
    add_scheduler_options(p, "K&C datasets: ")
    p.set_defaults(func=_diagnose, compiles=True)
