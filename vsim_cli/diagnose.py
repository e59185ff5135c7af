"""`vsim diagnose RIGDIR`: what the baseline gets wrong on measured data, the cause, the gain."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from vsim_cli.arguments import add_scheduler_options, output_folder
from vsim_core.errors import InputError


def _diagnose(args: argparse.Namespace) -> int:
    from vsim_recordings.datasets import dataset_level

    level = dataset_level(args.rigdir)
    quiet = args.json
    progress = None if quiet else lambda s: print(f"  {s}", file=sys.stderr, flush=True)
    if level == "kc":
        if args.bushing_model is not None:
            raise InputError("a K&C dataset is diagnosed against a vehicle: --vehicle V.yaml (default: the built-in "
                             "car), not --bushing-model", source=str(args.rigdir / "rig.yaml"), key="level")
        result, written, sentence, summary = _kc(args, progress)
    else:
        if args.bushing_model is None:
            raise InputError("a bench dataset needs the baseline law: --bushing-model SET (a parameter set name or "
                             "YAML path)", source=str(args.rigdir))
        result, written, sentence, summary = _bench(args, progress)
    if args.json:
        print(json.dumps(summary(result)))
    else:
        print(sentence(result))
        for path in written:
            print(f"wrote {path}")
    return 0


def _bench(args: argparse.Namespace, progress):
    from bushings.parameter_sets import load_parameter_set
    from vsim_diagnosis.bench_diagnosis import diagnose_bench
    from vsim_presentation.bench_report import summary, verdict_sentence, write_report
    from vsim_recordings.bench_dataset import read_bench_dataset

    result = diagnose_bench(read_bench_dataset(args.rigdir), load_parameter_set(args.bushing_model), progress=progress)
    written = write_report(result, args.output) if args.output is not None else []
    return result, written, verdict_sentence, summary


def _kc(args: argparse.Namespace, progress):
    from vehicle.model.vehicle_file import load_vehicle
    from vsim_core.shipped import DEFAULT_VEHICLE
    from vsim_cluster.executor import ClusterLost, executor
    from vsim_diagnosis.kc_diagnosis import diagnose_kc
    from vsim_presentation.kc_report import summary, verdict_sentence, write_report
    from vsim_recordings.kc_dataset import read_kc_dataset

    vehicle = load_vehicle(args.vehicle or DEFAULT_VEHICLE)
    data = read_kc_dataset(args.rigdir)
    try:
        with executor(args.scheduler, args.workers) as ex:
            result = diagnose_kc(data, vehicle, executor=ex, progress=progress)
    except ClusterLost as exc:
        print(f"vsim: {exc}: the diagnosis stopped; run it again", file=sys.stderr)
        raise SystemExit(1) from None
    written = write_report(result, vehicle, args.output, str(args.rigdir)) if args.output is not None else []
    return result, written, verdict_sentence, summary


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``diagnose`` sub-command."""
    p = subparsers.add_parser(
        "diagnose", help="name what the model misses in measured rig data (a directory with rig.yaml)",
        description="Run the baseline on exactly the tests found in the data, fit every applicable cause of the "
                    "catalogue on half of them, score it on the other half, and name the cause, or say that "
                    "nothing significant is missing, or that the mismatch is unexplained.")
    p.add_argument("rigdir", type=Path, metavar="RIGDIR")
    group = p.add_mutually_exclusive_group()
    group.add_argument("--vehicle", metavar="VEHICLE",
                       help="baseline vehicle file or built-in name (K&C datasets; default: the built-in car)")
    group.add_argument("--bushing-model", metavar="SET", help="baseline parameter set (bench datasets)")
    p.add_argument("-o", "--output", type=output_folder, metavar="REPORT_DIR",
                   help="write report.md, PNGs, diagnosis.json and extended_model.yaml here")
    p.add_argument("--json", action="store_true", help="print the verdict as one JSON object")
    add_scheduler_options(p, "K&C datasets: ")
    p.set_defaults(func=_diagnose)
