"""`vsim kc [--vehicle VEHICLE] [--bushing-model MODEL] [--json] [--curves DIR]`: standard K&C metrics of a vehicle."""

from __future__ import annotations

import argparse
import json

from elastokin.cli.arguments import add_vehicle_options, output_folder


def _kc(args: argparse.Namespace) -> int:
    from elastokin.api.vehicles import load_vehicle
    from elastokin.presentation.kc_table import format_table

    metrics = load_vehicle(args.vehicle).kc_metrics(args.bushing_model, args.curves)
    print(json.dumps(metrics, indent=2) if args.json else format_table(metrics))
    if args.curves is not None and not args.json:
        print(f"wrote the curves of each test in {args.curves} (one CSV per test, units in the column names)")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``kc``."""
    kc = subparsers.add_parser("kc", help="K&C metrics of a vehicle on the virtual rig (ISO 8855 signs)",
                               description="Runs bump, roll, lateral-force, longitudinal-force and "
                                           "aligning-torque triangles on both axles and a rack sweep (elastokin/vehicle/scenarios/kc_tests.py "
                                           "in the installed package) and prints each metric with its unit in its "
                                           "name; definitions and signs: elastokin/analysis/kc_metrics.py (METRICS).")
    add_vehicle_options(kc)
    kc.add_argument("--json", action="store_true", help="one JSON object keyed front and rear")
    kc.add_argument("--curves", type=output_folder, metavar="DIR", default=None,
                    help="also write the curves behind the metrics in DIR, one CSV per test as a K&C rig "
                         "delivers them (a row per sample, a column per quantity and wheel, units in the names)")
    kc.set_defaults(func=_kc, compiles=True)
