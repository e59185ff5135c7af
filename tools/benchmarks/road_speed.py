"""Benchmark of the car on the road (issue 26): speed beside the rig, and the step steer's
accuracy when the time step halves.

``python tools/benchmarks/road_speed.py [--json] [--timestep H]`` prints one JSON object:

* ``rtf_road_stvs``, ``rtf_rig_stvs``: simulated time / wall time of the compiled stepping, every
  bushing direction STVS (36 channels), 4 s per run, best of three, road and rig alternating in
  one process: the car at 80 km/h in a steady 34° turn on its four transient MF 6.1 tyres, and
  the same car on the K&C rig holding its pads; ``ratio_road_to_rig``: their step-time ratio;
* ``end_to_end_rtf``: simulated time / wall time of ``road/step_steer`` played and kept in memory
  (every sample measured, as ``vsim run`` does, without the file), STVS everywhere;
* ``yaw_rate_response_time_ms`` at the step steer's own step (``step_steer_timestep_s``, 5/3 ms at
  its 200 Hz) and at half of it, and ``response_time_change_on_half_step_ms``, the same for the
  lateral acceleration and the front toe lag (ISO 7401, the left case of ``road/step_steer`` with
  STVS everywhere); ``steady_ay_change_on_half_step`` (relative). ``--timestep`` sets the speed runs' H.

Targets (issue 26): rtf_road_stvs ≥ 10; the yaw-rate response time moves by < 1 ms when H halves.
The front toe lag is a 90 % crossing on a slow slope of a small signal: it moves more.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace

import numpy as np

from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.schedule import timestep
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.vehicle.simulation.rig import KCRig
from elastokin.vehicle.simulation.road import RoadCar
from elastokin.analysis.road_metrics import road_metrics
from elastokin.recordings.recorder import simulate

SECONDS = 4.0
SPEED = 80 / 3.6
STEER = math.radians(34.0)


def road_seconds(car: RoadCar, n: int) -> float:
    u = car.drive_inputs(np.full(n, STEER), np.full(n, SPEED))
    t0 = time.perf_counter()
    car.play(u)
    return time.perf_counter() - t0


def rig_seconds(rig: KCRig, n: int) -> float:
    t0 = time.perf_counter()
    rig.step(n)
    return time.perf_counter() - t0


def speed(h: float) -> dict[str, float]:
    options = BuildOptions(bushing_model="stvs", timestep=h)
    vehicle = load_vehicle("c_segment")
    car, rig = RoadCar(vehicle, options=options), KCRig(vehicle, options)
    car.set_brakes(500.0)
    car.step(round(1.0 / h))
    car.set_brakes(0.0)
    car.set_speed(SPEED)
    n = round(SECONDS / h)
    road_seconds(car, n)      # warm up: the turn established
    rig_seconds(rig, n)
    road, rig_t = [], []
    for _ in range(3):
        road.append(road_seconds(car, n))
        rig_t.append(rig_seconds(rig, n))
    return {"rtf_road_stvs": SECONDS / min(road), "rtf_rig_stvs": SECONDS / min(rig_t),
            "ratio_road_to_rig": min(road) / min(rig_t)}


def accuracy(h: float | None = None) -> dict[str, float]:
    """The step steer's figures at step ``h`` (default: the scenario's own) and at h/2."""
    scenario = replace(load_scenario("road/step_steer"), bushing_model="stvs")
    scenario = replace(scenario, cases=scenario.cases[:1])
    out: dict[str, float] = {}
    h = timestep(scenario) if h is None else h
    out["step_steer_timestep_s"] = h
    metrics = []
    for step in (h, h / 2):
        t0 = time.perf_counter()
        run = simulate(scenario, timestep_s=step)
        wall = time.perf_counter() - t0
        if step == h:
            out["end_to_end_rtf"] = float(run.t_s[-1]) / wall
        metrics.append(road_metrics(run)[1])
    coarse, fine = metrics
    for key in ("yaw_rate_response_time_s", "lateral_acceleration_response_time_s", "front_toe_lag_s"):
        name = key.removesuffix("_s")
        out[f"{name}_ms"] = 1e3 * coarse[key]
        out[f"{name}_ms_half_step"] = 1e3 * fine[key]
        out[f"{name}_change_on_half_step_ms"] = 1e3 * abs(coarse[key] - fine[key])
    out["steady_ay_change_on_half_step"] = abs(coarse["steady_lateral_acceleration_mps2"]
                                               / fine["steady_lateral_acceleration_mps2"] - 1.0)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="one JSON object (the default prints it indented)")
    parser.add_argument("--timestep", type=float, default=BuildOptions.timestep, metavar="H", help="time step [s]")
    args = parser.parse_args()
    result = {"timestep_s": args.timestep, **speed(args.timestep), **accuracy()}
    print(json.dumps(result) if args.json else json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
