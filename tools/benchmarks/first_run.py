"""Benchmark of the first run after an install (issue 49): the README's main job on a fresh install.

``python tools/benchmarks/first_run.py [--json] [--keep DIR]`` builds the wheel from this checkout,
installs it (with its dependencies, from the package index or pip's cache) into a new virtual
environment, runs ``vsim compile`` there (the README's first command does), then ``vsim run
pumping`` twice from an empty folder, each in a fresh process. It prints one JSON object:

* ``compile_s``: the wall time of ``vsim compile`` (once after an install);
* ``first_wall_s``, ``second_wall_s``: each run's wall time, from its process's start to its end;
  ``ratio`` = first / second (target: at most 2);
* ``first_stepping_s``, ``second_stepping_s``: the part each spent in the compiled stepping loop,
  as the command reports it;
* ``same_recording``: whether the two runs' MCAP files are the same, byte for byte;
* ``without_compile_wall_s``: the wall time of a first run in a second fresh environment where
  ``vsim compile`` was not run (the run compiles its kernels itself, and says so), and
  ``compiled``: what it compiled, by module: its ``functions``, their ``signatures`` and the
  ``seconds`` spent on each module's own (a callee compiled into its caller counted once), from
  numba's compile events;
* ``install_s``: how long the build and install took (not part of the ratio).
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from processes import run_measured

ROOT = Path(__file__).resolve().parents[2]
COMMAND = ["run", "pumping", "-o", "pumping.mcap", "--overwrite"]
#: Run in the fresh environment: the command with numba's compile events recorded, then their tally.
_COMPILES = """
import collections, json, sys, time
from numba.core import event
stack, tally = [], collections.defaultdict(lambda: {"functions": set(), "signatures": 0, "seconds": 0.0})
class Listener(event.Listener):
    # compiles nest (a callee compiled into its caller): each is counted with its own time only
    def on_start(self, e):
        stack.append([e.data["dispatcher"].py_func, time.perf_counter(), 0.0])
    def on_end(self, e):
        func, started, inner = stack.pop()
        took = time.perf_counter() - started
        if stack:
            stack[-1][2] += took
        entry = tally[func.__module__]
        entry["functions"].add(func.__qualname__)
        entry["signatures"] += 1
        entry["seconds"] += took - inner
event.register("numba:compile", Listener())
from elastokin.cli.main import main
status = main(sys.argv[1:])
print(json.dumps({m: {"functions": len(e["functions"]), "signatures": e["signatures"], "seconds": round(e["seconds"], 2)}
                  for m, e in sorted(tally.items(), key=lambda kv: -kv[1]["seconds"])}))
sys.exit(status)
"""


def _venv(folder: Path) -> tuple[Path, float]:
    """A new virtual environment in ``folder`` with the wheel of this checkout installed; its
    python and how long the build and install took [s]."""
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "venv", str(folder)], check=True)
    python = folder / "bin" / "python"
    source = folder / "source"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(".git", ".venv", "build", "*.egg-info", "out",
                                                                 "__pycache__", ".hypothesis"))
    subprocess.run([str(python), "-m", "pip", "install", "-q", str(source)], check=True, capture_output=True)
    shutil.rmtree(source)
    return python, time.perf_counter() - started


def _stepping_s(stdout: str) -> float | None:
    """The compiled stepping time the command printed (``compiled stepping 2.87 s``)."""
    for line in stdout.splitlines():
        if "compiled stepping" in line:
            return float(line.split("compiled stepping ")[1].split(" s")[0])
    return None


def measure(keep: Path | None) -> dict:
    """Both runs in one fresh environment, and the compile tally in another."""
    base = Path(tempfile.mkdtemp(prefix="first_run_")) if keep is None else keep
    python, install_s = _venv(base / "venv")
    vsim = str(base / "venv" / "bin" / "vsim")
    compiled_once = run_measured([vsim, "compile"], cwd=str(base))
    if compiled_once.returncode != 0:
        raise SystemExit(f"vsim compile failed:\n{compiled_once.stderr[-2000:]}")
    walls, steppings, files = [], [], []
    for k in range(2):
        empty = base / f"run{k}"
        empty.mkdir()
        done = run_measured([vsim, *COMMAND], cwd=str(empty))
        if done.returncode != 0:
            raise SystemExit(f"vsim run failed:\n{done.stderr[-2000:]}")
        walls.append(done.wall_s)
        steppings.append(_stepping_s(done.stdout))
        files.append((empty / "pumping.mcap").read_bytes())
    python_b, _ = _venv(base / "venv_tally")
    tally_dir = base / "tally"
    tally_dir.mkdir()
    tally = run_measured([str(python_b), "-c", _COMPILES, *COMMAND], cwd=str(tally_dir))
    compiled = json.loads(tally.stdout.strip().splitlines()[-1]) if tally.returncode == 0 else {"error": tally.stderr[-500:]}
    if keep is None:
        shutil.rmtree(base)
    return {"compile_s": round(compiled_once.wall_s, 1), "first_wall_s": round(walls[0], 2), "second_wall_s": round(walls[1], 2),
            "ratio": round(walls[0] / walls[1], 2), "first_stepping_s": steppings[0], "second_stepping_s": steppings[1],
            "same_recording": files[0] == files[1], "install_s": round(install_s, 1),
            "without_compile_wall_s": round(tally.wall_s, 2), "compiled": compiled}


def main() -> None:
    """Print the figures (JSON with --json, else one line each)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--keep", type=Path, metavar="DIR", help="build in DIR and keep it (default: a temporary folder)")
    args = parser.parse_args()
    figures = measure(args.keep)
    print(json.dumps(figures) if args.json else "\n".join(f"{k}: {v}" for k, v in figures.items()))


if __name__ == "__main__":
    main()
