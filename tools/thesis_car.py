"""Write the thesis's car (Bourgeteau 2009, §4.4): the default car with STVS laws on the 18
principal directions the thesis names (x, y, z of E1 and E2 front and E1 rear, both sides) at its
high loss, tan δ = 0.30 (§4.4.1: "une articulation de tangente d'angle de perte valant 0,3").

    python tools/thesis_car.py [--check]

Each translation's law is the default car's read as STVS (its own STVS set, or the family set
fig5_9_caption scaled to its K0: what ``--bushing-model stvs`` gives), made lossier to tan δ = 0.30 at
15 Hz, 1 mm (PSA's specification point, §2.1.1) with its |K*| there kept
(:func:`elastokin.bushings.frequency.with_loss`); the rotations keep the default car's laws. The
file is the default car's text with those nine directions (left side, mirrored) written inline,
so that it stays the default car in everything else; ``--check`` fails when the shipped file is
not what this writes (the default car changed since).
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from elastokin.bushings.frequency import with_loss
from elastokin.bushings.parameters import LENGTH_UNIT_SI, ChannelParams
from elastokin.core.shipped import DEFAULT_VEHICLE, VEHICLE_DIR
from elastokin.vehicle.model.vehicle_file import load_vehicle

#: The shipped file this writes.
THESIS_CAR = VEHICLE_DIR / "c_segment_thesis.yaml"
#: The loss of the thesis car's bushings and where it is read: tan δ, amplitude [m], frequency [Hz].
LOSS = (0.30, 1e-3, 15.0)
#: The directions that carry STVS (the thesis's three principal directions of each bushing).
STVS_DIRECTIONS = ("x", "y", "z")

_HEADER = """\
# The thesis's car (Bourgeteau 2009, §4.4): the default car (c_segment.yaml) with STVS laws on the
# 18 principal directions the thesis names (x, y, z of E1 and E2 front and E1 rear, both sides),
# at its high loss: tan δ = {tan:.2f} at {freq:g} Hz, {amp:g} mm (§4.4.1's "tangente d'angle de perte
# valant 0,3", read at PSA's specification point, §2.1.1). Each law is the default car's direction
# read as STVS (its own set, or the family set fig5_9_caption scaled to its K0) made lossier with its |K*|
# there kept: the ladder stiffened, K0 lowered (elastokin.bushings.frequency.with_loss). Not the
# thesis's measured parts, which it does not give. Written by `python tools/thesis_car.py`; do not
# edit by hand (the test suite checks it against the default car).
"""


def _thesis_units(law: ChannelParams) -> str:
    """An STVS translation law's parameters as the vehicle file writes them (N, mm, s)."""
    mm = LENGTH_UNIT_SI["translation"]
    values = {"N": law.n_cells, "K0": law.K0 * mm, "Kpa": law.Kpa * mm, "Kr": law.Kr * mm, "Ff": law.Ff,
              "Co": law.Co * mm ** law.pw, "pw": law.pw}
    return ", ".join(f"{k}: {v}" if k == "N" else f"{k}: {float(f'{v:.6g}')!r}" for k, v in values.items())


def thesis_car_text() -> str:
    """The thesis car's vehicle file, from the default car's text."""
    vehicle = load_vehicle(DEFAULT_VEHICLE)
    tan, amp, freq = LOSS
    laws = {(b.name, d): with_loss(b.directions[d].channel("stvs"), tan, amp, freq)
            for b in vehicle.bushings for d in STVS_DIRECTIONS}
    text = DEFAULT_VEHICLE.read_text()
    head, sep, bushings = text.partition("\nbushings:\n")
    lines, name, directions, done = [], None, False, set()
    for line in bushings.splitlines(keepends=True):
        if m := re.match(r"\s*- name: (\w+)", line):
            name, directions = m.group(1), False
        directions = directions or re.match(r"\s+directions:", line) is not None
        m = re.match(r"(\s+)(x|y|z):\s+\{.*\}(\s*#.*)?\n", line)
        if m and directions:
            lines.append(f"{m.group(1)}{m.group(2)}:  {{model: stvs, params: {{{_thesis_units(laws[name, m.group(2)])}}}}}"
                         f"  # tan δ {tan:g} at {freq:g} Hz, {amp * 1e3:g} mm\n")
            done.add((name, m.group(2)))
        else:
            lines.append(line)
    if done != set(laws):
        raise RuntimeError(f"{DEFAULT_VEHICLE}: found the directions {sorted(done)} of {sorted(laws)}")
    head = head.replace("name: c_segment\n", "name: c_segment_thesis\n", 1)
    head = re.sub(r"\ndescription: .*\n", "\ndescription: The thesis car (Bourgeteau 2009, §4.4), the default car with lossy STVS "
                  f"bushings (tan δ {tan:g}) on its 18 principal directions\n", head, count=1)
    return _HEADER.format(tan=tan, freq=freq, amp=amp * 1e3) + "#\n" + head + sep + "".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="fail if the shipped file is not what this writes")
    args = ap.parse_args(argv)
    text = thesis_car_text()
    if args.check:
        same = THESIS_CAR.is_file() and THESIS_CAR.read_text() == text
        print(f"{THESIS_CAR}: {'up to date' if same else 'out of date: run python tools/thesis_car.py'}")
        return 0 if same else 1
    THESIS_CAR.write_text(text)
    print(f"wrote {THESIS_CAR}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
