"""Wall time of `vsim diagnose` on the shipped measured datasets (issue 5's benchmark).

    python tools/benchmarks/diagnosis_speed.py [--json]

Targets on the project's 2-core machine: <= 1 minute for the bushing-bench dataset (data/rig/bench),
<= 10 minutes for the K&C dataset (data/rig/kc, when shipped); issue 28: <= 10 s for the bench.
Each diagnosis runs in a fresh process, as a user would run it (numba's compiled kernels come from
its on-disk cache); ``*_peak_rss_mb`` is that process's peak resident memory.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from processes import run_measured

ROOT = Path(__file__).resolve().parents[2]
DATASETS = {
    "bench": (ROOT / "data" / "rig" / "bench", ["--bushing-set", "fig5_9_progressive"], 60.0),
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
        done = run_measured([sys.executable, "-m", "elastokin", "diagnose", str(path), *baseline, "--json"])
        if done.returncode:
            print(done.stderr, file=sys.stderr)
            return done.returncode
        figures[f"{name}_wall_s"] = round(done.wall_s, 1)
        figures[f"{name}_target_s"] = target
        figures[f"{name}_peak_rss_mb"] = round(done.peak_rss_mb)
        figures[f"{name}_cause"] = json.loads(done.stdout)["cause"]
    if args.json:
        print(json.dumps(figures))
    else:
        for key, value in figures.items():
            print(f"{key:>16}: {value}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
