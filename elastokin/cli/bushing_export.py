"""`vsim bushing export SET [SET] -o F.bus`: laws of this library as an Adams bushing property file."""

from __future__ import annotations

import argparse
import math

from elastokin.cli.arguments import output_file


def _export(args: argparse.Namespace) -> int:
    from elastokin.bushings.adams_bus import CURVES, write_bus
    from elastokin.bushings.bench.bus_export import SLOW_RATE, compare, comparison_lines, export
    from elastokin.bushings.parameter_sets import load_parameter_set
    from elastokin.core.errors import InputError
    from elastokin.core.provenance import software_version

    for option in ("range", "damping_hz", "damping_at"):
        value = getattr(args, option)
        if not (math.isfinite(value) and value > 0.0):
            raise InputError(f"expected a positive number, got {value!r}", key=f"--{option.replace('_', '-')}")
    sets = [load_parameter_set(name) for name in args.sets]
    by_quantity = {}
    for name, pset in zip(args.sets, sets):
        if pset.quantity in by_quantity:
            raise InputError(f"a second {pset.quantity} set; expected at most one translation set (FX, FY, FZ) and "
                             f"one rotation set (TX, TY, TZ)", source=name)
        by_quantity[pset.quantity] = pset
    directions, notes = {}, []
    for quantity, pset in by_quantity.items():
        unit = "mm" if quantity == "translation" else "deg"
        channel = pset.channel()
        names = [c for c, d in CURVES.items() if (len(d) == 1) == (quantity == "translation")]
        made = export(channel, CURVES[names[0]], args.range, args.damping_hz, args.damping_at)
        for name in names:
            directions[CURVES[name]] = type(made.direction)(CURVES[name], made.direction.curve, made.direction.damping)
        lines = comparison_lines(compare(channel, made), quantity)
        notes += [f"{'/'.join(names)}: {pset.name} ({pset.model}; {pset.source})",
                  f"  curve: centre line of the slow loop ({SLOW_RATE * 60:g} {unit}/min triangle) over "
                  f"+-{args.range:g} {unit}, straight on beyond; damping: equivalent viscous at {args.damping_hz:g} Hz, "
                  f"{args.damping_at:g} {unit}",
                  "  not carried: hysteresis at vanishing rates, relaxation, the Payne effect (amplitude), frequency "
                  "dependence away from that point" + (", the set's effects" if pset.effects else ""),
                  *(f"  {line}" for line in lines)]
        print(f"{'/'.join(names)} from {pset.name}:")
        print("\n".join(f"  {line}" for line in lines))
    comments = [f"written by vsim (elastokin {software_version()}) from {', '.join(s.name for s in sets)}"]
    write_bus(args.output, directions, comments, notes, overwrite=args.overwrite)
    print(f"wrote {args.output}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``export`` (of the ``bushing`` group)."""
    p = subparsers.add_parser(
        "export", help="write bushing laws as an Adams bushing property file (.bus)",
        description="Write a translation set as the FX, FY, FZ curves and a rotation set as TX, TY, TZ: each "
                    "curve the centre line of the law's slow loop (the thesis's 20 mm/min triangle, fig. 5.6) over "
                    "the range, each damping the equivalent viscous coefficient Im K*/omega of the law's first "
                    "harmonic at one frequency and amplitude. The file's comments say what a curve and a dashpot "
                    "cannot carry, and the law and its export side by side on the bench: K_dyn and tan delta at "
                    "1 and 10 Hz, 0.1 and 1 mm (deg), and the slow loop's width (printed too).")
    p.add_argument("sets", nargs="+", metavar="SET", help="parameter sets (names or YAML paths): one translation, "
                                                          "one rotation at most")
    p.add_argument("-o", "--output", type=output_file, required=True, metavar="F.bus")
    p.add_argument("--range", type=float, default=2.0, metavar="MM_OR_DEG",
                   help="the curve's half range, mm or deg (default 2)")
    p.add_argument("--damping-hz", type=float, default=1.0, metavar="HZ",
                   help="frequency the damping is matched at (default 1)")
    p.add_argument("--damping-at", type=float, default=1.0, metavar="MM_OR_DEG",
                   help="amplitude the damping is matched at, mm or deg (default 1)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    p.set_defaults(func=_export, compiles=True)
