"""Run a scenario on the K&C rig and record it: one MCAP file per scenario run, the cases one after
the other on one time axis.

Each case starts from a freshly built rig at design position and goes through three phases,
recorded in the ``phase`` signal: 0, rest with every bushing direction linear at its reference
stiffness (the car settles under gravity); 1, rest with the bushing laws switched on from their
virgin state; 2, the input. Case k+1's first sample follows case k's last one by one output
period; the ``case`` signal (1-based) and the ``cases`` list of the run metadata (label, parameters,
start, bushings-on, input-start and end times) tell them apart.

Recorded signals (units in each label): per corner (fl, fr, rl, rr) wheel travel, camber, toe,
steer, half-track, wheel centre, measured pad height and vertical force; the rig inputs; spring and
damper forces; every bushing direction's deflection and force (one group per bushing); case, phase,
time since the input start and the loop-closure error. Camber, toe and half-track carry an
``x_axis`` hint: wheel travel (pumping, roll) or the pad force or torque of the test.

A run stops with :class:`DivergenceError` (time, bushing, direction, value) when the state turns
non-finite, MuJoCo reports an unstable acceleration, a bushing deflects beyond the scenario's limits
or a loop closure opens beyond its bound; the file is then closed and marked incomplete, as it is on
Ctrl-C or any other exception (:class:`vsim_recordings.run_writer.RunWriter`).
"""

from __future__ import annotations

import importlib.metadata
import math
import subprocess
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Callable, Sequence

import mujoco
import numpy as np

from vsim_core.errors import InputError
from vsim_core.shipped import ROOT
from vehicle.model.builder import CORNERS, BuildOptions
from vehicle.model.definition import VehicleDefinition, load_vehicle
from vsim_recordings.run_reader import Run
from vsim_recordings.run_writer import RunMetadata, RunWriter, SignalSpec, geometry_from_model
from vehicle.simulation.rig import KCRig, RigOutputs
from vehicle.scenarios.scenario_file import CORNER_TAGS, INPUT_CHANNELS, Case, Scenario, input_quantity

MM, DEG = 1e3, math.degrees(1.0)     #: SI → recorded units (mm per m, deg per rad)
PHASES = ("settle, bushings linear", "settle, bushing laws on", "input")
#: Recorded unit and SI → unit factor of each input quantity.
_INPUT_UNITS = {"pad_z": ("mm", MM), "pad_fx": ("N", 1.0), "pad_fy": ("N", 1.0), "pad_mz": ("N·m", 1.0),
                "rack": ("mm", MM)}
_TAGS = tuple(CORNER_TAGS[c] for c in CORNERS)


class DivergenceError(RuntimeError):
    """The simulation left its valid range; the message names time, bushing, direction and value."""

    def __init__(self, time_s: float, case: str, what: str):
        super().__init__(f"diverged at t = {time_s:.3f} s (case {case}): {what}")
        self.time_s, self.case, self.what = time_s, case, what


@dataclass(frozen=True)
class Progress:
    """Where a run is, passed to the progress callback after every recorded sample."""

    case: int              #: 1-based
    cases: int
    label: str
    phase: int             #: index in PHASES
    done_s: float          #: simulated time of the whole run so far [s]
    total_s: float         #: simulated time of the whole run [s]


@dataclass(frozen=True)
class RunResult:
    """A finished run: the file, its simulated and wall-clock durations."""

    path: Path
    simulated_s: float
    wall_s: float


@dataclass(frozen=True)
class CaseSchedule:
    """Step counts of a case's phases and its times in the file [s]."""

    steps: tuple[int, int, int]     #: steps of each phase, multiples of the output interval
    start_s: float                  #: time of its first sample in the file

    def phase_start_s(self, phase: int, dt: float) -> float:
        return self.start_s + sum(self.steps[:phase]) * dt

    def end_s(self, dt: float) -> float:
        return self.start_s + sum(self.steps) * dt


def schedule(scenario: Scenario, duration_scale: float, dt: float) -> list[CaseSchedule]:
    """Phase lengths of every case (settle times and inputs scaled by ``duration_scale``), each
    rounded up to whole output intervals, and each case's start in the file."""
    every = output_interval(scenario, dt)
    out, start = [], 0.0
    for case in scenario.cases:
        seconds = (scenario.settle.before_bushings_s, scenario.settle.before_input_s, case.duration_s)
        steps = tuple(every * math.ceil(round(s * duration_scale / dt, 6) / every) for s in seconds)
        out.append(CaseSchedule(steps, start))
        start += (sum(steps) + every) * dt
    return out


def output_interval(scenario: Scenario, dt: float) -> int:
    """Rig steps between recorded samples."""
    return max(1, round(1.0 / (scenario.output_rate_hz * dt)))


# -- signals ----------------------------------------------------------------------------------------
class SignalLayout:
    """The recorded signals of a rig, and one sample's values in the same order."""

    def __init__(self, x_quantity: str | None, bushings: Sequence[str] = (), springs: Sequence[str] = (),
                 dampers: Sequence[str] = ()):
        """Wheel, pad and input signals, then each named spring's and damper's force and each bushing
        direction's (``"<bushing>.<direction>"``) deflection and force; a rig records none of those."""

        def hint(tag: str) -> str | None:
            return f"{x_quantity}_{tag}" if x_quantity else None

        specs = [SignalSpec(f"wheel_travel_{t}", "mm", "wheel_travel") for t in _TAGS]
        for quantity, unit in (("camber", "deg"), ("toe", "deg"), ("half_track", "mm")):
            specs += [SignalSpec(f"{quantity}_{t}", unit, quantity, hint(t)) for t in _TAGS]
        specs += [SignalSpec(f"steer_{t}", "deg", "steer") for t in _TAGS]
        specs += [SignalSpec(f"wheel_centre_{a}_{t}", "mm", "wheel_centre") for t in _TAGS for a in "xyz"]
        specs += [SignalSpec(f"pad_height_{t}", "mm", "pads") for t in _TAGS]
        specs += [SignalSpec(f"pad_fz_{t}", "N", "pads") for t in _TAGS]
        self.input_scale = np.array([_INPUT_UNITS[input_quantity(ch)][1] for ch in INPUT_CHANNELS])
        specs += [SignalSpec(ch, _INPUT_UNITS[input_quantity(ch)][0], "inputs") for ch in INPUT_CHANNELS]
        self.springs = list(springs)
        self.dampers = list(dampers)
        specs += [SignalSpec(f"{n}_force", "N", "springs") for n in self.springs]
        specs += [SignalSpec(f"{n}_force", "N", "dampers") for n in self.dampers]
        self.bushings = list(bushings)
        rotation = np.array([is_rotation(n) for n in self.bushings])
        self.deflection_scale = np.where(rotation, DEG, MM)
        for name, rot in zip(self.bushings, rotation):
            bushing, direction = name.split(".")
            stem = f"{bushing}_{direction}"
            specs += [SignalSpec(f"{stem}_deflection", "deg" if rot else "mm", f"bushing_{bushing}"),
                      SignalSpec(f"{stem}_force", "N·m" if rot else "N", f"bushing_{bushing}")]
        specs += [SignalSpec("case", "-", "run"), SignalSpec("phase", "-", "run"),
                  SignalSpec("input_time", "s", "run"), SignalSpec("closure_error", "mm", "run")]
        self.specs = specs

    @classmethod
    def of_rig(cls, rig: KCRig, x_quantity: str | None) -> "SignalLayout":
        """The signals of a simulated run on ``rig``."""
        c = rig.coupling
        return cls(x_quantity, [ch.name for ch in rig.car.channels], [e.name for e in c.springs],
                   [e.name for e in c.dampers])

    def values(self, o: RigOutputs, design_z: np.ndarray, inputs: np.ndarray, case: int, phase: int,
               input_time_s: float) -> np.ndarray:
        """One sample from the rig outputs ``o``, the wheel-centre heights at design [m] (order of
        CORNERS), the rig inputs (SI, INPUT_CHANNELS order), the case number, phase and input time [s]."""
        w = [o.wheels[c] for c in CORNERS]
        centre = np.array([x.wheel_centre for x in w])
        bushing = np.column_stack([o.bushing_deflection * self.deflection_scale, o.bushing_force]).ravel()
        return np.concatenate([
            (centre[:, 2] - design_z) * MM,
            [x.camber * DEG for x in w], [x.toe * DEG for x in w], [x.half_track * MM for x in w],
            [x.steer * DEG for x in w],
            centre.ravel() * MM,
            [x.pad_height * MM for x in w], [x.pad_force[2] for x in w],
            inputs * self.input_scale,
            [o.spring_force[n] for n in self.springs], [o.damper_force[n] for n in self.dampers],
            bushing,
            [case, phase, input_time_s, o.closure_error * MM],
        ])


def is_rotation(channel: str) -> bool:
    """Whether a bushing channel (``e1_front_left.rx``) is a rotation."""
    return channel.split(".")[1].startswith("r")


# -- the rig ----------------------------------------------------------------------------------------
def check_divergence(rig: KCRig, o: RigOutputs, scenario: Scenario, time_s: float, case: str) -> None:
    """Raise :class:`DivergenceError` if the state of ``rig`` left its valid range."""
    names = o.bushing_names
    bad = ~(np.isfinite(o.bushing_deflection) & np.isfinite(o.bushing_force))
    if bad.any():
        i = int(np.argmax(bad))
        bushing, direction = names[i].split(".")
        raise DivergenceError(time_s, case, f"bushing {bushing}, direction {direction}: non-finite state "
                                            f"(deflection {o.bushing_deflection[i]}, force {o.bushing_force[i]})")
    if not np.all(np.isfinite(rig.data.qpos)):
        raise DivergenceError(time_s, case, "non-finite joint positions")
    if rig.data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number:
        raise DivergenceError(time_s, case, "MuJoCo found a non-finite or huge acceleration and reset the state")
    rotation = np.array([is_rotation(n) for n in names])
    limit = np.where(rotation, scenario.limits.rotation_rad, scenario.limits.translation_m)
    ratio = np.abs(o.bushing_deflection) / limit
    i = int(np.argmax(ratio))
    if ratio[i] > 1.0:
        bushing, direction = names[i].split(".")
        scale, unit = (DEG, "deg") if rotation[i] else (MM, "mm")
        raise DivergenceError(time_s, case, f"bushing {bushing}, direction {direction}: deflection "
                                            f"{o.bushing_deflection[i] * scale:.3f} {unit} beyond the limit "
                                            f"{limit[i] * scale:g} {unit}")
    if o.closure_error > scenario.limits.closure_error_m:
        raise DivergenceError(time_s, case, f"loop-closure error {o.closure_error * MM:.3f} mm beyond the limit "
                                            f"{scenario.limits.closure_error_m * MM:g} mm")


# -- metadata ---------------------------------------------------------------------------------------
def software_version() -> str:
    """The installed vsim version, or ``unknown``."""
    try:
        return importlib.metadata.version("vsim")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def git_revision() -> str:
    """The source tree's commit (``-dirty`` if tracked files changed), or ``unknown``."""
    root = ROOT
    try:
        rev = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, check=True)
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                               capture_output=True, text=True, check=True)
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return rev.stdout.strip() + ("-dirty" if dirty.stdout.strip() else "")


def run_metadata(scenario: Scenario, plan: list[CaseSchedule], duration_scale: float, dt: float,
                 rig: KCRig | None = None) -> RunMetadata:
    """The metadata of a run of ``scenario``: the scenario, the schedule of its cases, and (for a
    simulated run, ``rig`` given) the vehicle and bushing parameters; software version and revision."""
    cases = []
    for k, (case, s) in enumerate(zip(scenario.cases, plan), start=1):
        entry = {"case": k, "label": case.label, "parameters": dict(case.parameters), "cycles": case.cycles,
                 "start_s": s.start_s, "bushings_on_s": s.phase_start_s(1, dt),
                 "input_start_s": s.phase_start_s(2, dt), "end_s": s.end_s(dt)}
        w = case.waveform
        if w is not None and not w.sines and len(w.values) > 2 and w.values[-1] == w.values[-2]:
            entry["hold_from_s"] = entry["input_start_s"] + w.times_s[-2] * duration_scale  # the final hold
        cases.append(entry)
    model = {} if rig is None else {"vehicle_file": str(scenario.vehicle),
                                    "bushing_model": scenario.bushing_model or "as in the vehicle file"}
    return RunMetadata(
        scenario_yaml=scenario.text,
        vehicle_yaml="" if rig is None else scenario.vehicle.read_text(),
        bushing_parameters={} if rig is None else {ch.name: {**asdict(ch.params), "effects": asdict(ch.effects)}
                                                   for ch in rig.car.channels},
        software_version=software_version(),
        git_revision=git_revision(),
        extra={"scenario": scenario.name, "type": scenario.type, "description": scenario.description,
               "scenario_file": str(scenario.path), **model, "axles": list(scenario.axles),
               "x_quantity": scenario.x_quantity, "duration_scale": duration_scale,
               "output_rate_hz": scenario.output_rate_hz, "timestep_s": dt,
               "limits": asdict(scenario.limits), "settle": asdict(scenario.settle), "cases": cases},
        source="simulation" if rig is not None else "rig",
    )


# -- running ----------------------------------------------------------------------------------------
def default_output(scenario: Scenario) -> Path:
    """``out/<scenario name>.mcap`` in the working directory."""
    return Path("out") / f"{scenario.name}.mcap"


def run_scenario(scenario: Scenario, output: Path, *, bushing_model: str | None = None, overwrite: bool = False,
                 duration_scale: float = 1.0, progress: Callable[[Progress], None] | None = None) -> RunResult:
    """Run every case of ``scenario`` and record them in ``output`` (one MCAP file).

    ``bushing_model`` overrides the scenario's choice; ``duration_scale`` multiplies every duration
    (settle phases, periods, holds) for quick runs. Raises InputError if ``output`` exists and not
    ``overwrite``, DivergenceError when the simulation diverges (the file is kept, incomplete).
    """
    output = Path(output)
    if bushing_model is not None:
        scenario = replace(scenario, bushing_model=bushing_model)
    started = time.perf_counter()
    play = _Play(scenario, load_vehicle(scenario.vehicle), duration_scale, progress)
    output.parent.mkdir(parents=True, exist_ok=True)
    bodies = play.bodies()
    with RunWriter(output, signals=play.layout.specs, bodies=bodies,
                   geometry=geometry_from_model(play.rig.model, bodies), metadata=play.metadata(),
                   overwrite=overwrite) as writer:
        play.run(writer)
    return RunResult(output, play.total_s, time.perf_counter() - started)


class _Memory:
    """A run's samples kept in memory (the :class:`RunWriter` interface, without body poses)."""

    def __init__(self) -> None:
        self.t_s: list[float] = []
        self.rows: list[np.ndarray] = []

    def write(self, t_s: float, values: np.ndarray, body_pos_m: np.ndarray, body_quat_wxyz: np.ndarray) -> None:
        self.t_s.append(t_s)
        self.rows.append(values)


def simulate(scenario: Scenario, vehicle: VehicleDefinition | None = None, *, duration_scale: float = 1.0,
             progress: Callable[[Progress], None] | None = None) -> Run:
    """Run every case of ``scenario`` on ``vehicle`` (default: the scenario's file) in memory.

    The result is the :class:`vsim_recordings.run_reader.Run` that :func:`run_scenario` would record, without the
    body poses: the same signals, units and metadata (``vehicle_yaml`` empty when ``vehicle`` was
    given, as it need not come from a file).
    """
    play = _Play(scenario, load_vehicle(scenario.vehicle) if vehicle is None else vehicle, duration_scale, progress)
    memory = _Memory()
    play.run(memory)
    specs = play.layout.specs
    values = np.array(memory.rows).reshape(len(memory.rows), len(specs))
    metadata = play.metadata()
    if vehicle is not None:
        metadata = replace(metadata, vehicle_yaml="", extra={**metadata.extra, "vehicle_file": "(in memory)"})
    signals = {s.name: values[:, i] for i, s in enumerate(specs)}
    return Run(path=Path("(in memory)"), t_s=np.array(memory.t_s), signals=signals,
               units={s.name: s.unit for s in specs}, groups={s.name: s.group for s in specs}, specs=specs,
               body_names=[], body_pos=np.empty((len(values), 0, 3)), body_quat_wxyz=np.empty((len(values), 0, 4)),
               geometry=[], metadata=metadata, complete=True, reason="")


class _Play:
    """The cases of a scenario played one after the other, each on a fresh rig."""

    def __init__(self, scenario: Scenario, vehicle: VehicleDefinition, duration_scale: float,
                 progress: Callable[[Progress], None] | None):
        if not duration_scale > 0:
            raise InputError(f"expected a positive duration scale, got {duration_scale}", key="--duration-scale")
        self.scenario, self.vehicle, self.duration_scale = scenario, vehicle, duration_scale
        self.progress = progress
        self.options = BuildOptions(bushing_model=scenario.bushing_model)
        self.rig = KCRig(vehicle, self.options)
        self.dt = self.rig.model.opt.timestep
        self.plan = schedule(scenario, duration_scale, self.dt)
        self.layout = SignalLayout.of_rig(self.rig, scenario.x_quantity)
        self.total_s = self.plan[-1].end_s(self.dt)

    def bodies(self) -> list[str]:
        m = self.rig.model
        return [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, i) for i in range(1, m.nbody)]

    def metadata(self) -> RunMetadata:
        return run_metadata(self.scenario, self.plan, self.duration_scale, self.dt, self.rig)

    def run(self, sink: RunWriter | _Memory) -> None:
        rig, cases = self.rig, self.scenario.cases
        for k, (case, when) in enumerate(zip(cases, self.plan), start=1):
            if k > 1:
                rig = KCRig(self.vehicle, self.options)

            def report(phase: int, t: float) -> None:
                if self.progress is not None:
                    self.progress(Progress(k, len(cases), case.label, phase, t, self.total_s))

            _run_case(rig, self.scenario, case, k, when, self.duration_scale, self.layout, sink, report)


def _run_case(rig: KCRig, scenario: Scenario, case: Case, number: int, when: CaseSchedule, duration_scale: float,
              layout: SignalLayout, writer: RunWriter | _Memory, report: Callable[[int, float], None]) -> None:
    """Simulate one case from a fresh rig, recording every output interval."""
    m, d = rig.model, rig.data
    dt = m.opt.timestep
    every = output_interval(scenario, dt)
    bodies = np.arange(1, m.nbody)
    rest = np.zeros(len(INPUT_CHANNELS))
    design = rig.measure()
    design_z = np.array([design.wheels[c].wheel_centre[2] for c in CORNERS])
    name = f"{number} '{case.label}'"
    input_start = sum(when.steps[:2])

    def record(step: int, phase: int, inputs: np.ndarray) -> None:
        t = when.start_s + step * dt
        o = rig.measure()
        values = layout.values(o, design_z, inputs, number, phase, (step - input_start) * dt)
        writer.write(t, values, d.xpos[bodies], d.xquat[bodies])
        check_divergence(rig, o, scenario, t, name)
        report(phase, t)

    step = 0

    def hold(phase: int) -> None:
        nonlocal step
        for _ in range(when.steps[phase] // every):
            rig.step(every)
            step += every
            record(step, phase, rest)

    rig.set_inputs(rest)
    with rig.bushing_laws_off():
        record(step, 0, rest)
        hold(0)
    hold(1)
    for _ in range(when.steps[2] // every):
        u = case.inputs((step - input_start + np.arange(1, every + 1)) * dt / duration_scale)
        rig.play(u)
        step += every
        record(step, 2, u[-1])
