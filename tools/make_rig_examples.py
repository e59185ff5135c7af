"""Regenerate the shipped measured examples in data/rig/ with the virtual rig.

    python tools/make_rig_examples.py              # writes data/rig/bench, kc and kc_csv (overwrites)
    python tools/make_rig_examples.py kc           # only data/rig/kc (seven K&C cases: about half a minute)
    python tools/make_rig_examples.py kc --output-dir /tmp/rig    # elsewhere

``kc_csv`` is shipped as a rig delivers it: each test's CSV export and META in SAE signs (`vsim rig
export`), the recordings measured by the virtual rig left out.

The truths live in tools/truths/, not beside the data, so that the datasets do not reveal them.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TRUTHS = ROOT / "tools" / "truths"
#: Dataset name (its folder in data/rig/) -> the truth it is measured on.
EXAMPLES = {"bench": TRUTHS / "bench_example.yaml", "kc": TRUTHS / "kc_example.yaml",
            "kc_csv": TRUTHS / "kc_csv_example.yaml"}
#: Datasets shipped as a rig's CSV exports, in this sign convention.
EXPORTED = {"kc_csv": "sae"}


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
        if name in EXPORTED:
            with tempfile.TemporaryDirectory() as tmp:
                status = (vsim(["rig", "measure", str(EXAMPLES[name]), "-o", tmp, "--overwrite"])
                          or vsim(["rig", "export", tmp, "-o", str(args.output_dir / name), "--convention",
                                   EXPORTED[name], "--overwrite"]))
        else:
            status = vsim(["rig", "measure", str(EXAMPLES[name]), "-o", str(args.output_dir / name), "--overwrite"])
        if status:
            return status
    return 0


if __name__ == "__main__":
    sys.exit(main())
