"""The thesis's time-domain identification experiment (Bourgeteau 2009, §5.4.2, fig. 5.24,
eqs. 5.49–5.52): a two-cell model close to the RT, its parameters fitted to simulated "measurements"
from a start away from them, on a sine, a swept sine, steps and a swept sine followed by a step.

The model is the RT ladder without its parallel spring: F = k1·(e − x1), node 1 tied to the input
by k1 and to node 2 by k2, node 2 to the ground by k2, each node to the ground by a damper
b·sign(x')·|x'|^a (eqs. 5.49–5.52): here ``rt`` with K0 = 0, N = 2, Kpa = k1, Kr = k2, Co = b,
pw = a, in N, mm, s. The thesis's "measurement" takes k1 = 1200, k2 = 800, b = 50, a = 0.5; its
fits start from k1 = k2 = 1000, b = 80, a = 0.4 and, with Matlab's fmincon without
regularisation, end at a = 0.567–0.586 and b = 63–66.6 (its five results are
:data:`THESIS_RESULTS`). The thesis does not give its programmes beyond their kind and length
(a 1 Hz, 1 mm sine; a swept sine; a step over 1 s and 2 s; a swept sine and a step over 4 s):
the ones here (:data:`PROGRAMMES`) are this module's choice, stated.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from elastokin.bushings.bench.identification import FitResult, fit
from elastokin.bushings.bench.programmes import sine, step
from elastokin.bushings.bench.records import BenchRecord, simulate_record
from elastokin.bushings.parameter_sets import ParameterSet
from elastokin.bushings.parameters import to_si
from elastokin.core.units import MM

#: The thesis's "measured" parameters and its fits' start (N, mm, s), §5.4.2.
TRUTH = {"N": 2, "K0": 0.0, "Kpa": 1200.0, "Kr": 800.0, "Co": 50.0, "pw": 0.5}
START = {"N": 2, "K0": 0.0, "Kpa": 1000.0, "Kr": 1000.0, "Co": 80.0, "pw": 0.4}
#: The thesis's results per programme: k1, k2 [N/mm], a, b [N/(mm/s)^a], its cost (its own scale).
THESIS_RESULTS = {
    "sine": (1237.0, 1043.0, 0.573, 63.0, 4e-3),
    "swept sine": (1208.0, 928.0, 0.586, 66.5, 1.8e-3),
    "step 1 s": (1150.0, 922.0, 0.572, 65.0, 11.1e-3),
    "step 2 s": (1253.0, 800.0, 0.583, 66.6, 3.7e-3),
    "swept sine + step": (1153.0, 1017.0, 0.567, 63.9, 455e-3),
}
#: Time step of the simulated records [s].
DT_S = 1e-3
#: The swept sine: 1 mm, its frequency rising linearly from 0.5 to 10 Hz over 2 s (this module's choice).
SWEEP = (1.0, 0.5, 10.0, 2.0)
#: The step: 1 mm, risen in 10 ms (this module's choice).
STEP = (1.0, 0.01)


def _swept(duration_s: float) -> tuple[np.ndarray, np.ndarray]:
    amplitude, f0, f1, sweep_s = SWEEP
    t = DT_S * np.arange(round(duration_s / DT_S) + 1)
    phase = 2.0 * np.pi * (f0 * t + 0.5 * (f1 - f0) / sweep_s * t * t)
    return t, amplitude * MM * np.sin(phase)


def _step(hold_s: float) -> tuple[np.ndarray, np.ndarray]:
    height, rise = STEP
    return step(height * MM, rise, hold_s - rise, DT_S)


def programme(name: str) -> tuple[np.ndarray, np.ndarray]:
    """Time [s] and deflection [m] of one of :data:`THESIS_RESULTS`' programmes."""
    if name == "sine":
        return sine(1.0 * MM, 1.0, 2, DT_S)
    if name == "swept sine":
        return _swept(SWEEP[3])
    if name in ("step 1 s", "step 2 s"):
        return _step(float(name.split()[1]))
    if name == "swept sine + step":
        t1, e1 = _swept(SWEEP[3])
        t2, e2 = _step(2.0)
        return np.r_[t1, t1[-1] + DT_S + t2], np.r_[e1, e1[-1] + e2]   # the step from where the sweep ends
    raise ValueError(f"unknown programme {name!r}; expected one of {', '.join(THESIS_RESULTS)}")


@dataclass(frozen=True)
class Identified:
    """One programme's fit beside the thesis's."""

    programme: str
    result: FitResult
    thesis: tuple[float, float, float, float, float]

    @property
    def ours(self) -> tuple[float, float, float, float]:
        """k1, k2, a, b as fitted here."""
        v = self.result.values
        return v["Kpa"], v["Kr"], v["pw"], v["Co"]


def identify(name: str, noise: float = 0.0, seed: int = 0) -> Identified:
    """The fit of the model to the truth's simulated response to programme ``name``, from the
    thesis's start, K0 held at 0 and N at 2 (the thesis's model has no parallel spring); with
    white noise of ``noise`` times the force's range added to the "measurement" (drawn from ``seed``)."""
    t, e = programme(name)
    force = simulate_record([to_si("rt", TRUTH)], t, e)[:, 0]
    force = force + noise * float(np.ptp(force)) * np.random.default_rng(seed).standard_normal(force.size)
    measured = BenchRecord(name, t, e, force)
    start = ParameterSet("thesis_start", "rt", "translation", dict(START), "Bourgeteau 2009, §5.4.2")
    return Identified(name, fit([measured], "rt", [start], hold=("K0",), max_samples=len(t)), THESIS_RESULTS[name])
