"""Measured K&C rig recordings: the one place that writes them (format: ``data/README.md``).

A rig recording is a run file (:mod:`elastokin.recordings.run_writer`) with source ``rig``: the channels a rig
measures, under the run's names and units, the scenario that was played, and the ``case``,
``phase`` and ``input_time`` signals and per-case schedule that the runner's own functions derive
from that scenario, so that every tool reading a simulated run splits a measured one the same way.
It holds nothing about a model: no vehicle, no bushing parameters, no bodies.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from elastokin.vehicle.scenarios.channels import INPUT_CHANNELS
from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.vehicle.scenarios.schedule import PHASES, CaseSchedule, schedule, timestep
from elastokin.core.units import plausible, si
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output
from elastokin.recordings.run_format import SignalSpec
from elastokin.recordings.run_signals import SignalLayout, run_metadata
from elastokin.recordings.run_writer import RunWriter

#: The runner's group of bookkeeping signals: not measured.
_RUN_GROUP = "run"
#: What errors call the time base (``where(i, TIME_NAME)``).
TIME_NAME = "t_s"
#: Bookkeeping signals a rig recording derives from the scenario's schedule.
DERIVED = ("case", "phase", "input_time")
#: Times closer than this are the same instant [s]: CSV text and the MCAP's 1 ns stamps round them.
TIME_TOLERANCE_S = 1e-6
#: A time step longer than this many median steps is a sampling gap.
MAX_STEP_RATIO = 1.5
#: A recorded rig input follows its command to within this fraction of the channel's largest
#: command in the case, plus :data:`TRACKING_FLOOR` (a servo-hydraulic rig tracks to about 1 % of full scale)...
TRACKING_FRACTION = 0.05
#: ... in the channel's unit (a load cell's and a displacement transducer's noise and zero, widely).
TRACKING_FLOOR = {"mm": 0.5, "N": 100.0, "N·m": 10.0}
#: ... and as late or early as this [s] (a controller's and a filter's lag, tens of milliseconds).
TRACKING_LAG_S = 0.05
_LAGS = np.linspace(-TRACKING_LAG_S, TRACKING_LAG_S, 11)
_NO_POSES = (np.empty((0, 3)), np.empty((0, 4)))


def _layout(x_quantity: str | None) -> list[SignalSpec]:
    return SignalLayout(x_quantity).specs


def measured_channels() -> dict[str, str]:
    """The run channels a K&C rig measures, name → unit, in the run's order.

    Per wheel (``fl fr rl rr``): wheel travel, camber, toe, half-track, steer [deg, mm], wheel
    centre x/y/z [mm], pad height [mm] and vertical force [N]; the rig inputs: pad vertical
    displacement [mm], pad forces [N] and aligning torques [N·m] per wheel, rack [mm]. Taken from
    the runner's signal list, so the names and units are those of a simulated run.
    """
    return {s.name: s.unit for s in _layout(None) if s.group != _RUN_GROUP}


def _driven_inputs(scenario: Scenario) -> list[str]:
    """Input channels that some case of ``scenario`` moves."""
    used = np.zeros(len(INPUT_CHANNELS), dtype=bool)
    for case in scenario.cases:
        gains = case.table.values if case.table is not None else np.asarray(case.pattern)[None, :]
        used |= np.any(gains != 0.0, axis=0)
    return [ch for ch, u in zip(INPUT_CHANNELS, used) if u]


def _missing_required(scenario: Scenario, specs: list[SignalSpec], present: Mapping[str, Any]) -> list[str]:
    """Required channels absent from ``present``: every input the scenario drives, camber and toe of
    at least one wheel, and the x signal of every given wheel output (its loops are drawn against it)."""
    missing = [ch for ch in _driven_inputs(scenario) if ch not in present]
    tags = [s.name.removeprefix("camber_") for s in specs if s.name.startswith("camber_")]
    if not any(f"camber_{t}" in present and f"toe_{t}" in present for t in tags):
        missing.append("camber_<c> and toe_<c> of one wheel <c>")
    missing += [s.x_axis for s in specs if s.name in present and s.x_axis and s.x_axis not in present]
    return list(dict.fromkeys(missing))


def _check_time(t: np.ndarray, end_s: float, source: str | None, where: Callable[[int, str], str]) -> None:
    """Finite, strictly increasing, without gaps, covering [0, end_s] to within a sample step."""
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise InputError(f"time is {t[bad[0]]}; expected a finite number", source=source, key=where(bad[0], TIME_NAME))
    step = np.diff(t)
    back = np.flatnonzero(step <= 0.0)
    if back.size:
        i = back[0] + 1
        raise InputError(f"time must increase strictly: {t[i]:.9g} s follows {t[i - 1]:.9g} s",
                         source=source, key=where(i, TIME_NAME))
    median = float(np.median(step))
    gaps = np.flatnonzero(step > MAX_STEP_RATIO * median)
    if gaps.size:
        i = gaps[0] + 1
        raise InputError(f"sampling gap of {step[i - 1]:.6g} s from t = {t[i - 1]:.9g} s to {t[i]:.9g} s; expected "
                         f"steps of at most {MAX_STEP_RATIO:g} × the median step {median:.6g} s",
                         source=source, key=where(i, TIME_NAME))
    slack = median + TIME_TOLERANCE_S
    if not 0.0 <= t[0] <= slack:
        raise InputError(f"time starts at {t[0]:.9g} s; expected the scenario's start, 0 s (to within one sample "
                         f"step; shift the time base with an offset)", source=source, key=where(0, TIME_NAME))
    if t[-1] < end_s - slack:
        raise InputError(f"time ends at {t[-1]:.9g} s, before the end of the scenario at {end_s:.9g} s; "
                         f"expected a recording of the whole scenario", source=source, key=where(len(t) - 1, TIME_NAME))


def _check_signals(t: np.ndarray, signals: Mapping[str, np.ndarray], units: Mapping[str, str], source: str | None,
                   where: Callable[[int, str], str]) -> dict[str, np.ndarray]:
    """Every signal a measured channel in its run unit, as long as ``t`` and finite; as float arrays."""
    known = measured_channels()
    out = {}
    for name, values in signals.items():
        if name not in known:
            derived = f"; {', '.join(DERIVED)} are derived from the scenario" if name in DERIVED else ""
            raise InputError(f"not a channel a K&C rig measures{derived}; expected one of {', '.join(known)}",
                             source=source, key=name)
        if units.get(name) != known[name]:
            raise InputError(f"unit {units.get(name)!r}; expected {known[name]!r}, the run's unit of {name}",
                             source=source, key=name)
        array = np.asarray(values, dtype=float)
        if array.shape != t.shape:
            raise InputError(f"{array.shape} values for {t.shape} times", source=source, key=name)
        bad = np.flatnonzero(~np.isfinite(array))
        if bad.size:
            raise InputError(f"value {array[bad[0]]} at t = {t[bad[0]]:.9g} s; expected a finite number",
                             source=source, key=where(bad[0], name))
        limit = plausible(known[name])
        bad = np.flatnonzero(np.abs(array) > limit)
        if bad.size:
            raise InputError(f"value {array[bad[0]]:.6g} {known[name]} at t = {t[bad[0]]:.9g} s is beyond any plausible "
                             f"value; expected at most {limit:g} {known[name]} in magnitude", source=source,
                             key=where(bad[0], name))
        out[name] = array
    return out


def _schedule_signals(t: np.ndarray, plan: list[CaseSchedule], dt: float) -> dict[str, np.ndarray]:
    """``case`` (1-based), ``phase`` and ``input_time`` [s] at times ``t``, as the runner records them:
    a sample on a phase boundary belongs to the phase it ends; between two cases, to the next."""
    starts = np.array([p.start_s for p in plan])
    k = np.maximum(np.searchsorted(starts, t + TIME_TOLERANCE_S, side="right") - 1, 0)
    bounds = np.array([[p.phase_start_s(1, dt), p.phase_start_s(2, dt)] for p in plan])[k]
    phase = (t > bounds[:, 0] + TIME_TOLERANCE_S).astype(float) + (t > bounds[:, 1] + TIME_TOLERANCE_S)
    return {"case": k + 1.0, "phase": phase, "input_time": t - bounds[:, 1]}


def _commanded(scenario: Scenario, plan: list[CaseSchedule], dt: float, duration_scale: float,
               t: np.ndarray) -> np.ndarray:
    """The rig inputs the scenario commands at times ``t`` [s] of the file, (len(t), len(INPUT_CHANNELS))
    in SI: as the runner plays them, held at zero before each case's input and the input at
    ``input_time`` / ``duration_scale`` of the case during it."""
    at = _schedule_signals(t, plan, dt)
    out = np.zeros((len(t), len(INPUT_CHANNELS)))
    for k, case in enumerate(scenario.cases):
        rows = (at["case"] == k + 1) & (at["phase"] == 2)
        if rows.any():
            out[rows] = case.inputs(at["input_time"][rows] / duration_scale)
    return out


def _check_inputs(scenario: Scenario, plan: list[CaseSchedule], dt: float, duration_scale: float, t: np.ndarray,
                  values: Mapping[str, np.ndarray], source: str | None, where: Callable[[int, str], str]) -> None:
    """Every recorded rig input follows what ``scenario`` commands (TRACKING_FRACTION, _FLOOR and
    _LAG_S): a record of another scenario, or an input column with a wrong sign, unit or offset,
    is refused at its first sample off, with both values."""
    given = [(j, ch) for j, ch in enumerate(INPUT_CHANNELS) if ch in values]
    if not given:
        return
    known = measured_channels()
    columns = [j for j, _ in given]
    scale = np.array([si(known[ch]) for _, ch in given])
    # the command's range within the lags allowed, channel by channel (N, given): kept as it goes, not per lag
    low = high = now = _commanded(scenario, plan, dt, duration_scale, t)[:, columns] / scale
    for lag in _LAGS[_LAGS != 0.0]:
        command = _commanded(scenario, plan, dt, duration_scale, t + lag)[:, columns] / scale
        low, high = np.minimum(low, command), np.maximum(high, command)
    at = _schedule_signals(t, plan, dt)
    case, phase = at["case"].astype(int) - 1, at["phase"]
    for c, (_, ch) in enumerate(given):
        unit = known[ch]
        peaks = np.zeros(len(plan))
        np.maximum.at(peaks, case, np.maximum(np.abs(low[:, c]), np.abs(high[:, c])))   # each case's largest command
        slack = TRACKING_FRACTION * peaks[case] + TRACKING_FLOOR[unit]
        off = np.flatnonzero((values[ch] < low[:, c] - slack) | (values[ch] > high[:, c] + slack))
        if off.size:
            i, k = off[0], case[off[0]]
            raise InputError(
                f"the rig input is {values[ch][i]:.6g} {unit} at t = {t[i]:.9g} s where the scenario "
                f"{scenario.name} commands {now[i, c]:.6g} {unit} (case {k + 1} "
                f"'{scenario.cases[k].label}', {PHASES[int(phase[i])]}); expected to follow it to within "
                f"{slack[i]:.3g} {unit} ({TRACKING_FRACTION:.0%} of the case's largest command, {peaks[k]:.6g} {unit}, "
                f"+ {TRACKING_FLOOR[unit]:g} {unit}) and ±{TRACKING_LAG_S * 1e3:g} ms: a record of another scenario, "
                f"or the column's sign, unit or offset wrong?", source=source, key=where(i, ch))


def _sample(index: int, name: str) -> str:
    return f"sample {index}, {name}"


def write_rig_recording(path: str | os.PathLike[str], scenario: Scenario, t_s: np.ndarray,
                        signals: Mapping[str, np.ndarray], units: Mapping[str, str], *, rig: Mapping[str, Any],
                        duration_scale: float = 1.0, overwrite: bool = False, source: str | None = None,
                        where: Callable[[int, str], str] = _sample) -> Path:
    """Write a measured K&C rig recording of ``scenario`` to ``path`` (MCAP) and return the path.

    ``t_s`` (N,) is the time since the scenario's start [s]; ``signals`` maps channels of
    :func:`measured_channels` to (N,) arrays in the units ``units`` names, which must be the run's.
    Required: every input channel the scenario drives, camber and toe of at least one wheel, and the
    x signal (wheel travel, or the pad force or torque of the test) of every wheel output given.
    ``rig`` is free-form metadata (name, notes, ...; ``sample_rate_hz`` defaults to 1 / the median
    step); ``duration_scale`` is the factor the scenario's durations were played at (as
    ``vsim run --duration-scale``). ``source`` and ``where(sample index, channel name)`` name the
    data in errors (the CSV importer names its file, lines and columns).

    Raises :class:`InputError` for an existing ``path`` without ``overwrite``, an unknown channel or
    unit, a missing required channel, a non-finite value, a time base that is not strictly
    increasing, has a sampling gap (a step over 1.5 × the median) or does not cover the scenario,
    or a rig input (pad travel, pad force or torque, rack) that does not follow the scenario's
    command (to within 5 % of the channel's largest command in the case + 0.5 mm, 100 N or 10 N·m, ±50 ms);
    nothing is written then, nor if writing fails (the file appears complete or not at all).
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise InputError("the output exists; pass --overwrite (overwrite=True) to replace it", source=str(path))
    t = np.asarray(t_s, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise InputError(f"expected at least two samples in one time vector, got shape {t.shape}", source=source)
    values = _check_signals(t, signals, units, source, where)
    specs = [s for s in _layout(scenario.x_quantity) if s.name in values or s.name in DERIVED]
    missing = _missing_required(scenario, specs, values)
    if missing:
        raise InputError(f"missing required channel(s) {', '.join(missing)}; expected every input the scenario "
                         f"drives, camber and toe of one wheel, and the x signal of every wheel output given "
                         f"(data/README.md)", source=source, key="channels")
    dt = timestep(scenario)
    plan = schedule(scenario, duration_scale, dt)
    _check_time(t, plan[-1].end_s(dt), source, where)

    _check_inputs(scenario, plan, dt, duration_scale, t, values, source, where)
    values.update(_schedule_signals(t, plan, dt))
    metadata = run_metadata(scenario, plan, duration_scale, dt)
    metadata.extra["rig"] = {"sample_rate_hz": 1.0 / float(np.median(np.diff(t))), **rig}
    table = np.column_stack([values[s.name] for s in specs])
    with atomic_output(path) as tmp, RunWriter(tmp, signals=specs, bodies=[], geometry=[], metadata=metadata,
                                                overwrite=True) as writer:
        for time_s, row in zip(t, table):
            writer.write(time_s, row, *_NO_POSES)
    return path
