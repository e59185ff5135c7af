"""A simulated run against a measured rig recording of the same scenario, test by test and channel
by channel (`vsim compare`; the metrics are :mod:`elastokin.analysis.run_metrics`'s).

Both files are runs (:func:`elastokin.recordings.run_reader.load_run`) with the same channel names and units; the rig's
may lack bushing channels and body poses, be sampled at another rate and on a slightly different
time base. Within each case the simulation is interpolated onto the rig's samples by the time since
the case's input started (``input_time``), which both record.

Channels: camber, toe, steer, half-track, wheel centre x/y/z and the pad's vertical force (the
pads' fx, fy and mz are rig inputs) of every wheel both files record. Per case and channel:

========================  =====================================================  ====================
metric                    definition                                             when
========================  =====================================================  ====================
gradient                  centre-line slope at design against the x quantity,    periodic inputs
                          per m of travel, per kN or per kN·m
loop_width                width of the loop at design                            periodic inputs
loop_area                 ∮ y dx over the last cycle                             periodic inputs
rms_error                 RMS of simulation − rig over the input phase           always
relaxation                change over the final hold                             steps with a hold
dynamic_stiffness         first-harmonic |F1/X1| of a force over its             sine inputs, on one
                          displacement (:data:`run_metrics.STIFFNESS_PAIRS`)     channel per wheel
========================  =====================================================  ====================

Differences are simulation minus rig.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from elastokin.vehicle.scenarios.channels import CORNER_TAGS
from elastokin.vehicle.scenarios.scenario import SIGNAL_TYPES
from elastokin.analysis.loops import rms_error
from elastokin.analysis.run_metrics import (STIFFNESS_PAIRS, case_dynamic_stiffness, case_loop, case_mask, case_relaxation,
                                       cases, gradient_unit, loop_axes)
from elastokin.core.errors import InputError
from elastokin.recordings.run_format import MEASURED_SOURCES, Run

#: Compared quantities, each recorded per wheel as ``<quantity>_<wheel>``.
QUANTITIES = ("camber", "toe", "steer", "half_track", "wheel_centre_x", "wheel_centre_y", "wheel_centre_z", "pad_fz")
#: Signals without which a file is not a run of a scenario.
_SCHEDULE = ("case", "phase", "input_time")
_EPS_S = 1e-9


@dataclass(frozen=True)
class Metric:
    """One metric of one channel in both runs, in ``unit``."""

    unit: str
    sim: float
    rig: float

    @property
    def diff(self) -> float:
        """Simulation − rig [unit]."""
        return self.sim - self.rig

    def to_json(self) -> dict[str, Any]:
        """The metric as plain JSON data."""
        return {"unit": self.unit, "sim": self.sim, "rig": self.rig, "diff": self.diff}


@dataclass(frozen=True)
class ChannelComparison:
    """One channel (``camber_fl``) of one case: RMS error [unit] and the metrics that apply."""

    channel: str
    unit: str
    rms_error: float
    metrics: dict[str, Metric]


@dataclass(frozen=True)
class CaseComparison:
    """One case (test): its channels, and why the metrics that do not apply do not."""

    case: int
    label: str
    channels: list[ChannelComparison]
    not_applicable: dict[str, str]


@dataclass(frozen=True)
class Comparison:
    """A simulated run against a rig recording, case by case."""

    sim: Path
    rig: Path
    scenario: str
    x_quantity: str | None
    cases: list[CaseComparison]
    damage: dict[str, list[str]] = field(default_factory=dict)   #: by file: what a damaged one could not give

    def to_json(self) -> dict[str, Any]:
        """The comparison as plain JSON data (``comparison.json``)."""
        return {
            "sim": str(self.sim), "rig": str(self.rig), "scenario": self.scenario, "x_quantity": self.x_quantity,
            "difference": "simulation - rig", "damage": self.damage,
            "cases": [{"case": c.case, "label": c.label, "not_applicable": c.not_applicable,
                       "channels": [{"channel": ch.channel, "unit": ch.unit, "rms_error": ch.rms_error,
                                     **{name: m.to_json() for name, m in ch.metrics.items()}}
                                    for ch in c.channels]}
                      for c in self.cases],
        }


# -- checks ----------------------------------------------------------------------------------------
def _check_run(run: Run) -> None:
    extra = run.metadata.extra
    missing = [s for s in _SCHEDULE if s not in run.signals]
    if "cases" not in extra or missing:
        raise InputError(f"not a run of a scenario: expected a case schedule in the metadata and the signals "
                         f"{', '.join(_SCHEDULE)}", source=str(run.path))


def _check_order(sim: Run, rig: Run) -> None:
    """Differences are simulation minus measurement: swapped files would change their sign unnoticed."""
    if sim.metadata.source in MEASURED_SOURCES and rig.metadata.source == "simulation":
        raise InputError(f"the files are swapped: this is a measured {sim.metadata.source} recording and {rig.path} a "
                         f"simulated run; expected the simulated run first, the measured one second", source=str(sim.path))


def _check_cases(sim: Run, rig: Run) -> None:
    """The rig file plays the simulation's scenario: same type, duration scale and cases."""
    for key in ("type", "duration_scale"):
        if rig.metadata.extra.get(key) != sim.metadata.extra[key]:
            raise InputError(f"{key} {rig.metadata.extra.get(key)!r}; expected {sim.metadata.extra[key]!r} as in "
                             f"{sim.path}", source=str(rig.path))
    expected, got = [c["label"] for c in cases(sim)], [c["label"] for c in cases(rig)]
    if got != expected:
        raise InputError(f"cases {got}; expected the cases of {sim.path}: {expected}", source=str(rig.path))
    for run in (sim, rig):
        for case in cases(run):
            if not case_mask(run, case).any():
                raise InputError(f"case {case['case']} '{case['label']}' has no input samples (the run is "
                                 f"{'complete' if run.complete else f'incomplete: {run.reason}'})", source=str(run.path))


def check_pair(sim: Run, rig: Run) -> None:
    """InputError (naming the file) if either is not a run of a scenario, the files are swapped (a
    measured recording first, a simulated run second) or the second plays other cases."""
    for run in (sim, rig):
        _check_run(run)
    _check_order(sim, rig)
    _check_cases(sim, rig)


def common_channels(sim: Run, rig: Run) -> list[str]:
    """The compared channels both runs record (quantity by quantity, wheel by wheel); InputError if
    there are none or a unit differs."""
    names = [f"{q}_{tag}" for q in QUANTITIES for tag in CORNER_TAGS.values()]
    common = [n for n in names if n in sim.signals and n in rig.signals]
    if not common:
        raise InputError(f"no channel in common with {sim.path}; expected any of {', '.join(names)}",
                         source=str(rig.path))
    for name in common:
        if rig.units[name] != sim.units[name]:
            raise InputError(f"{name} in {rig.units[name]!r}; expected {sim.units[name]!r} as in {sim.path}",
                             source=str(rig.path))
    return common


# -- metrics ---------------------------------------------------------------------------------------
def aligned(sim: Run, rig: Run, case: int, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(input time [s], simulation, rig) of signal ``name`` on the rig's input samples of case
    number ``case`` that the simulation's input phase spans, the simulation interpolated on them."""
    ms = case_mask(sim, cases(sim)[case - 1])
    mr = case_mask(rig, cases(rig)[case - 1])
    ts, tr = sim.signals["input_time"][ms], rig.signals["input_time"][mr]
    keep = (tr >= ts[0] - _EPS_S) & (tr <= ts[-1] + _EPS_S)
    return tr[keep], np.interp(tr[keep], ts, sim.signals[name][ms]), rig.signals[name][mr][keep]


def _stiffness_channel(run: Run) -> tuple[str, str, str] | None:
    """(compared quantity, force, displacement) of the dynamic stiffness of the run's input: on the
    force's row if it is measured, else on the displacement's. None for other inputs."""
    quantity = SIGNAL_TYPES.get(run.metadata.extra["type"])
    if quantity is None:
        return None
    force, displacement = STIFFNESS_PAIRS[quantity]
    return (force if force in QUANTITIES else displacement), force, displacement


def _channel_metrics(run: Run, case: Mapping[str, Any], name: str) -> dict[str, tuple[str, float]]:
    """The metrics of ``name`` in one run's ``case`` that apply: metric → (unit, value)."""
    quantity, tag = name.rsplit("_", 1)
    unit, out = run.units[name], {}
    x, driver = loop_axes(run, tag) or (None, None)
    loop = case_loop(run, case, x, name, driver) if x in run.signals and driver in run.signals else None
    if loop is not None:
        scale, per = gradient_unit(unit, run.units[x])
        out |= {"gradient": (per, scale * loop.gradient), "loop_width": (unit, loop.width),
                "loop_area": (_product(unit, run.units[x]), loop.area)}
    relaxation = case_relaxation(run, case, name)
    if relaxation is not None:
        out["relaxation"] = (unit, relaxation)
    pair = _stiffness_channel(run)
    if pair is not None and pair[0] == quantity and all(f"{s}_{tag}" in run.signals for s in pair[1:]):
        force, displacement = (f"{s}_{tag}" for s in pair[1:])
        k = case_dynamic_stiffness(run, case, force, displacement)
        if k is not None:
            out["dynamic_stiffness"] = (f"{run.units[force]}/{run.units[displacement]}", abs(k))
    return out


def _product(a: str, b: str) -> str:
    return f"{a}²" if a == b else f"{a}·{b}"


def _not_applicable(sim: Run, case: Mapping[str, Any]) -> dict[str, str]:
    reasons = {}
    if sim.metadata.extra["x_quantity"] is None:
        reasons |= dict.fromkeys(("gradient", "loop_width", "loop_area"), "a time-only input, no x quantity")
    if case.get("hold_from_s") is None:
        reasons["relaxation"] = "no final hold"
    pair = _stiffness_channel(sim)
    if case["parameters"].get("shape") != "sine":
        reasons["dynamic_stiffness"] = "not a sine input"
    elif pair is not None:
        reasons["dynamic_stiffness"] = f"only on {pair[0]} ({pair[1]} over {pair[2]})"
    return reasons


def compare_runs(sim: Run, rig: Run) -> Comparison:
    """Compare ``sim`` with ``rig`` (see the module); InputError (naming the file) if either is not
    a run of a scenario, the files are swapped (a rig recording first, a simulated run second), the rig
    plays other cases, or they share no channel. Two runs of the same source compare too (two variants of
    the car, two rig sessions)."""
    check_pair(sim, rig)
    names = common_channels(sim, rig)
    out = []
    for sim_case, rig_case in zip(cases(sim), cases(rig)):
        channels = []
        for name in names:
            _, a, b = aligned(sim, rig, sim_case["case"], name)
            mine, theirs = _channel_metrics(sim, sim_case, name), _channel_metrics(rig, rig_case, name)
            metrics = {m: Metric(unit, value, theirs[m][1]) for m, (unit, value) in mine.items() if m in theirs}
            channels.append(ChannelComparison(name, sim.units[name], rms_error(a, b) if a.size else math.nan, metrics))
        out.append(CaseComparison(sim_case["case"], sim_case["label"], channels, _not_applicable(sim, sim_case)))
    damage = {str(run.path): list(run.damage) for run in (sim, rig) if run.damage}
    return Comparison(sim.path, rig.path, sim.metadata.extra["scenario"], sim.metadata.extra["x_quantity"], out, damage)
