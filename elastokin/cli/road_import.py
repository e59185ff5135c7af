"""`vsim road import SCENARIO -o ROAD.mcap`: a measured_steer scenario's logs as a measured road run."""

from __future__ import annotations

import argparse

from elastokin.cli.arguments import output_file


def _import(args: argparse.Namespace) -> int:
    from elastokin.vehicle.scenarios.scenario_file import load_scenario
    from elastokin.recordings.road_recordings import logged_channels, write_road_recording
    from elastokin.recordings.run_reader import load_run

    scenario = load_scenario(args.scenario)
    run = load_run(write_road_recording(args.output, scenario, overwrite=args.overwrite))
    print(f"wrote {run.path}: {len(run.metadata.extra['cases'])} case(s) of {scenario.name}, "
          f"{', '.join(logged_channels(scenario))}; compare it with `vsim run {args.scenario}`'s run: "
          f"vsim compare SIM.mcap {run.path}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``import`` (of the ``road`` group)."""
    p = subparsers.add_parser(
        "import", help="a measured_steer scenario's logs as a measured road run (.mcap)",
        description="Read every case's CSV log of a measured_steer road scenario (scenarios/README.md, "
                    "\"Measured manoeuvres\") as the scenario declares it, resampled as the car gets its input, "
                    "and write them as one road-test recording on the time axis of a simulated run of the "
                    "scenario, read by vsim compare, plot and view like a simulated run. Nothing is written on "
                    "error.")
    p.add_argument("scenario", metavar="SCENARIO", help="measured_steer scenario file (or a built-in one)")
    p.add_argument("-o", "--output", type=output_file, required=True, metavar="ROAD.mcap",
                   help="road-test recording to write")
    p.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    p.set_defaults(func=_import)
