"""`vsim bushings-on-road SCENARIO [--extended FILE]... [-o DIR]`: a road manoeuvre on the car with
its bushings linear, as defined, all STVS and as other vehicle files define them; metric
differences tabulated and plotted."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from elastokin.cli.arguments import output_folder, positive_scale


def _bushings_on_road(args: argparse.Namespace) -> int:
    from elastokin.vehicle.scenarios.road_scenario import RoadScenario
    from elastokin.vehicle.scenarios.scenario_file import load_scenario
    from elastokin.analysis.road_comparison import compare_variants
    from elastokin.presentation.progress_bar import ProgressBar
    from elastokin.presentation.road_comparison_report import format_table, write_report

    scenario = load_scenario(args.scenario)
    if not isinstance(scenario, RoadScenario):
        print(f"vsim: {scenario.path}: a {scenario.type} scenario runs on the K&C rig; expected a road scenario "
              f"(scenarios/road/)", file=sys.stderr)
        return 2
    bar = ProgressBar()
    try:
        variants = compare_variants(scenario, args.extended, args.duration_scale, lambda label, p: bar(p))
    finally:
        bar.close()
    print(format_table(variants))
    written = write_report(variants, args.output)
    print(f"wrote {written[0]} and {len(written) - 1} PNG(s) in {args.output}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``bushings-on-road``."""
    cmd = subparsers.add_parser(
        "bushings-on-road", help="what the bushings change on the road: one manoeuvre, several cars",
        description="Run a road scenario (scenarios/road/) with the car's bushings linear, as the scenario or "
                    "vehicle file defines them, every direction STVS, and as each --extended vehicle file "
                    "defines them (for instance the extended_vehicle.yaml of `vsim diagnose`); print the ISO "
                    "7401 / 4138 metrics of each and their differences from the linear car (times in ms); write "
                    "DIR/metrics.csv and one overlay PNG per case.")
    cmd.add_argument("scenario", metavar="SCENARIO", help="road scenario file, or a built-in one (road/step_steer)")
    cmd.add_argument("--extended", type=Path, action="append", default=[], metavar="VEHICLE.yaml",
                     help="another vehicle file to compare (repeatable)")
    cmd.add_argument("-o", "--output", type=output_folder, default=Path("out/bushings_on_road"), metavar="DIR",
                     help="where metrics.csv and the PNGs go (default out/bushings_on_road)")
    cmd.add_argument("--duration-scale", type=positive_scale, default=1.0, metavar="X",
                     help="multiply every duration by X for a quick look (rise times too)")
    cmd.set_defaults(func=_bushings_on_road, compiles=True)
