"""Where the K&C campaign can see each cause, as the K&C diagnosis sees it: every catalogue cause
(and backlash) at every place it can sit in a vehicle, at the weak end of its realistic range
(its first parameter at the low end of its draw, the others mid-range), run on the whole campaign.
Prints the model error it makes in excess of the noise: the RMS over every compared channel and
sample of the change, each channel's mean per recording removed (the diagnosis takes it for a zero
error), in units of the channel's noise (the virtual rig's defaults). A baseline held-out error of
√(1 + excess²) is what the diagnosis must explain; it names nothing below 1.11 (excess 0.48).
``elastokin.diagnosis.kc_catalogue.OBSERVABLE`` lists the places whose excess is at least
``kc_catalogue.MIN_EXCESS`` at the test campaign's speed (``--duration-scale 0.25``).

    python tools/kc_observability.py [--vehicle V.yaml] [--duration-scale S] [--cause C ...] [--json]

About 2 min on 2 cores at ``--duration-scale 0.25`` (its runs on a local Dask cluster, or where ``VSIM_SCHEDULER`` says).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from contextlib import closing
from pathlib import Path

import numpy as np

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.cluster.executor import TaskFailed, executor
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.diagnosis.kc_catalogue import (BUSHING_CAUSES, MIN_EXCESS, VEHICLE_CAUSES, Hypothesis, extended_vehicle,
                                         locations, parameters)
from elastokin.diagnosis.kc_layout import COMPARED
from elastokin.diagnosis.kc_fits import nominal
from elastokin.diagnosis.virtual_kc_rig import DEFAULT_SCENARIOS, MEASUREMENT_DEFAULTS, sensor
from elastokin.recordings.recorder import simulate


def weak(cause: str) -> list[dict[str, float]]:
    """The cause's values at the weak end of its range: the first parameter at the low end of its
    draw (of either sign, for a cause screened on both: :attr:`elastokin.diagnosis.catalogue.Parameter.signs`),
    the others mid-range."""
    first = parameters(cause)[0]
    return [{**nominal(cause), first.name: sign * first.draw[0]} for sign in first.signs]


def floor(cause: str, excess_at_weak_end: float) -> float:
    """The first parameter's magnitude at which the cause's excess reaches MIN_EXCESS, taking the
    effect proportional to it as the diagnosis's fit does (:meth:`Parameter.effect`)."""
    if excess_at_weak_end <= 1e-3 * MIN_EXCESS:
        return math.inf
    first = parameters(cause)[0]
    return first.from_effect(first.effect(first.draw[0]) * MIN_EXCESS / excess_at_weak_end)


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


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--vehicle", type=Path, default=DEFAULT_VEHICLE)
    parser.add_argument("--duration-scale", type=float, default=1.0, help="the campaign's speed-up (0.25: the tests')")
    parser.add_argument("--cause", action="append", choices=[*BUSHING_CAUSES, *VEHICLE_CAUSES, "backlash"],
                        help="only this cause (repeat for more; default: every cause)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    vehicle = load_vehicle(args.vehicle)
    base = campaign(vehicle, args.duration_scale)
    causes = args.cause or (*BUSHING_CAUSES, *VEHICLE_CAUSES, "backlash")
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
