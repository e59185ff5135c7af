"""Where the K&C campaign can see each cause, as the K&C diagnosis sees it: every catalogue cause
(and backlash) at every place it can sit in a vehicle, at the weak end of its realistic range
(its first parameter at the low end of its draw, the others mid-range), run on the whole campaign.
Prints the model error it makes in excess of the noise: the RMS over every compared channel and
sample of the change, each channel's mean per recording removed (the diagnosis takes it for a zero
error), in units of the channel's noise (the virtual rig's defaults). A baseline held-out error of
√(1 + excess²) is what the diagnosis must explain; it names nothing below 1.11 (excess 0.48).
``elastokin.diagnosis.kc_catalogue.OBSERVABLE`` lists the places whose excess is at least
``kc_catalogue.MIN_EXCESS`` at the test campaign's speed (``--duration-scale 0.25``).

With ``--through-rig``, at each place of ``OBSERVABLE`` and at magnitudes spread over the draw's
range (:data:`THROUGH_RIG_STEPS`, every sign and side it is drawn on), what the change leaves once
a calibrated rig's errors have taken what they can: every rig error the diagnosis fits beside the
causes (its measuring transducers' gains and cross-talks and its inputs' gains, each within its
bound; the zeros' drifts; the acquisition's lags; the rig's mechanics), fitted to the change alone
on the car measured on the virtual rig without a chain. A cause below MIN_EXCESS there is one the
rig's errors leave too little of to name; ``kc_catalogue.THROUGH_A_RIG`` lists each place's floor,
the magnitude from which its weakest way stays above it (the larger of it and ``OBSERVABLE``'s,
kept where it leaves the top fifth of the range).

    python tools/kc_observability.py [--vehicle V.yaml] [--duration-scale S] [--cause C ...] [--through-rig] [--json]

About 2 min on 2 cores at ``--duration-scale 0.25``, 29 min with ``--through-rig`` beside a slow
test run (its runs on a local Dask cluster, or where ``VSIM_SCHEDULER`` says).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from contextlib import closing
from functools import partial
from pathlib import Path

import numpy as np

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.cluster.executor import TaskFailed, executor
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.diagnosis.kc_catalogue import (BUSHING_CAUSES, MIN_EXCESS, OBSERVABLE, VEHICLE_CAUSES, Hypothesis,
                                              drawn_ways, extended_vehicle, locations, parameters)
from elastokin.diagnosis.kc_diagnosis import rig_scorer
from elastokin.diagnosis.kc_layout import COMPARED, Layout, run_sets
from elastokin.diagnosis.kc_fits import nominal
from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.verdict import split
from elastokin.diagnosis.virtual_kc_rig import (DEFAULT_SCENARIOS, MEASUREMENT_DEFAULTS, KCTruth, measure_kc,
                                                sensor)
from elastokin.recordings.kc_dataset import read_kc_dataset
from elastokin.recordings.recorder import simulate

#: Magnitudes tried at each place with ``--through-rig``: the draw's range's ends and evenly between,
#: in the coordinate its effect grows with.
THROUGH_RIG_STEPS = 4


def weak(cause: str) -> list[dict[str, float]]:
    """The cause's values at the weak end of its range: the first parameter at the low end of its
    draw (of either sign, for a cause screened on both: :attr:`elastokin.diagnosis.catalogue.Parameter.signs`),
    the others mid-range."""
    first = parameters(cause)[0]
    return [{**nominal(cause), first.name: sign * first.draw[0]} for sign in first.signs]


def floor(cause: str, excess: float, magnitude: float | None = None) -> float:
    """The first parameter's magnitude at which the cause's excess reaches MIN_EXCESS, from its
    ``excess`` at ``magnitude`` (default: the weak end of its draw), taking the effect proportional
    to it as the diagnosis's fit does (:meth:`Parameter.effect`)."""
    if excess <= 1e-3 * MIN_EXCESS:
        return math.inf
    first = parameters(cause)[0]
    return first.from_effect(first.effect(first.draw[0] if magnitude is None else magnitude) * MIN_EXCESS / excess)


def campaign(vehicle: VehicleDefinition, duration_scale: float) -> list[dict[str, np.ndarray]]:
    """Per recording of the campaign, the compared channels in units of their noise."""
    out = []
    for path in DEFAULT_SCENARIOS:
        run = simulate(load_scenario(path), vehicle, duration_scale=duration_scale)
        out.append({name: run.signals[name] / sensor(unit, MEASUREMENT_DEFAULTS)[0] for name, unit in run.units.items()
                    if name.rsplit("_", 1)[0] in COMPARED or name.rsplit("_", 2)[0] in COMPARED})
    return out


def _campaign(job: tuple[VehicleDefinition, float]) -> list[dict[str, np.ndarray]]:
    """:func:`campaign` of a (vehicle, duration scale) pair: one task of the executor."""
    return campaign(*job)


def excess(base: list[dict[str, np.ndarray]], run: list[dict[str, np.ndarray]]) -> float:
    """RMS change over every channel and sample, each channel's mean per recording removed [noise]."""
    squares = [float(np.mean((d - d.mean()) ** 2)) for b, r in zip(base, run) for d in (r[n] - b[n] for n in b)]
    return math.sqrt(float(np.mean(squares)))


def left_by_the_rig(scorer: Scorer, change: np.ndarray) -> float:
    """RMS over every compared channel and sample of what a ``change`` (N, C) of the baseline's rows
    leaves once every rig error ``scorer`` fits has taken what it can of it, each within its bounds
    (:meth:`~elastokin.diagnosis.kc_scorer.Scorer.seen_left`) [noise]."""
    return math.sqrt(float(np.mean(scorer.seen_left(change, np.ones(len(change), dtype=bool)) ** 2)))


def magnitudes(cause: str) -> list[float]:
    """:data:`THROUGH_RIG_STEPS` magnitudes of ``cause``'s first parameter over its draw's range."""
    first = parameters(cause)[0]
    lo, hi = (first.effect(x) for x in first.draw)
    return [first.from_effect(lo + k * (hi - lo) / (THROUGH_RIG_STEPS - 1)) for k in range(THROUGH_RIG_STEPS)]


def rig_floor(cause: str, excess_by_magnitude: list[tuple[float, float]]) -> float:
    """The first parameter's magnitude from which the excess left by the rig's errors stays at least
    MIN_EXCESS: interpolated between the magnitudes tried in their effect's coordinate (a little low
    where the excess grows faster than in proportion, as one left by bounded errors does), in
    proportion below the first; infinite if the last is below."""
    first = parameters(cause)[0]
    if excess_by_magnitude[-1][1] < MIN_EXCESS:
        return math.inf
    k = max(i for i, (_, x) in enumerate(excess_by_magnitude) if i == 0 or excess_by_magnitude[i - 1][1] < MIN_EXCESS)
    m1, x1 = excess_by_magnitude[k]
    if k == 0:
        return floor(cause, x1, m1)
    m0, x0 = excess_by_magnitude[k - 1]
    e0, e1 = first.effect(m0), first.effect(m1)
    return first.from_effect(e0 + (MIN_EXCESS - x0) / (x1 - x0) * (e1 - e0))


def through_rig(vehicle: VehicleDefinition, duration_scale: float, causes: list[str], show: bool
                ) -> dict[str, dict[str, object]]:
    """Per place of OBSERVABLE of ``causes`` (the catalogue's: backlash is drawn through no rig's
    chain), the excess left by the rig's errors at each magnitude (its weakest way) and the floor
    (module docstring); each excess printed as it comes if ``show``."""
    places = [(c, where) for c in causes if c in OBSERVABLE and c != "backlash" for where in OBSERVABLE[c]]
    tried = [(c, where, m, Hypothesis(c, where, {**nominal(c), parameters(c)[0].name: v}))
             for c, where in places for m in magnitudes(c) for v in drawn_ways(c, m)]
    scenarios = tuple(load_scenario(p) for p in DEFAULT_SCENARIOS)
    clean = KCTruth("<a clean car>", vehicle, scenarios, (), MEASUREMENT_DEFAULTS, 1, duration_scale)
    with tempfile.TemporaryDirectory() as folder, executor() as pool:
        layout = Layout.of(read_kc_dataset(measure_kc(clean, Path(folder) / "measured")), vehicle)
        every = range(len(layout.tests))
        runs = partial(run_sets, layout, pool)
        (base,) = runs([("the baseline", layout.jobs(vehicle, every), every)])
        scorer = rig_scorer(layout, base, split(len(layout.tests)), runs)
        rows = runs([(h.label, layout.jobs(extended_vehicle(vehicle, [h]), every), every) for *_, h in tried])
        weakest: dict[tuple, dict[float, float]] = {}
        for (c, where, m, h), r in zip(tried, rows):
            x = left_by_the_rig(scorer, r - base)
            if show:
                print(f"{h.label:40s} {parameters(c)[0].name} = {h.values[parameters(c)[0].name]:<8.4g} "
                      f"left by the rig's errors {x:7.2f}", flush=True)
            at = weakest.setdefault((c, where), {})
            at[m] = min(x, at.get(m, math.inf))
    out = {}
    for (c, where), at in weakest.items():
        pairs = sorted(at.items())
        out[Hypothesis(c, where).label] = {"excess": [x for _, x in pairs], "magnitudes": [m for m, _ in pairs],
                                           "floor": rig_floor(c, pairs)}
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--vehicle", type=Path, default=DEFAULT_VEHICLE)
    parser.add_argument("--duration-scale", type=float, default=1.0, help="the campaign's speed-up (0.25: the tests')")
    parser.add_argument("--cause", action="append", choices=[*BUSHING_CAUSES, *VEHICLE_CAUSES, "backlash"],
                        help="only this cause (repeat for more; default: every cause)")
    parser.add_argument("--through-rig", action="store_true",
                        help="what a calibrated rig's errors leave of each cause, at the places it is drawn")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    vehicle = load_vehicle(args.vehicle)
    causes = args.cause or (*BUSHING_CAUSES, *VEHICLE_CAUSES, "backlash")
    if args.through_rig:
        floors = through_rig(vehicle, args.duration_scale, list(causes), not args.json)
        if args.json:
            print(json.dumps(floors))
        else:
            print("\nthe floor through a rig's errors (inf: below MIN_EXCESS over the whole draw range):")
            for label, r in floors.items():
                print(f"  {label:40s} floor {r['floor']:.4g}")
        return 0
    base = campaign(vehicle, args.duration_scale)
    places = [Hypothesis(c, where, values) for c in causes for where in locations(vehicle, c) for values in weak(c)]
    out: dict[str, dict[str, float]] = {}
    with executor() as ex, closing(ex.each(_campaign, [(extended_vehicle(vehicle, [h]), args.duration_scale)
                                                       for h in places])) as outcomes:
        for o in outcomes:   # printed as they finish
            if o.error:
                raise TaskFailed(f"{places[o.index].label}: {o.error}")
            h, x = places[o.index], excess(base, o.result)
            if not args.json:
                print(f"{h.label:40s} {parameters(h.cause)[0].name} = {h.values[parameters(h.cause)[0].name]:<8.4g}"
                      f" excess {x:7.2f}", flush=True)
            if x < out.get(h.label, {}).get("excess", math.inf):   # a cause tried on both signs: its weaker
                out[h.label] = {"excess": x, "floor": floor(h.cause, x)}
    out = {label: out[label] for label in dict.fromkeys(h.label for h in places)}   # in the places' order
    if args.json:
        print(json.dumps(out))
    else:
        print("\nobservable (the first parameter's floor leaves at least the top fifth of its range, in the "
              "coordinate its effect grows with: a factor's logarithm):")
        for label, r in out.items():
            first = parameters(next(p for p in places if p.label == label).cause)[0]
            if first.effect(r["floor"]) <= 0.8 * first.effect(first.draw[1]):
                print(f"  {label:40s} floor {r['floor']:.4g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
