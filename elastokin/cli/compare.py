"""`vsim compare SIM.mcap RIG.mcap [-o DIR]`: a simulated run against a measured rig recording, or a
simulated road run against the road test of the same measured_steer scenario; `vsim compare --kc
DIR [--vehicle VEHICLE]`: a rig's K&C curves' metrics beside `vsim kc`'s."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from elastokin.cli.arguments import add_strict_option, add_vehicle_options, output_folder
from elastokin.core.errors import InputError


def _compare(args: argparse.Namespace) -> int:
    from elastokin.analysis.compare import compare_runs
    from elastokin.analysis.run_metrics import is_road
    from elastokin.presentation.comparison_report import format_table, write_outputs
    from elastokin.recordings.run_reader import load_run

    if args.kc is not None:
        return _compare_kc(args)
    if args.sim is None or args.rig is None:
        raise InputError("give SIM.mcap and RIG.mcap, or --kc DIR (a rig's K&C curves)", source="vsim compare")
    sim, rig = load_run(args.sim, strict=args.strict), load_run(args.rig, strict=args.strict)
    if is_road(sim):
        return _compare_road(sim, rig, args.output)
    comparison = compare_runs(sim, rig)
    print(format_table(comparison))
    if args.output is not None:
        written = write_outputs(comparison, sim, rig, args.output)
        print(f"wrote {written[0]} and {len(written) - 1} PNG(s) in {args.output}")
    return 0


def _compare_road(sim, measured, output: Path | None) -> int:
    from elastokin.analysis.road_comparison import compare_road_runs, response_errors
    from elastokin.presentation.road_comparison_report import format_errors, format_table, write_report

    variants = compare_road_runs(sim, measured)
    errors = response_errors(sim, measured)
    print(format_table(variants))
    print()
    print(format_errors(errors))
    if output is not None:
        written = write_report(variants, output, errors)
        print(f"wrote {', '.join(str(p) for p in written if p.suffix == '.csv')} and "
              f"{sum(p.suffix == '.png' for p in written)} PNG(s) in {output}")
    return 0


def _compare_kc(args: argparse.Namespace) -> int:
    from elastokin.api.vehicles import load_vehicle
    from elastokin.presentation.kc_table import format_comparison

    comparison = load_vehicle(args.vehicle).compare_kc(args.kc, args.bushing_model)
    print(json.dumps(comparison, indent=2) if args.json else format_comparison(comparison))
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``compare`` sub-command."""
    compare = subparsers.add_parser(
        "compare", help="compare a simulated run with a measured rig recording of the same scenario",
        description="Per test (case) and channel (camber, toe, steer, half-track, wheel centre, pad vertical "
                    "force of each wheel in both files): gradient, loop width at design, loop area, RMS error, "
                    "relaxation over a final hold and first-harmonic dynamic stiffness for sine inputs; "
                    "simulation, rig and their difference (elastokin/analysis/compare.py). For road runs (a "
                    "simulated measured_steer scenario against its road test, vsim road import): both runs' ISO "
                    "7401 / 4138 metrics and the responses' RMS errors (elastokin/analysis/road_comparison.py).")
    compare.add_argument("sim", type=Path, metavar="SIM.mcap", nargs="?", help="simulated run (vsim run)")
    compare.add_argument("rig", type=Path, metavar="RIG.mcap", nargs="?",
                         help="measured rig recording of the same scenario (or road test: vsim road import)")
    compare.add_argument("--kc", type=Path, metavar="DIR", default=None,
                         help="instead: a rig's K&C curves (one CSV per test, as vsim kc --curves writes them), "
                              "their metrics beside vsim kc's of --vehicle")
    add_vehicle_options(compare, "with --kc, the car measured and simulated: ")
    compare.add_argument("--json", action="store_true", help="with --kc: the table as JSON")
    compare.add_argument("-o", "--output", type=output_folder, metavar="DIR",
                         help="also write DIR/comparison.json and loop and time-history overlays (PNG); for "
                              "road runs DIR/metrics.csv, DIR/errors.csv and one overlay PNG per case")
    add_strict_option(compare)
    compare.set_defaults(func=_compare)
