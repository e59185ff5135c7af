"""The standard K&C tests (spec vehicle.md §4): quasi-static triangles on both axles at once.

Each test starts from the design pose with virgin bushings, rests :data:`SETTLE` s, then runs the
triangle 0 → +A → −A → +A at a constant rate; the +A → −A leg gives the unloading (down) branch,
the −A → +A leg the loading (up) branch.

========  ======================================  ============  ======================  =========
test      input (every wheel of both axles)        A             rate                    duration
========  ======================================  ============  ======================  =========
bump      pad heights in phase (bump +)            25 mm         25 mm/s (≈ thesis       5 s
                                                                 60 mm at 0.1 Hz)
roll      pads in opposite phase, right up         25 mm         25 mm/s                 5 s
lateral   Fy at the contact points, +y (left)      2 kN/wheel    2 kN/s                  5 s
longit.   Fx at the contact points, −x (braking)   1.5 kN/wheel  2 kN/s                  3.75 s
drive     Fx at the wheel centres, +x (driving)    1.5 kN/wheel  2 kN/s                  3.75 s
aligning  Mz about the vertical, +z (to the left)  150 N·m       200 N·m/s               3.75 s
steering  rack displacement, +y (to the left)      40 mm         40 mm/s                 5 s
========  ======================================  ============  ======================  =========

The braking test pushes the pads' carriages (the contact points: outboard brakes, the wheels
braked); the drive test pushes the wheels at their centres with the carriages free fore and aft,
as inboard drive shafts do (their torque reacted by the body). The steering sweep
(:data:`STEERING`) runs on the front axle's rack alone, pads held at design.
"""

from __future__ import annotations

from dataclasses import dataclass

SETTLE = 0.5             #: rest before each test [s]
SAMPLES_PER_LEG = 200    #: samples on each of the down and up legs


@dataclass(frozen=True)
class Triangle:
    """One quasi-static triangle applied to all four wheels."""

    name: str
    input: str               #: ``pads``, ``fx``, ``fy``, ``mz`` or ``rack`` (see :meth:`elastokin.vehicle.simulation.rig.KCRig.ramp`)
    pattern: tuple[float, float, float, float]   #: per corner (order of CORNERS), times the amplitude; the rack: its first
    amplitude: float         #: [m, N or N·m]
    rate: float              #: [m/s, N/s or N·m/s]
    at: str = "contact"      #: where Fx and Fy push: ``"contact"`` (the contact points) or ``"centre"`` (the wheel centres)


TESTS = (
    Triangle("bump", "pads", (1, 1, 1, 1), 0.025, 0.025),
    Triangle("roll", "pads", (-1, 1, -1, 1), 0.025, 0.025),
    Triangle("lateral", "fy", (1, 1, 1, 1), 2000.0, 2000.0),
    Triangle("longitudinal", "fx", (-1, -1, -1, -1), 1500.0, 2000.0),
    Triangle("drive", "fx", (1, 1, 1, 1), 1500.0, 2000.0, at="centre"),
    Triangle("aligning", "mz", (1, 1, 1, 1), 150.0, 200.0),
)
TEST = {t.name: t for t in TESTS}   #: the tests by name
STEERING = Triangle("steering", "rack", (1, 0, 0, 0), 0.040, 0.040)   #: the rack sweep


def triangle_input(test: Triangle, t: float) -> float:
    """``test``'s input [m, N or N·m; times each corner's pattern] at ``t`` [s] from the test's
    start (the rig's reset): held at zero for :data:`SETTLE`, then 0 → +A → −A → +A."""
    leg = test.amplitude / test.rate
    s = t - SETTLE
    if s <= 0.0:
        return 0.0
    if s <= leg:
        return test.amplitude * s / leg
    if s <= 3 * leg:
        return test.amplitude * (1.0 - (s - leg) / leg)
    return test.amplitude * (-1.0 + (s - 3 * leg) / leg)

