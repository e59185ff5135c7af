"""Where MuJoCo's step spends its time on the K&C rig (issue 28): MuJoCo's own timers over a pumping
ramp with STVS on all 36 bushing directions.

``python tools/benchmarks/step_timers.py [--json] [--timestep H]`` prints, for each of MuJoCo's
timers that ran, its calls, its time per step [µs] and its share of ``mj_step``; and the wall time
per step of the whole compiled loop (coupling and bushings included) for comparison. The timers
call back into Python (``mujoco.set_mjcb_time``), which slows the step: read the shares, not the
absolute figures.
"""

from __future__ import annotations

import argparse
import json
import time

import mujoco
import numpy as np

from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.simulation.rig import KCRig

RAMP_S, AMPLITUDE_M = 2.5, 0.06   #: a quarter of the benchmark's pumping period


def timers(h: float) -> dict[str, object]:
    """The figures at time step ``h`` [s]."""
    rig = KCRig(load_vehicle(), BuildOptions(bushing_model="stvs", timestep=h))
    m, d = rig.model, rig.data
    rig.step(200)
    steps = round(RAMP_S / h)
    started = time.perf_counter()
    rig.ramp(RAMP_S, pads=(np.zeros(4), np.full(4, AMPLITUDE_M)))
    loop_us = 1e6 * (time.perf_counter() - started) / steps
    rig.ramp(RAMP_S, pads=(np.full(4, AMPLITUDE_M), np.zeros(4)))   # back, to time the same ramp again
    for timer in d.timer:
        timer.duration, timer.number = 0.0, 0
    mujoco.set_mjcb_time(time.perf_counter)
    try:
        rig.ramp(RAMP_S, pads=(np.zeros(4), np.full(4, AMPLITUDE_M)))
    finally:
        mujoco.set_mjcb_time(None)
    step = d.timer[mujoco.mjtTimer.mjTIMER_STEP].duration
    shares = {mujoco.mjtTimer(i).name.removeprefix("mjTIMER_").lower():
              {"calls": int(t.number), "us_per_step": 1e6 * t.duration / steps, "share_of_step": t.duration / step}
              for i, t in enumerate(d.timer) if t.number}
    return {"timestep_s": h, "loop_us_per_step": loop_us, "nv": int(m.nv), "nefc": int(d.nefc),
            "solver_iterations_last_step": int(d.solver_niter[0]), "timers": shares}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print one JSON object (default: a table)")
    parser.add_argument("--timestep", type=float, default=BuildOptions.timestep, help="time step H [s] (default: %(default)s)")
    args = parser.parse_args()
    result = timers(args.timestep)
    if args.json:
        print(json.dumps(result))
        return 0
    print(f"time step {result['timestep_s']} s: the compiled loop takes {result['loop_us_per_step']:.1f} µs a step "
          f"(nv {result['nv']}, {result['nefc']} constraint rows, {result['solver_iterations_last_step']} solver "
          f"iterations on the last step)")
    for name, t in result["timers"].items():
        print(f"  {name:<18} {t['calls']:>7} calls {t['us_per_step']:8.2f} µs/step {t['share_of_step']:7.1%} of mj_step")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
