"""`vsim bushing import F.bus -o DIR`: an Adams bushing property file as one parameter set per direction."""

from __future__ import annotations

import argparse
from pathlib import Path

from elastokin.cli.arguments import output_folder


def _import(args: argparse.Namespace) -> int:
    from elastokin.bushings.adams_bus import read_bus
    from elastokin.bushings.parameter_sets import save_parameter_set
    from elastokin.core.errors import InputError

    bus = read_bus(args.property_file)
    targets = {d: args.output / f"{bus.path.stem}_{d}.yaml" for d in bus.directions}
    existing = [str(p) for p in targets.values() if p.exists()]
    if existing and not args.overwrite:
        raise InputError(f"the output exists ({', '.join(existing)}); pass --overwrite to replace it",
                         source=str(args.output))
    args.output.mkdir(parents=True, exist_ok=True)
    for direction, target in targets.items():
        save_parameter_set(bus.parameter_set(direction), target)
        print(f"wrote {target}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``import`` (of the ``bushing`` group)."""
    p = subparsers.add_parser(
        "import", help="read an Adams bushing property file (.bus) into parameter sets, one per direction",
        description="Read F.bus (TeimOrbit: [UNITS] in any of Adams's units, [DAMPING], [FX_CURVE] ... [TZ_CURVE] "
                    "with or without their {disp force} line) and write DIR/<F>_<direction>.yaml for each curve: "
                    "a `curve` law (the monotone cubic through the points, straight on beyond them) with the "
                    "direction's damping as a linear dashpot, in N, mm, s (N·m, deg, s for rotations). A vehicle "
                    "file takes the .bus itself too (`property_file:` on a bushing or a direction).")
    p.add_argument("property_file", type=Path, metavar="F.bus")
    p.add_argument("-o", "--output", type=output_folder, required=True, metavar="DIR", help="folder for the sets")
    p.add_argument("--overwrite", action="store_true", help="replace existing sets")
    p.set_defaults(func=_import)
