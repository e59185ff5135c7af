"""Benchmark of the execution layer (issue 27): the K&C diagnosis on 1 and 2 workers, the scheduling
overhead of a sweep, and what each task sends and receives.

``python tools/benchmarks/cluster_speed.py [--json] [--skip-diagnosis]`` prints one JSON object:

* ``diagnosis_1_worker_s``, ``diagnosis_2_workers_s``, ``diagnosis_speedup``: ``vsim diagnose
  data/rig/kc --workers N --json`` in a fresh process each (local Dask cluster), and whether the two
  verdicts are the same JSON but for their wall times (``diagnosis_same_verdict``);
* ``sweep_runs``, ``sweep_wall_s``, ``sweep_compute_s``, ``sweep_overhead_per_task_pct``: a 64-run
  Latin hypercube of 10 s rig runs (one pumping triangle) on a local cluster of 2 workers;
  overhead per task = (wall × workers − Σ the runs' own compute time) / runs, against the mean run;
* ``sweep_task_bytes``, ``sweep_result_bytes``, ``diagnosis_job_bytes``, ``diagnosis_result_bytes``:
  pickled sizes of one task and of its result (what crosses the network on a remote cluster).

Targets (issue 27): speed-up ≥ 1.7 on 2 cores, diagnosis ≤ 3 min; overhead per task ≤ 5 %.
Say the machine's load when quoting: the figures are wall times.
"""

from __future__ import annotations

import argparse
import json
import pickle
import sys
import tempfile
from pathlib import Path

import numpy as np

from processes import run_measured
from elastokin.cluster.executor import executor
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.diagnosis.kc_layout import Layout, run_job
from elastokin.recordings.kc_dataset import read_kc_dataset
from elastokin.sweeps.designs import design_points
from elastokin.sweeps.sweep import run_sweep
from elastokin.sweeps.sweep_file import load_sweep
from elastokin.sweeps.sweep_runs import run_point, tasks
from elastokin.vehicle.model.vehicle_file import load_vehicle

ROOT = Path(__file__).resolve().parents[2]
KC = ROOT / "data" / "rig" / "kc"
#: One 10 s pumping triangle of the front axle after 1 s of settling: a 10 s rig run.
SCENARIO = f"""name: pumping_10s
type: pumping
vehicle: {DEFAULT_VEHICLE}
axles: [front, rear]
output_rate_hz: 50
settle: {{before_bushings_s: 0.5, before_input_s: 0.5}}
cases:
  - {{amplitude_mm: 40, shape: triangle, frequency_hz: 0.111111, cycles: 1}}
"""
SWEEP = """name: overhead
scenarios: [pumping_10s.yaml]
parameters:
  front.spring.rate: {min_factor: 0.8, max_factor: 1.2}
  bushings.e2_front.y.Kr: {min_factor: 0.7, max_factor: 1.3}
design: {type: latin_hypercube, runs: 64, seed: 1}
metrics: [front.toe_loop_width_deg, front.camber_loop_width_deg]
"""


def _diagnosis(figures: dict) -> None:
    verdicts = []
    for workers in (1, 2):
        done = run_measured([sys.executable, "-m", "elastokin", "diagnose", str(KC), "--workers", str(workers),
                             "--json"])
        if done.returncode:
            raise SystemExit(done.stderr)
        key = "diagnosis_1_worker_s" if workers == 1 else "diagnosis_2_workers_s"
        figures[key] = round(done.wall_s, 1)
        verdicts.append({k: v for k, v in json.loads(done.stdout).items() if k != "wall_s"})
    figures["diagnosis_speedup"] = round(figures["diagnosis_1_worker_s"] / figures["diagnosis_2_workers_s"], 2)
    figures["diagnosis_same_verdict"] = verdicts[0] == verdicts[1]   # every number but the wall time
    figures["diagnosis_cause"] = verdicts[1]["cause"]
    layout = Layout.of(read_kc_dataset(KC), load_vehicle(DEFAULT_VEHICLE))
    job = layout.tests[0].job
    figures["diagnosis_job_bytes"] = len(pickle.dumps(job))
    figures["diagnosis_result_bytes"] = len(pickle.dumps(run_job(job)))


def _sweep(figures: dict) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "pumping_10s.yaml").write_text(SCENARIO)
        (Path(tmp) / "sweep.yaml").write_text(SWEEP)
        sweep = load_sweep(Path(tmp) / "sweep.yaml")
        points = design_points(sweep.design, np.array([p.low for p in sweep.parameters]),
                               np.array([p.high for p in sweep.parameters]))
        task = tasks(sweep, list(points), [0], None)[0]
        figures["sweep_task_bytes"] = len(pickle.dumps(task))
        figures["sweep_result_bytes"] = len(pickle.dumps(run_point(task)))
        with executor("local", 2) as ex:
            ex.map(run_point, tasks(sweep, list(points), [0, 1], None))   # the workers' imports and kernels
            report = run_sweep(sweep, Path(tmp) / "out", ex)
        workers = 2
    per_run = report.compute_s / report.runs
    figures |= {"sweep_runs": report.runs, "sweep_failed": report.failed, "sweep_wall_s": round(report.wall_s, 2),
                "sweep_compute_s": round(report.compute_s, 2), "sweep_mean_run_s": round(per_run, 3),
                "sweep_overhead_per_task_pct": round(100 * (report.wall_s * workers - report.compute_s)
                                                     / report.runs / per_run, 2)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--skip-diagnosis", action="store_true", help="the sweep figures only (seconds, not minutes)")
    args = parser.parse_args()
    figures: dict[str, object] = {}
    _sweep(figures)
    if not args.skip_diagnosis:
        _diagnosis(figures)
    if args.json:
        print(json.dumps(figures))
    else:
        for key, value in figures.items():
            print(f"{key:>30}: {value}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
