"""What a run of a scenario on the K&C rig records: its signals (names, recorded units, groups, the
x-axis hint of the loops), one sample's values in that order, and the run's metadata.

Recorded signals (units in each label): per corner (fl, fr, rl, rr) wheel travel, camber, toe,
steer, half-track, wheel centre, measured pad height and vertical force; the rig inputs; spring and
damper forces; every bushing direction's deflection and force (one group per bushing); case, phase,
time since the input start and the loop-closure error. Camber, toe and half-track carry an
``x_axis`` hint: wheel travel (pumping, roll) or the pad force or torque of the test. The ``case``
signal (1-based) and the ``cases`` list of the run metadata (label, parameters, start,
bushings-on, input-start and end times) tell the cases apart.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from elastokin.vehicle.model.definition import CORNERS, is_rotation
from elastokin.vehicle.model.elements import Channel
from elastokin.vehicle.scenarios.channels import CORNER_TAGS, INPUT_CHANNELS, channel_quantity
from elastokin.vehicle.scenarios.road_scenario import RoadScenario
from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.vehicle.scenarios.schedule import CaseSchedule
from elastokin.vehicle.simulation.outputs import RIG_WHEEL, MeasuredColumns, SampleBlock
from elastokin.core import units
from elastokin.core.files import read_text
from elastokin.core.units import DEG_PER_RAD, MM_PER_M
from elastokin.core.provenance import git_revision, software_version
from elastokin.recordings.run_format import RunMetadata, SignalSpec

#: Recorded unit of each input quantity.
INPUT_UNITS = {"pad_z": "mm", "pad_fx": "N", "pad_fy": "N", "pad_mz": "N·m", "rack": "mm"}
_TAGS = tuple(CORNER_TAGS[c] for c in CORNERS)


class SignalLayout:
    """The recorded signals of a rig, and a block of samples' values in the same order."""

    def __init__(self, x_quantity: str | None, bushings: Sequence[str] = (), springs: Sequence[str] = (),
                 dampers: Sequence[str] = ()):
        """Wheel, pad and input signals, then each named spring's and damper's force and each bushing
        direction's (``"<bushing>.<direction>"``) deflection and force, read from the rig's measured
        vectors (:attr:`elastokin.vehicle.simulation.rig.KCRig.columns`)."""
        columns = MeasuredColumns((), RIG_WHEEL, len(springs), len(dampers), len(bushings))

        def hint(tag: str) -> str | None:
            return f"{x_quantity}_{tag}" if x_quantity else None

        specs = [SignalSpec(f"wheel_travel_{t}", "mm", "wheel_travel") for t in _TAGS]
        for quantity, unit in (("camber", "deg"), ("toe", "deg"), ("half_track", "mm")):
            specs += [SignalSpec(f"{quantity}_{t}", unit, quantity, hint(t)) for t in _TAGS]
        specs += [SignalSpec(f"steer_{t}", "deg", "steer") for t in _TAGS]
        specs += [SignalSpec(f"wheel_centre_{a}_{t}", "mm", "wheel_centre") for t in _TAGS for a in "xyz"]
        specs += [SignalSpec(f"pad_height_{t}", "mm", "pads") for t in _TAGS]
        specs += [SignalSpec(f"pad_fz_{t}", "N", "pads") for t in _TAGS]
        # the wheels' signals, in the order above: measured columns and their factors to the recorded units
        read = [("travel", MM_PER_M), ("camber", DEG_PER_RAD), ("toe", DEG_PER_RAD), ("half_track", MM_PER_M),
                ("steer", DEG_PER_RAD)]
        self._columns = np.concatenate([columns.wheel(q) for q, _ in read]
                                       + [np.ravel(np.column_stack([columns.wheel(f"centre_{a}") for a in "xyz"])),
                                          columns.wheel("pad_height"), columns.wheel("pad_fz")])
        self._scale = np.concatenate([np.full(4, f) for _, f in read] + [np.full(12, MM_PER_M), np.full(4, MM_PER_M),
                                                                         np.ones(4)])
        self.input_scale = np.array([units.per_si(INPUT_UNITS[channel_quantity(ch)]) for ch in INPUT_CHANNELS])
        specs += [SignalSpec(ch, INPUT_UNITS[channel_quantity(ch)], "inputs") for ch in INPUT_CHANNELS]
        self.suspension = SuspensionSignals(columns, bushings, springs, dampers)
        self.specs = specs + self.suspension.specs

    def values(self, block: SampleBlock) -> np.ndarray:
        """The block's values (samples, signals), in the recorded units and the order of :attr:`specs`."""
        return np.hstack([block.measured[:, self._columns] * self._scale, block.inputs * self.input_scale,
                          self.suspension.values(block)])


class SuspensionSignals:
    """The signals every run of the car records, on the rig or on the road, after its own: each
    named spring's and damper's force, each bushing direction's (``"<bushing>.<direction>"``)
    deflection and force (one group per bushing), then case, phase, time since the input started
    and the loop-closure error; read from the car's measured vectors (``columns``)."""

    def __init__(self, columns: MeasuredColumns, bushings: Sequence[str] = (), springs: Sequence[str] = (),
                 dampers: Sequence[str] = ()):
        """The signals of the named parts, read from measured vectors of ``columns``."""
        self.columns = columns
        self.springs, self.dampers, self.bushings = list(springs), list(dampers), list(bushings)
        specs = [SignalSpec(f"{n}_force", "N", "springs") for n in self.springs]
        specs += [SignalSpec(f"{n}_force", "N", "dampers") for n in self.dampers]
        rotation = np.array([is_rotation(n) for n in self.bushings], dtype=bool)
        self.deflection_scale = np.where(rotation, DEG_PER_RAD, MM_PER_M)
        for name, rot in zip(self.bushings, rotation):
            bushing, direction = name.split(".")
            stem = f"{bushing}_{direction}"
            specs += [SignalSpec(f"{stem}_deflection", "deg" if rot else "mm", f"bushing_{bushing}"),
                      SignalSpec(f"{stem}_force", "N·m" if rot else "N", f"bushing_{bushing}")]
        specs += [SignalSpec("case", "-", "run"), SignalSpec("phase", "-", "run"),
                  SignalSpec("input_time", "s", "run"), SignalSpec("closure_error", "mm", "run")]
        self.specs = specs

    def values(self, block: SampleBlock) -> np.ndarray:
        """Their values (samples, signals) in ``block``, in the recorded units and the order of :attr:`specs`."""
        m, c = block.measured, self.columns
        n = len(m)
        bushing = np.empty((n, 2 * len(self.bushings)))
        bushing[:, 0::2] = m[:, c.deflection] * self.deflection_scale
        bushing[:, 1::2] = m[:, c.force]
        return np.column_stack([m[:, c.springs], m[:, c.dampers], bushing, np.full(n, float(block.case)),
                                np.full(n, float(block.phase)), block.input_time_s, m[:, c.closure_error] * MM_PER_M])


def road_facts(steering_ratio: float, wheelbase_m: float, tyre_file: Path) -> dict[str, Any]:
    """What a road run's metadata says of its car besides the vehicle file: the kinematic overall
    steering ratio, the wheelbase [m], and the tyre's property file, path and text."""
    return {"steering_ratio": steering_ratio, "wheelbase_m": wheelbase_m, "tyre_file": str(tyre_file),
            "tyre_tir": read_text(tyre_file)}


def run_metadata(scenario: Scenario | RoadScenario, plan: list[CaseSchedule], duration_scale: float, dt: float,
                 channels: Sequence[Channel] | None = None, road: Mapping[str, Any] | None = None,
                 vehicle_yaml: str = "", source: str | None = None) -> RunMetadata:
    """The metadata of a run of ``scenario``: the scenario, the schedule of its cases (a measured
    road case's log with them), and (for a simulated run, its bushing ``channels`` given) the
    vehicle file's text ``vehicle_yaml`` and the bushing parameters; on the road, the throttle, the
    manoeuvre and the facts of the car ``road`` gives (:func:`road_facts`); software version and
    revision; the ``source`` (default ``simulation`` for a simulated run, else ``rig``)."""
    cases = []
    for k, (case, s) in enumerate(zip(scenario.cases, plan), start=1):
        entry = {"case": k, "label": case.label, "parameters": dict(case.parameters), "cycles": case.cycles,
                 "start_s": s.start_s, "bushings_on_s": s.phase_start_s(1, dt),
                 "input_start_s": s.phase_start_s(len(s.steps) - 1, dt), "end_s": s.end_s(dt)}
        w = case.waveform
        log = getattr(case, "log", None)
        if log is not None:   # a measured case: the recording carries its log as read
            entry["input_log"] = {"file": log.file, "csv": log.text, "filter_hz": log.filter_hz,
                                  "log_rate_hz": log.log_rate_hz, "resampled_hz": log.rate_hz}
        elif w is not None and not w.sines and len(w.values) > 2 and w.values[-1] == w.values[-2]:
            entry["hold_from_s"] = entry["input_start_s"] + w.times_s[-2] * duration_scale  # the final hold
        cases.append(entry)
    simulated = channels is not None
    model = {"vehicle_file": str(scenario.vehicle),
             "bushing_model": scenario.bushing_model or "as in the vehicle file"} if simulated else {}
    if isinstance(scenario, RoadScenario):
        model |= {"throttle": scenario.throttle, "manoeuvre": scenario.manoeuvre, **(road or {})}
    return RunMetadata(
        scenario_yaml=scenario.text,
        vehicle_yaml=vehicle_yaml if simulated else "",
        bushing_parameters={ch.name: {**asdict(ch.params), "effects": asdict(ch.effects)}
                            for ch in channels} if simulated else {},
        software_version=software_version(),
        git_revision=git_revision(),
        extra={"scenario": scenario.name, "type": scenario.type, "description": scenario.description,
               "scenario_file": str(scenario.path), **model, "axles": list(getattr(scenario, "axles", ())),
               "x_quantity": getattr(scenario, "x_quantity", None), "duration_scale": duration_scale,
               "output_rate_hz": scenario.output_rate_hz, "timestep_s": dt,
               "limits": asdict(scenario.limits), "settle": asdict(scenario.settle), "cases": cases},
        source=source or ("simulation" if simulated else "rig"),
    )
