"""`vsim list` (every built-in by kind) and `vsim copy NAME DIR` (an editable copy of one)."""

from __future__ import annotations

import argparse

from elastokin.cli.arguments import output_folder


def _list(args: argparse.Namespace) -> int:
    from elastokin.api.built_ins import KINDS, built_ins

    names = built_ins()
    for kind in KINDS:
        if args.kind in (None, kind.name):
            print(f"{kind.name}: {kind.about}")
            for name in names[kind.name]:
                print(f"  {name}")
    print("Name one where a file is asked for (vsim run road/step_steer); `vsim copy NAME DIR` makes an editable copy.")
    return 0


def _copy(args: argparse.Namespace) -> int:
    from elastokin.api.built_ins import copy_built_in

    for path in copy_built_in(args.name, args.folder, overwrite=args.overwrite):
        print(f"wrote {path}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``list`` and ``copy``."""
    from_kinds = ("vehicles", "bushing sets", "bushing property files", "tyres", "scenarios", "sweeps",
                  "bench programmes", "datasets")
    listing = subparsers.add_parser(
        "list", help="the built-in vehicles, scenarios, bushing sets, tyres, sweeps, bench programmes and datasets",
        description="Every file shipped with the software that a command takes by name instead of a path.")
    listing.add_argument("kind", nargs="?", choices=from_kinds, metavar="KIND",
                         help=f"only this kind ({', '.join(from_kinds)})")
    listing.set_defaults(func=_list)
    copy = subparsers.add_parser(
        "copy", help="copy a built-in into a folder, to edit it",
        description="Copy a built-in (a name `vsim list` prints) into DIR, with what it needs to run from there: a "
                    "vehicle with its tyre's property file; a scenario or sweep naming its vehicle by name; a "
                    "dataset whole. Write `KIND:NAME` where two kinds share a name.")
    copy.add_argument("name", metavar="NAME")
    copy.add_argument("folder", type=output_folder, metavar="DIR")
    copy.add_argument("--overwrite", action="store_true", help="replace files of the same names in DIR")
    copy.set_defaults(func=_copy)
