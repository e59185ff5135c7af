"""One run of a sweep: a pure function of the vehicle file's text, the scenarios (parsed where the
sweep was read), the values set at their places and the duration scale, so that any worker computes
the bits a serial run computes. The worker reads the files the vehicle names (bushing parameter
sets, tyre) by their absolute paths: a shared filesystem or the same installation. It returns the
run's metrics; a failure (a diverged car, a metric that raises) is raised to the executor, which
makes it the run's row with its reason."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

from elastokin.vehicle.model.file_overrides import vehicle_with
from elastokin.vehicle.scenarios.road_scenario import RoadScenario
from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.analysis.road_metrics import road_metrics
from elastokin.analysis.run_metrics import is_road, run_metrics
from elastokin.recordings.recorder import run_scenario, simulate
from elastokin.recordings.run_format import Run
from elastokin.sweeps.sweep_file import MetricColumn, SourceFile, Sweep


@dataclass(frozen=True)
class RunTask:
    """Everything one run needs, as plain values (it travels to a worker)."""

    index: int                                #: 0-based run number in the design
    values: tuple[tuple[str, float], ...]     #: (place, value) of each parameter
    vehicle: SourceFile
    scenarios: tuple[Scenario | RoadScenario, ...]
    duration_scale: float
    columns: tuple[MetricColumn, ...]
    record_dir: str | None                    #: where to write each scenario's MCAP, or None
    source: str                               #: the sweep file, for errors


@dataclass(frozen=True)
class RunOutcome:
    """What a run gives back: its metrics by column name (NaN where a case gave none) and how long
    its simulations took in the worker [s] (for the scheduling overhead, not for the table)."""

    metrics: dict[str, float]
    compute_s: float


def tasks(sweep: Sweep, points: list[tuple[float, ...]], indices: list[int], record_dir: Path | None) -> list[RunTask]:
    """The :class:`RunTask` of each run number of ``indices`` (its parameter values in ``points``)."""
    places = [p.place for p in sweep.parameters]
    return [RunTask(i, tuple(zip(places, points[i])), sweep.vehicle, sweep.scenarios, sweep.duration_scale,
                    sweep.columns, None if record_dir is None else str(record_dir.resolve()), str(sweep.path))
            for i in indices]


def _value(metrics: dict, column: MetricColumn) -> float:
    case = metrics.get(column.case, {})
    value = case.get(column.axle, {}).get(column.metric) if column.axle else case.get(column.metric)
    return math.nan if value is None else float(value)


def run_point(task: RunTask) -> RunOutcome:
    """Run every scenario of ``task`` on its vehicle and collect its metric columns."""
    started = time.perf_counter()
    vehicle = vehicle_with(task.vehicle.text, Path(task.vehicle.path), dict(task.values),
                           f"{task.source}: run {task.index + 1}")
    out: dict[str, float] = {}
    for k, scenario in enumerate(task.scenarios):
        if task.record_dir is None:
            run: Run = simulate(scenario, vehicle, duration_scale=task.duration_scale)
        else:
            output = Path(task.record_dir) / f"run{task.index + 1:05d}_{scenario.name}.mcap"
            run = run_scenario(scenario, output, overwrite=True, duration_scale=task.duration_scale,
                               vehicle=vehicle).run
        metrics = road_metrics(run) if is_road(run) else run_metrics(run)
        out |= {c.name: _value(metrics, c) for c in task.columns if c.scenario == k}
    return RunOutcome(out, time.perf_counter() - started)
