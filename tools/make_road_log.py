"""Regenerate the shipped road-test log, scenarios/road/logs/step_steer_left.csv, that
scenarios/road/measured_steer.yaml replays.

    python tools/make_road_log.py                      # overwrites the shipped log (about 5 s)
    python tools/make_road_log.py --output /tmp/log.csv

The "test car" is the default car with every bushing direction STVS (the rubber's hysteresis and
relaxation that the filed laws leave out) driven through road/step_steer's left case; the log is
written as a data logger gives it: its own column names and units, the steering positive to the
right (as many steering robots log it), a clock that does not start at 0, a second of straight
running before the step, 200 Hz, and sensor noise drawn from a fixed seed (levels below).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUTPUT = ROOT / "scenarios" / "road" / "logs" / "step_steer_left.csv"
SEED = 20091
#: Seconds of straight running kept before the step, and the logger's clock at the first sample [s].
LEAD_S, CLOCK_S = 1.0, 417.25
#: The logger's columns: header → (road-run signal, factor from the run's unit, noise σ in the
#: column's unit: an optical steering encoder, a GNSS speed, a MEMS gyro and accelerometer).
COLUMNS = {"SWA_deg": ("steering_wheel", -1.0, 0.05), "Vx_kph": ("speed", 1.0, 0.05),
           "YawRate_degps": ("yaw_rate", 1.0, 0.1), "Ay_g": ("lateral_acceleration", 1.0 / 9.80665, 0.003),
           "Roll_deg": ("roll", 1.0, 0.02)}


def main(argv: list[str] | None = None) -> int:
    from elastokin.recordings.recorder import simulate
    from elastokin.vehicle.scenarios.scenario_file import load_scenario

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=OUTPUT, help=f"the CSV to write (default {OUTPUT})")
    args = parser.parse_args(argv)
    scenario = load_scenario("road/step_steer")
    scenario = dataclasses.replace(scenario, bushing_model="stvs", cases=scenario.cases[:1])
    run = simulate(scenario)
    case = run.metadata.extra["cases"][0]
    keep = (run.t_s >= case["input_start_s"] - LEAD_S - 1e-9) & (run.t_s <= case["end_s"] + 1e-9)
    rng = np.random.default_rng(SEED)
    columns = {"Time_s": np.round(run.t_s[keep] - run.t_s[keep][0] + CLOCK_S, 6)}
    for name, (signal, factor, sigma) in COLUMNS.items():
        columns[name] = run.signals[signal][keep] * factor + rng.normal(0.0, sigma, keep.sum())
    args.output.parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(args.output, np.column_stack(list(columns.values())), delimiter=",", header=",".join(columns),
               comments="", fmt="%.6f")
    print(f"wrote {args.output}: {keep.sum()} samples over {math.fsum(np.diff(columns['Time_s'])):.3f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
