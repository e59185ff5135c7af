"""Where the K&C campaign can see each cause: every catalogue cause (and backlash) at every place it
can sit in a vehicle, at mid-range magnitude, run on the campaign's largest case of each scenario;
prints the measured channels it moves most, as RMS change over the channel's measurement noise
(the virtual rig's defaults). ``vehicle.diagnosis.kc_catalogue.OBSERVABLE`` lists the places whose
best channel exceeds 2.

    python tools/kc_observability.py [--vehicle V.yaml] [--json]

About 15 s per place on one core (some 50 places).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from vehicle.definition import DEFAULT_VEHICLE, load_vehicle
from vehicle.diagnosis.kc_catalogue import BUSHING_CAUSES, VEHICLE_CAUSES, Hypothesis, extended_vehicle, locations
from vehicle.diagnosis.kc_diagnosis import COMPARED, _nominal
from vehicle.diagnosis.kc_rig import DEFAULT_SCENARIOS, MEASUREMENT_DEFAULTS, sensor
from vehicle.runner import simulate
from vehicle.scenarios import load_scenario


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--vehicle", type=Path, default=DEFAULT_VEHICLE)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    vehicle = load_vehicle(args.vehicle)
    scenarios = [load_scenario(p) for p in DEFAULT_SCENARIOS]
    scenarios = [replace(s, cases=s.cases[-1:], bushing_model=None) for s in scenarios]
    base = [simulate(s, vehicle) for s in scenarios]
    out = {}
    for cause in (*BUSHING_CAUSES, *VEHICLE_CAUSES, "backlash"):
        values = _nominal(cause)
        for where in locations(vehicle, cause):
            h = Hypothesis(cause, where, values)
            runs = [simulate(s, extended_vehicle(vehicle, [h])) for s in scenarios]
            score: dict[str, float] = {}
            for b, r in zip(base, runs):
                for name, unit in b.units.items():
                    if name.rsplit("_", 1)[0] in COMPARED or name.rsplit("_", 2)[0] in COMPARED:
                        noise = sensor(unit, MEASUREMENT_DEFAULTS)[0]
                        change = float(np.sqrt(np.mean((r.signals[name] - b.signals[name]) ** 2)) / noise)
                        score[name] = max(score.get(name, 0.0), change)
            top = sorted(score.items(), key=lambda kv: -kv[1])[:3]
            out[h.label] = top
            if not args.json:
                print(f"{h.label:40s} " + "  ".join(f"{n} {x:.2f}" for n, x in top), flush=True)
    if args.json:
        print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
