"""Regenerate the shipped measured examples in data/rig/ with the virtual rig.

    python tools/make_rig_examples.py              # writes data/rig/bench and data/rig/kc (overwrites)
    python tools/make_rig_examples.py kc           # only data/rig/kc (seven K&C cases: about half a minute)
    python tools/make_rig_examples.py kc --output-dir /tmp/rig    # elsewhere

The truths live in tools/truths/, not beside the data, so that the datasets do not reveal them.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TRUTHS = ROOT / "tools" / "truths"
#: Dataset name (its folder in data/rig/) -> the truth it is measured on.
EXAMPLES = {"bench": TRUTHS / "bench_example.yaml", "kc": TRUTHS / "kc_example.yaml"}


def main(argv: list[str] | None = None) -> int:
    from elastokin.cli.main import main as vsim

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", metavar="NAME",
                        help=f"datasets to make (default: all of {', '.join(EXAMPLES)})")
    parser.add_argument("--output-dir", type=Path, default=ROOT / "data" / "rig",
                        help="where the datasets go (default: data/rig)")
    args = parser.parse_args(argv)
    unknown = [n for n in args.names if n not in EXAMPLES]
    if unknown:
        parser.error(f"unknown dataset {unknown[0]!r}; expected one of {', '.join(EXAMPLES)}")
    for name in args.names or list(EXAMPLES):
        status = vsim(["rig", "measure", str(EXAMPLES[name]), "-o", str(args.output_dir / name), "--overwrite"])
        if status:
            return status
    return 0


if __name__ == "__main__":
    sys.exit(main())
