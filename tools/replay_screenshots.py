"""Screenshots of `vsim view` replays in the real Rerun viewer: the manual check of the replay's layout.

Records a rig run (pumping) and a road run (step steer), short, writes their .rrd replays and takes a
screenshot of each in the viewer, headless under Xvfb with Mesa's software Vulkan driver (packages
``xvfb`` and ``mesa-vulkan-drivers``), saved at half size in 256 colours (about 90 kB). Look at the
PNGs: the whole car framed (on its pads on the rig; on the ground with its path on the road, followed
by the camera), the loops over the whole recording, one time-series plot per unit. The viewer starts
playing when it opens, so the time of each shot varies by a fraction of a second. The shots in
tools/replay/ were made so.

    python tools/replay_screenshots.py [-o tools/replay] [--keep-runs]
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from PIL import Image

#: (name, scenario, duration scale): one run on the K&C rig, one on the road.
RUNS = (("rig_pumping", "pumping", 0.2), ("road_step_steer", "road/step_steer", 0.3))
WINDOW = "1600x1000"
#: Xvfb's pointer rests at the screen's centre: on a screen over twice the window's size, the window
#: (at the top left corner) opens without a hover tooltip.
SCREEN = "3600x1200x24"
DISPLAY = ":97"


def _run(argv: list[str], **kwargs) -> None:
    """Run ``argv``, quietly; its error output becomes the error if it fails."""
    done = subprocess.run(argv, capture_output=True, text=True, **kwargs)
    if done.returncode:
        raise SystemExit(f"{' '.join(argv)} failed:\n{done.stderr}")


def _screenshot(rrd: Path, png: Path) -> None:
    """One shot of the viewer opened on ``rrd`` (the rerun executable beside this Python), halved."""
    rerun = shutil.which("rerun", path=str(Path(sys.executable).parent)) or "rerun"
    # RUST_LOG=error: the viewer's warnings (a container, a software renderer) would show as toasts
    env = {**os.environ, "DISPLAY": DISPLAY, "WGPU_BACKEND": "vulkan", "XDG_RUNTIME_DIR": tempfile.gettempdir(),
           "RUST_LOG": "error"}
    _run([rerun, str(rrd), "--screenshot-to", str(png), "--window-size", WINDOW], env=env, timeout=300)
    with Image.open(png) as shot:   # the viewer draws at two pixels per point
        half = shot.convert("RGB").resize((shot.width // 2, shot.height // 2), Image.Resampling.LANCZOS)
    half.quantize(256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE).save(png, optimize=True)


def main() -> int:
    """Make the runs, the replays and the screenshots; print the PNGs' paths."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("-o", "--out", type=Path, default=Path(__file__).parent / "replay")
    parser.add_argument("--keep-runs", action="store_true", help="keep the .mcap and .rrd files beside the PNGs")
    args = parser.parse_args()
    if shutil.which("Xvfb") is None:
        raise SystemExit("Xvfb is not installed (apt-get install xvfb mesa-vulkan-drivers)")
    args.out.mkdir(parents=True, exist_ok=True)
    xvfb = subprocess.Popen(["Xvfb", DISPLAY, "-screen", "0", SCREEN], stderr=subprocess.DEVNULL)
    try:
        time.sleep(1.0)  # the server accepts clients once it has opened its display
        with tempfile.TemporaryDirectory() as scratch:
            runs = args.out if args.keep_runs else Path(scratch)
            for name, scenario, scale in RUNS:
                mcap, rrd, png = runs / f"{name}.mcap", runs / f"{name}.rrd", args.out / f"{name}.png"
                vsim = [sys.executable, "-m", "elastokin"]
                _run([*vsim, "run", scenario, "--duration-scale", str(scale), "-o", str(mcap), "--overwrite"])
                _run([*vsim, "view", str(mcap), "--save", str(rrd), "--overwrite"])
                _screenshot(rrd, png)
                print(png)
    finally:
        xvfb.terminate()
        xvfb.wait()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
