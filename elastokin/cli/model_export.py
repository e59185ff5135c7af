"""`vsim model export VEHICLE.yaml -o car.xml`: write the MJCF of a vehicle for inspection."""

from __future__ import annotations

import argparse

from elastokin.vehicle.model.definition import BUSHING_MODELS
from elastokin.cli.arguments import output_file


def _export(args: argparse.Namespace) -> int:
    from elastokin.vehicle.model.builder import build
    from elastokin.vehicle.model.elements import BuildOptions
    from elastokin.vehicle.model.statics import resolve_preloads
    from elastokin.vehicle.model.vehicle_file import load_vehicle
    from elastokin.core.files import atomic_output

    vehicle = resolve_preloads(load_vehicle(args.vehicle))
    options = (BuildOptions(rig=False, clamped=False, road=True, bushing_model=args.bushing_model) if args.road else
               BuildOptions(rig=not args.bare, clamped=not args.free, bushing_model=args.bushing_model))
    car = build(vehicle, options)
    with atomic_output(args.output) as tmp:
        tmp.write_text(car.xml())
    print(f"wrote {args.output}: {car.model.nbody - 1} bodies, {car.model.nv} DOF, "
          f"{len(car.channels)} bushing directions, {car.model.neq} equality constraints")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``export`` (of the ``model`` group)."""
    export = subparsers.add_parser("export", help="write the MJCF of a vehicle definition")
    export.add_argument("vehicle", help="vehicle file, or the name of a built-in one (c_segment)")
    export.add_argument("-o", "--output", type=output_file, required=True, help="MJCF file to write")
    export.add_argument("--bushing-model", choices=BUSHING_MODELS, default=None,
                        help="read every bushing parameter set as this model")
    mounting = export.add_mutually_exclusive_group()
    mounting.add_argument("--road", action="store_true", help="mounted on the road: free body, steered rack, "
                                                              "ground plane (the tyres' forces are not in the MJCF)")
    mounting.add_argument("--bare", action="store_true", help="without the K&C rig")
    export.add_argument("--free", action="store_true", help="free body instead of clamped (on the rig or --bare)")
    export.set_defaults(func=_export)
