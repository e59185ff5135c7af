"""`vsim kc [--vehicle VEHICLE] [--bushing-model MODEL] [--json]`: standard K&C metrics of a vehicle."""

from __future__ import annotations

import argparse
import json

from elastokin.vehicle.model.definition import BUSHING_MODELS
from elastokin.core.shipped import DEFAULT_VEHICLE


def _kc(args: argparse.Namespace) -> int:
    from elastokin.api.vehicles import load_vehicle
    from elastokin.presentation.kc_table import format_table

    metrics = load_vehicle(args.vehicle).kc_metrics(args.bushing_model)
    print(json.dumps(metrics, indent=2) if args.json else format_table(metrics))
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``kc``."""
    kc = subparsers.add_parser("kc", help="K&C metrics of a vehicle on the virtual rig (ISO 8855 signs)",
                               description="Runs bump, roll, lateral-force, longitudinal-force and "
                                           "aligning-torque triangles on both axles (elastokin/vehicle/scenarios/kc_tests.py "
                                           "in the installed package) and prints each metric with its unit in its "
                                           "name; definitions and signs: elastokin/analysis/kc_metrics.py (METRICS).")
    kc.add_argument("--vehicle", default=DEFAULT_VEHICLE.stem, metavar="VEHICLE",
                    help="vehicle file, or the name of a built-in one (default: %(default)s)")
    kc.add_argument("--bushing-model", choices=BUSHING_MODELS, default=None,
                    help="put this model on every bushing direction (models/vehicles/README.md)")
    kc.add_argument("--json", action="store_true", help="one JSON object keyed front and rear")
    kc.set_defaults(func=_kc, compiles=True)
