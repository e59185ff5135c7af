"""Wall time of `vsim diagnose` on the shipped measured datasets (issue 5's benchmark).

    python tools/benchmarks/diagnosis_speed.py [--json]

Targets on the project's 2-core machine: <= 1 minute for the bushing-bench dataset (data/rig/bench),
<= 10 minutes for the K&C dataset (data/rig/kc, when shipped). Each diagnosis runs in a fresh
process, as a user would run it (numba's compiled kernels come from its on-disk cache).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DATASETS = {
    "bench": (ROOT / "data" / "rig" / "bench", ["--bushing-model", "fig5_9_progressive"], 60.0),
    "kc": (ROOT / "data" / "rig" / "kc", ["--vehicle", str(ROOT / "models" / "vehicles" / "c_segment.yaml")], 600.0),
}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args()
    figures: dict[str, object] = {}
    for name, (path, baseline, target) in DATASETS.items():
        if not path.is_dir():
            figures[f"{name}_wall_s"] = None
            figures[f"{name}_note"] = f"{path.relative_to(ROOT)} is not shipped yet"
            continue
        started = time.perf_counter()
        done = subprocess.run([sys.executable, "-m", "vsim_cli", "diagnose", str(path), *baseline, "--json"],
                              capture_output=True, text=True)
        wall = time.perf_counter() - started
        if done.returncode:
            print(done.stderr, file=sys.stderr)
            return done.returncode
        figures[f"{name}_wall_s"] = round(wall, 1)
        figures[f"{name}_target_s"] = target
        figures[f"{name}_cause"] = json.loads(done.stdout)["cause"]
    if args.json:
        print(json.dumps(figures))
    else:
        for key, value in figures.items():
            print(f"{key:>16}: {value}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
