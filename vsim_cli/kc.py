"""`vsim kc [--vehicle V.yaml] [--bushings MODEL] [--json]`: standard K&C metrics of a vehicle."""

from __future__ import annotations

import argparse
import json

from vehicle.model.builder import BuildOptions
from vehicle.model.definition import DEFAULT_VEHICLE, load_vehicle
from vehicle.simulation.kc import format_table, vehicle_kc
from vsim_cli.model import BUSHING_MODELS


def _kc(args: argparse.Namespace) -> int:
    metrics = vehicle_kc(load_vehicle(args.vehicle), BuildOptions(bushing_model=args.bushings))
    print(json.dumps(metrics, indent=2) if args.json else format_table(metrics))
    return 0


def register(subparsers) -> None:
    """Add ``kc``."""
    kc = subparsers.add_parser("kc", help="K&C metrics of a vehicle on the virtual rig (spec §4)",
                               description="Runs bump, roll, lateral-force, longitudinal-force and "
                                           "aligning-torque triangles on both axles (vehicle/simulation/kc.py).")
    kc.add_argument("--vehicle", default=str(DEFAULT_VEHICLE), help="vehicle YAML file (default: %(default)s)")
    kc.add_argument("--bushings", choices=BUSHING_MODELS, default=None,
                    help="put this model on every bushing direction (models/vehicles/README.md)")
    kc.add_argument("--json", action="store_true", help="one JSON object keyed front and rear")
    kc.set_defaults(func=_kc)
