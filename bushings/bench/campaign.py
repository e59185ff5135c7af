"""The virtual bench's standard test campaign: the thesis's bench programmes (spec bushings §5),
played in this order on one part, whose state carries over from test to test.

The order alternates kinds of test so that holding out every other record leaves each kind of
evidence (slow and fast loops, sines, relaxations, static offsets, a long endurance run) on both
sides of the split. The endurance sine comes late, so that later tests see a warm part.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from elastokin.bushings.bench.programmes import parse_programme


@dataclass(frozen=True)
class BenchTest:
    """One record of the campaign: a programme, its sampling step and the rest before it."""

    name: str
    programme: dict[str, Any]     #: the programme as a bench file writes it (mm, s, Hz)
    dt_s: float                   #: the rig's sampling step [s]
    rest_before_s: float          #: rest at zero deflection before the test [s]

    def signal(self, dt_s: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Time [s] from 0 and deflection [m], sampled every dt_s (default: the rig's step)."""
        programme = parse_programme(self.programme, dt_s or self.dt_s, f"the campaign's test {self.name}")
        return programme.t_s, programme.e_m


def _sine(a: float, f: float, cycles: int, **extra: float) -> dict[str, Any]:
    return {"type": "sine", "amplitude_mm": a, "frequency_hz": f, "cycles": cycles, **extra}


def _dt(f_hz: float, points: int = 50) -> float:
    return 1.0 / (points * f_hz)


#: The standard campaign, in the order played.
CAMPAIGN: tuple[BenchTest, ...] = (
    BenchTest("triangle_2mm_slow", {"type": "triangle", "amplitude_mm": 2.0, "speed_mm_s": 0.333, "cycles": 2}, 0.01, 0.0),
    BenchTest("triangle_1mm_slow", {"type": "triangle", "amplitude_mm": 1.0, "speed_mm_s": 0.333, "cycles": 2}, 0.01, 5.0),
    BenchTest("triangle_2mm_10mm_s", {"type": "triangle", "amplitude_mm": 2.0, "speed_mm_s": 10.0, "cycles": 3}, 0.002, 5.0),
    BenchTest("triangle_2mm_100mm_s", {"type": "triangle", "amplitude_mm": 2.0, "speed_mm_s": 100.0, "cycles": 3}, 0.0002, 5.0),
    BenchTest("sine_1hz_1mm", _sine(1.0, 1.0, 5), _dt(1.0), 5.0),
    BenchTest("sine_10hz_0.5mm", _sine(0.5, 10.0, 10), _dt(10.0), 5.0),
    BenchTest("step_1mm", {"type": "step", "amplitude_mm": 1.0, "rise_time_s": 0.1, "hold_s": 20.0}, 0.004, 5.0),
    BenchTest("sine_10hz_0.1mm", _sine(0.1, 10.0, 10), _dt(10.0), 5.0),
    BenchTest("sine_1hz_0.5mm_static_-2mm", _sine(0.5, 1.0, 3, static_mm=-2.0), 0.004, 5.0),
    BenchTest("sine_1hz_0.5mm_static_+2mm", _sine(0.5, 1.0, 3, static_mm=2.0), 0.004, 5.0),
    BenchTest("bisine_1hz_1mm_10hz_0.2mm", {"type": "bisine", "duration_s": 3.0, "components": [
        {"amplitude_mm": 1.0, "frequency_hz": 1.0}, {"amplitude_mm": 0.2, "frequency_hz": 10.0}]}, _dt(10.0), 5.0),
    BenchTest("step_-1mm", {"type": "step", "amplitude_mm": -1.0, "rise_time_s": 0.1, "hold_s": 20.0}, 0.004, 5.0),
    BenchTest("firtree_3mm", {"type": "firtree", "amplitude_mm": 3.0, "speed_mm_s": 10.0, "step_mm": 1.0,
                              "hold_s": 3.0, "cycles": 1}, 0.005, 5.0),
    BenchTest("endurance_15hz_1.5mm", _sine(1.5, 15.0, 450), _dt(15.0, 40), 5.0),
    BenchTest("triangle_2mm_slow_after", {"type": "triangle", "amplitude_mm": 2.0, "speed_mm_s": 0.333, "cycles": 1},
              0.01, 2.0),
    BenchTest("sine_10hz_0.5mm_after", _sine(0.5, 10.0, 10), _dt(10.0), 2.0),
)


def campaign_duration_s(tests: tuple[BenchTest, ...] = CAMPAIGN) -> float:
    """Total time of the campaign including rests [s]."""
    return sum(t.rest_before_s + float(t.signal()[0][-1]) for t in tests)


def samples(tests: tuple[BenchTest, ...] = CAMPAIGN) -> int:
    """Total number of samples the rig records."""
    return sum(len(t.signal()[0]) for t in tests)

