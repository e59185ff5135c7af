"""Road runs side by side, each with its road metrics (:mod:`elastokin.analysis.road_metrics`) and
their differences from the first:

* what the bushings do on the road: one road scenario run on variants of its car (the bushings
  linear, as the scenario or the vehicle file defines them, every direction STVS, and any other
  vehicle file, such as the ``extended_vehicle.yaml`` a K&C diagnosis writes), the linear car first;
* a simulated road run against the measured one of the same ``measured_steer`` scenario (``vsim
  compare``), the measurement first, with the RMS error of every response both hold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, Sequence

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.road_scenario import ROAD_TYPES, RoadScenario
from elastokin.vehicle.scenarios.schedule import Progress
from elastokin.analysis.compare import aligned, check_pair
from elastokin.analysis.loops import rms_error
from elastokin.analysis.road_metrics import METRICS, road_metrics
from elastokin.core.errors import InputError
from elastokin.recordings.recorder import simulate
from elastokin.recordings.run_format import Run


_UNITS = {key: unit for key, unit, _ in METRICS}


@dataclass(frozen=True)
class Variant:
    """One car of the comparison: its label, its run (in memory) and its metrics by case number."""

    label: str
    run: Run
    metrics: dict[int, dict[str, float]]


def variant_plan(scenario: RoadScenario, extended: Sequence[Path] = ()
                 ) -> list[tuple[str, RoadScenario, VehicleDefinition]]:
    """The cars to compare: (label, scenario, vehicle) with the bushings linear first (the
    reference), then as defined and every direction STVS (each unless it is one of those before),
    then each vehicle file of ``extended`` (once, labelled by its path) with its own bushings."""
    base = load_vehicle(scenario.vehicle)
    defined = f"bushings {scenario.bushing_model}" if scenario.bushing_model else "bushings as in the vehicle file"
    plan = [("bushings linear", replace(scenario, bushing_model="linear"), base)]
    if scenario.bushing_model != "linear":
        plan.append((defined, scenario, base))
    if scenario.bushing_model != "stvs":
        plan.append(("bushings stvs", replace(scenario, bushing_model="stvs"), base))
    plan += [(str(path), replace(scenario, bushing_model=None), load_vehicle(path)) for path in dict.fromkeys(extended)]
    return plan


def compare_variants(scenario: RoadScenario, extended: Sequence[Path] = (), duration_scale: float = 1.0,
                     progress: Callable[[str, Progress], None] | None = None) -> list[Variant]:
    """Run ``scenario`` on every car of :func:`variant_plan`; ``progress(label, p)`` after every sample."""
    out = []
    for label, s, vehicle in variant_plan(scenario, extended):
        report = None if progress is None else (lambda p, label=label: progress(label, p))
        run = simulate(s, vehicle, duration_scale=duration_scale, progress=report)
        out.append(Variant(label, run, road_metrics(run)))
    return out


def is_time(metric: str) -> bool:
    """Whether a road metric is a time [s] (its differences are given in ms)."""
    return _UNITS.get(metric.removeprefix("second_")) == "s"


def differences(variants: Sequence[Variant]) -> list[dict[str, object]]:
    """One row per (case, metric, variant): the value, and its difference from the first variant
    (times also in ms), for every metric the first variant has."""
    reference = variants[0]
    rows = []
    for case, metrics in reference.metrics.items():
        label = next(c["label"] for c in reference.run.metadata.extra["cases"] if c["case"] == case)
        for key, ref in metrics.items():
            for v in variants:
                value = v.metrics.get(case, {}).get(key, math.nan)
                rows.append({"case": label, "metric": key, "variant": v.label, "value": value,
                             "difference": value - ref,
                             "difference_ms": 1e3 * (value - ref) if is_time(key) else math.nan})
    return rows


#: The responses a simulated and a measured road run are compared on, where both hold them.
COMPARED = ("yaw_rate", "lateral_acceleration", "longitudinal_acceleration", "roll", "pitch", "sideslip", "speed")


def compare_road_runs(sim: Run, measured: Run) -> list[Variant]:
    """``measured`` (a road test, or any run of the same scenario) and ``sim`` as the variants of a
    comparison, the measurement first (differences are simulation minus measurement). InputError
    naming the file when either is not a road run of a scenario, the files are swapped or the
    measurement plays other cases (:func:`elastokin.analysis.compare.check_pair`)."""
    check_pair(sim, measured)
    for run in (sim, measured):
        if run.metadata.extra["type"] not in ROAD_TYPES:
            raise InputError(f"a {run.metadata.extra['type']} run is not a road run; expected two road runs of one "
                             f"scenario", source=str(run.path))
    return [Variant(f"measured ({measured.metadata.source})", measured, road_metrics(measured)),
            Variant(f"simulated ({sim.metadata.source})", sim, road_metrics(sim))]


def response_errors(sim: Run, measured: Run) -> list[dict[str, object]]:
    """One row per (case, response of :data:`COMPARED` both runs hold): the RMS of simulation −
    measurement over the measurement's input samples, in the response's unit."""
    rows = []
    for case in measured.metadata.extra["cases"]:
        for name in COMPARED:
            if name in sim.signals and name in measured.signals:
                _, a, b = aligned(sim, measured, case["case"], name)
                rows.append({"case": case["label"], "signal": name, "unit": measured.units[name],
                             "rms_error": rms_error(a, b) if a.size else math.nan})
    return rows
