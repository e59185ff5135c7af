"""`vsim run SCENARIO`: play a scenario (on the K&C rig or the road) with a progress line, record it, print its summary."""

from __future__ import annotations

import argparse
import sys
import time

from elastokin.vehicle.model.definition import BUSHING_MODELS
from elastokin.cli.arguments import output_file, positive_scale
from elastokin.cli.interrupts import status as interrupt_status


def _run(args: argparse.Namespace) -> int:
    from elastokin.api.simulation import Simulation
    from elastokin.core.files import check_output
    from elastokin.presentation.progress_bar import ProgressBar
    from elastokin.presentation.run_summary import summary
    from elastokin.recordings.recorder import default_output
    from elastokin.recordings.run_reader import load_run
    from elastokin.vehicle.simulation.runner import DivergenceError

    simulation = Simulation(None, args.scenario, bushings=args.bushing_model, duration_scale=args.duration_scale)
    output = args.output or check_output(default_output(simulation.scenario))
    bar = ProgressBar()
    status, note, run = 0, "", None
    started = time.perf_counter()
    try:
        played = simulation.run(progress=bar, output=output, overwrite=args.overwrite)
        run, timing = played.recorded, played.timing
        note = f"({timing.simulated_s:.1f} s simulated in {timing.wall_s:.1f} s, {timing.real_time_factor:.1f}x real " \
               f"time; compiled stepping {timing.stepping_s:.2f} s)"
    except DivergenceError as exc:
        status, note = 1, f"stopped: {exc}"
    except KeyboardInterrupt as exc:
        status, note = interrupt_status(exc), f"interrupted ({exc or 'SIGINT'}) after {time.perf_counter() - started:.0f} s"
    finally:
        bar.close()
    if status:
        kept = f"the incomplete recording is kept in {output}" if output.exists() else "nothing was recorded"
        print(f"vsim: run {note}; {kept}", file=sys.stderr)
    if output.exists():
        print(summary(run or load_run(output)))   # a stopped run is summarised from what the file kept
        print(f"wrote {output} {note if not status else '(incomplete)'}")
    return status


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``run``."""
    run = subparsers.add_parser(
        "run", help="play a scenario (.yaml) on the K&C rig or the road and record it (.mcap)",
        description="Run every case of a scenario file (format: scenarios/README.md) and record them in one "
                    "MCAP file; print a summary (gradients and loop widths, K&C metrics, relaxation, peak bushing "
                    "deflections).")
    run.add_argument("scenario", metavar="SCENARIO",
                     help="scenario file, or the name of a built-in one (pumping, kc/roll, road/step_steer: `vsim list`)")
    run.add_argument("-o", "--output", type=output_file, metavar="OUT.mcap", help="run file (default: out/<scenario>.mcap)")
    run.add_argument("--bushing-model", choices=BUSHING_MODELS, default=None,
                     help="this bushing model on every bushing direction (overrides the scenario's `bushings`)")
    run.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    run.add_argument("--duration-scale", type=positive_scale, default=1.0, metavar="X",
                     help="multiply every duration (settle phases, periods, holds) by X, e.g. 0.1 for a quick run")
    run.set_defaults(func=_run, compiles=True)
