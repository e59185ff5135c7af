"""Causes a K&C campaign cannot tell apart, and the test that would (:mod:`elastokin.diagnosis.kc_diagnosis`).

Two hypotheses can act alike on the tests measured: a hardpoint and a bushing stiffness, the two
ends of the strut's axis moved sideways, the tie rod's inner end raised or its outer end lowered.
A rival of the best cause is *alike* when it would be named on its own (it explains the mismatch
as a cause must) and the best does not beat it as a cause must beat what it is compared with
(:func:`elastokin.diagnosis.verdict.told_apart`): the campaign then names the best, but it cannot say
which of the two is the car's. Each alike rival and the best are run on every shipped rig scenario
the dataset lacks; the one where their predictions differ most, in units of the measured noise
(each channel's mean removed, as a zero error would be), is the extra test that separates them.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.vehicle.simulation.runner import DivergenceError
from elastokin.core.shipped import SCENARIO_DIR, built_in
from elastokin.diagnosis.kc_fits import Candidate
from elastokin.diagnosis.kc_layout import Job, run_job
from elastokin.diagnosis.verdict import Separation, difference
from elastokin.diagnosis.verdict import alike as is_alike


def alike(best: Candidate, verified: Sequence[Candidate], before: float, floor: float = 1.0) -> list[Candidate]:
    """The verified candidates other than ``best`` (another cause, or another place) that the tests
    cannot tell from it (:func:`elastokin.diagnosis.verdict.alike`, against the baseline's held-out error
    ``before``), best first."""
    same = lambda c: (c.hypothesis.cause, c.hypothesis.location) == (best.hypothesis.cause, best.hypothesis.location)
    return [c for c in verified if c.verified and not same(c)
            and is_alike(before, c.heldout_error, best.heldout_error, floor)]


def extra_scenarios(measured: Sequence[str]) -> list[tuple[Path, Scenario]]:
    """The shipped rig scenarios (the K&C campaign's and the others; not the road's) whose names are
    not among ``measured``."""
    out = []
    for name in built_in(SCENARIO_DIR):
        path = SCENARIO_DIR / f"{name}.yaml"
        scenario = load_scenario(path)
        if isinstance(scenario, Scenario) and scenario.name not in measured:
            out.append((path, scenario))
    return out


def run_unless_diverged(job: Job) -> dict[str, np.ndarray] | None:
    """:func:`~elastokin.diagnosis.kc_layout.run_job`'s channels, None when the car leaves its valid range
    (a rival far off may, in a harsher test than the dataset's): a task of the executor."""
    try:
        return run_job(job)
    except DivergenceError:
        return None


def separations(vehicles: Sequence[VehicleDefinition], scenarios: Sequence[tuple[Path, Scenario]],
                channels: Sequence[str], noise: np.ndarray, duration_scale: float,
                run: Callable[[list[Job]], list[dict[str, np.ndarray] | None]]) -> list[Separation | None]:
    """For every vehicle after the first (the rivals of ``vehicles[0]``, the best cause's), the
    scenario whose predictions differ most from the first's in units of ``noise`` (per channel of
    ``channels``), or None when no scenario ran for both; ``run`` gives the compared channels of
    jobs (their input phases) in their order, on whatever executor, None for a run that left the
    car's valid range (:func:`run_unless_diverged`)."""
    jobs = [Job(s, v, duration_scale, tuple(channels)) for v in vehicles for _, s in scenarios]
    results = run(jobs)
    n = len(scenarios)
    predicted = [[None if r is None else np.column_stack([r[c] for c in channels]) for r in results[k * n:(k + 1) * n]]
                 for k in range(len(vehicles))]
    out: list[Separation | None] = []
    for rival in predicted[1:]:
        differences = [-math.inf if a is None or b is None else difference(a, b, noise)
                       for a, b in zip(predicted[0], rival)]
        k = int(np.argmax(differences)) if differences else 0
        out.append(Separation(scenarios[k][1].name, scenarios[k][0], differences[k])
                   if differences and differences[k] > -math.inf else None)
    return out

