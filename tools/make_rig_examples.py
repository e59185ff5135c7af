"""Regenerate the shipped measured examples in data/rig/ with the virtual rig.

    python tools/make_rig_examples.py          # writes data/rig/bench (overwrites)

The truths live in tools/truths/, not beside the data, so that the datasets do not reveal them.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = {"bench": ROOT / "tools" / "truths" / "bench_example.yaml"}


def main() -> int:
    from vehicle.cli import main as vsim

    for name, truth in EXAMPLES.items():
        status = vsim(["rig", "measure", str(truth), "-o", str(ROOT / "data" / "rig" / name), "--overwrite"])
        if status:
            return status
    return 0


if __name__ == "__main__":
    sys.exit(main())
