"""Playing a scenario on the K&C rig: the cases one after the other on one time axis, each from a
freshly built rig, yielding the samples that a recording keeps in blocks
(:class:`elastokin.vehicle.simulation.outputs.SampleBlock`; :mod:`elastokin.recordings.recorder` records them in a
file or in memory). A block's samples are stepped and measured in one compiled call
(:meth:`elastokin.vehicle.simulation.rig.KCRig.sampled`): no Python runs between them.

Each case goes through the three phases of :data:`elastokin.vehicle.scenarios.schedule.PHASES`: 0, rest with
every bushing direction linear at its reference stiffness (the car settles under gravity); 1, rest
with the bushing laws switched on from their virgin state; 2, the input. The first two are the same
for every case of a scenario: the cases after the first start from the first's settled state
(:class:`Settled`). Case k+1's first sample follows case k's last one by one output interval.

A run stops with :class:`DivergenceError` (time, bushing, direction, value) when the state turns
non-finite, MuJoCo resets it (a non-finite or huge position, velocity or acceleration: the block
ends at the first sample after), a bushing deflects beyond the scenario's limits or a loop closure
opens beyond its bound; the samples up to the one that shows it are yielded first, so that a
recording keeps them.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any, Callable, Iterator

import mujoco
import numpy as np

from elastokin.vehicle.model.builder import CarModel
from elastokin.vehicle.model.definition import VehicleDefinition, is_rotation
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.statics import resolve_preloads
from elastokin.vehicle.scenarios.channels import INPUT_CHANNELS
from elastokin.vehicle.scenarios.road_scenario import RoadScenario
from elastokin.vehicle.scenarios.scenario import Case, Scenario
from elastokin.vehicle.scenarios.schedule import (PHASES, CaseSchedule, Progress, check_timestep, output_interval, schedule,
                                        timestep)
from elastokin.vehicle.simulation.mounted import CarState, MountedCar
from elastokin.vehicle.simulation.outputs import MeasuredColumns, SampleBlock
from elastokin.vehicle.simulation.rig import KCRig
from elastokin.vehicle.simulation.unconverged import UnconvergedTally
from elastokin.core.units import DEG_PER_RAD, MM_PER_M


class DivergenceError(RuntimeError):
    """The simulation left its valid range; the message names time, bushing, direction and value."""

    def __init__(self, time_s: float, case: str, what: str):
        """``case`` names the case (number and label), ``what`` says what left its range."""
        super().__init__(f"diverged at t = {time_s:.3f} s (case {case}): {what}")
        self.time_s, self.case, self.what = time_s, case, what


#: Samples measured in one compiled call: progress, Ctrl-C and the state checks come between calls.
BLOCK_SAMPLES = 200
#: The wheel quantities every mounting measures from the joints' positions (their non-finite values diverge).
_POSE = ("camber", "toe", "steer", "travel")


def divergence(block: SampleBlock, columns: MeasuredColumns, names: tuple[str, ...], car: MountedCar,
               scenario: Scenario | RoadScenario) -> tuple[int, str] | None:
    """The first row of ``block`` (the last ones measured on ``car``) at which the car left its
    valid range, and what left it; None if it did not: a non-finite bushing state or wheel pose, a
    bushing deflection beyond the scenario's limits, an opened loop closure (each at its row);
    non-finite joint positions now, or MuJoCo's reset of the state (at the block's last row, the
    first after the reset)."""
    m = block.measured
    found = []   # (row, priority within a row, what)
    rows = np.arange(len(m))
    deflection, force = m[:, columns.deflection], m[:, columns.force]
    bad = ~(np.isfinite(deflection) & np.isfinite(force))
    if bad.any():
        r, i = np.argwhere(bad)[0]
        bushing, direction = names[i].split(".")
        found.append((r, 0, f"bushing {bushing}, direction {direction}: non-finite state "
                            f"(deflection {deflection[r, i]}, force {force[r, i]})"))
    pose = m[:, np.concatenate([columns.wheel(q) for q in _POSE])]
    state_bad = ~np.isfinite(pose).all(axis=1)
    if state_bad.any() or not np.all(np.isfinite(car.data.qpos)):
        found.append((rows[state_bad][0] if state_bad.any() else rows[-1], 1, "non-finite joint positions"))
    if car.was_reset():   # the block ends at the first sample after it
        found.append((rows[-1], 2, "MuJoCo found a non-finite or huge position, velocity or acceleration and "
                                   "reset the state"))
    rotation, limit = _deflection_limits(names, scenario.limits.rotation_rad, scenario.limits.translation_m)
    ratio = np.abs(deflection) / limit
    beyond = ratio.max(axis=1, initial=0.0) > 1.0
    if beyond.any():
        r = rows[beyond][0]
        i = int(np.argmax(ratio[r]))
        bushing, direction = names[i].split(".")
        scale, unit = (DEG_PER_RAD, "deg") if rotation[i] else (MM_PER_M, "mm")
        found.append((r, 3, f"bushing {bushing}, direction {direction}: deflection "
                            f"{deflection[r, i] * scale:.3f} {unit} beyond the limit {limit[i] * scale:g} {unit}"))
    closure = m[:, columns.closure_error]
    opened = closure > scenario.limits.closure_error_m
    if opened.any():
        r = rows[opened][0]
        found.append((r, 4, f"loop-closure error {closure[r] * MM_PER_M:.3f} mm beyond the limit "
                            f"{scenario.limits.closure_error_m * MM_PER_M:g} mm"))
    if not found:
        return None
    row, _, what = min(found, key=lambda f: f[:2])
    return int(row), what


@functools.lru_cache(maxsize=8)
def _deflection_limits(names: tuple[str, ...], rotation_rad: float, translation_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Which bushing directions turn, and each one's deflection limit (computed once per run, not per sample)."""
    rotation = np.array([is_rotation(n) for n in names], dtype=bool)
    return rotation, np.where(rotation, rotation_rad, translation_m)


class PlayedScenario:
    """What every play of a scenario shares, on the rig or on the road: the schedule of its cases,
    the first case's car (``mount(vehicle, options, built)``, ``built`` None or the model compiled
    for the first case), the simulated time and the time spent in
    the compiled stepping loop. ``duration_scale`` multiplies every duration (settle phases,
    periods, holds) for quick runs; ``progress`` is called after every block with a :class:`Progress`;
    ``timestep_s`` is the car's time step (default the scenario's: :func:`~elastokin.vehicle.scenarios.schedule.timestep`);
    ``poses`` whether the blocks carry the bodies' poses (a recording's replay needs them)."""

    #: Names of a case's phases (the ``phase`` signal is the index).
    phases: tuple[str, ...] = PHASES

    def __init__(self, scenario: Scenario | RoadScenario, vehicle: VehicleDefinition, duration_scale: float,
                 progress: Callable[[Progress], None] | None,
                 mount: Callable[[VehicleDefinition, BuildOptions, CarModel | None], Any],
                 timestep_s: float | None = None, poses: bool = True):
        # the preloads resolved once for every case's car (each build would solve the kinematics again)
        self.scenario, self.vehicle, self.duration_scale = scenario, resolve_preloads(vehicle), duration_scale
        self.progress, self._mount = progress, mount
        if timestep_s is not None:
            check_timestep(scenario, timestep_s)
        self.options = BuildOptions(bushing_model=scenario.bushing_model,
                                    timestep=timestep(scenario) if timestep_s is None else timestep_s,
                                    **({"rig_mechanics": scenario.rig} if isinstance(scenario, Scenario) else {}))
        self.dt = self.options.timestep
        self.plan = schedule(scenario, duration_scale, self.dt)   # checks the scale before the build
        #: The first case's car (each later case mounts its own on a copy of its model, as built).
        self.car = mount(self.vehicle, self.options, None)
        self._built = self.car.car.copy()
        self.total_s = self.plan[-1].end_s(self.dt)
        #: Ids of the bodies whose poses the blocks carry: every body but the world (``poses``), or none.
        self.recorded_bodies = np.arange(1 if poses else 0, self.car.model.nbody if poses else 0, dtype=np.int64)
        #: Wall time the cases spent in the compiled stepping loop [s] (their cars' ``stepping_s``).
        self.stepping_s = 0.0
        #: The bushing steps whose solve did not converge, so far.
        self.unconverged = UnconvergedTally()

    def bodies(self) -> list[str]:
        """Names of the bodies whose poses the blocks carry."""
        m = self.car.model
        return [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, i) for i in self.recorded_bodies]

    def blocks(self) -> Iterator[SampleBlock]:
        """Every sample of every case in blocks, in time order, each case on a fresh car (the
        subclass's ``_case``)."""
        car = self.car
        for k, (case, when) in enumerate(zip(self.scenario.cases, self.plan), start=1):
            if k > 1:
                car = self._mount(self.vehicle, self.options, self._built)
            try:
                yield from self._case(car, case, k, when)
            finally:
                self.stepping_s += car.stepping_s

    def _report(self, number: int, label: str, phase: int, time_s: float) -> None:
        """Tell ``progress`` (if any) where the run is."""
        if self.progress is not None:
            self.progress(Progress(number, len(self.scenario.cases), label, phase, self.phases[phase], time_s,
                                   self.total_s))


@dataclass(frozen=True)
class Sampled:
    """One block of a case's samples as its car measured them: the case's ``phase``, the steps
    ``apart`` its samples are, the case's step count at each (samples,), the inputs recorded
    (samples, inputs), the measured vectors and the bodies' poses (:meth:`KCRig.sampled`)."""

    phase: int
    apart: int
    steps: np.ndarray
    recorded: np.ndarray
    measured: np.ndarray
    pos: np.ndarray
    quat: np.ndarray


@dataclass(frozen=True)
class Settled:
    """A scenario's car settled (phases 0 and 1, every input held at zero): the steps of each phase,
    the blocks sampled meanwhile and the car's state at the end. Every case of a scenario settles
    the same car the same way; each case after the first restores this instead of stepping it all
    again (the same bits; settling is about a tenth of a K&C case's steps)."""

    steps: tuple[int, int]
    blocks: tuple[Sampled, ...]
    state: CarState

    def replay(self, car: KCRig, blocks: CaseSamples) -> Iterator[SampleBlock]:
        """The settled blocks on ``blocks``'s case, its ``car`` put in the settled state."""
        car.restore(self.state)
        for sampled in self.blocks:
            yield from blocks.emit(sampled)


class CaseSamples:
    """The blocks of one case of ``play`` on its ``car``: each :meth:`measure` samples the car (its
    ``sampled``), places the samples on the run's time axis, checks them and reports progress."""

    def __init__(self, play: PlayedScenario, car: Any, number: int, label: str, when: CaseSchedule,
                 input_start: int):
        """``input_start``: the case's step at which its input starts."""
        self.play, self.car, self.number, self.label, self.when = play, car, number, label, when
        self.input_start = input_start
        self.names = tuple(ch.name for ch in car.car.channels)
        #: Steps the case has made so far.
        self.step = 0
        #: The bank's counts of unconverged steps already tallied (the bank is the case's own).
        self._tallied: np.ndarray | None = None
        #: The blocks sampled while a caller keeps them (a list it set), else None.
        self.history: list[Sampled] | None = None

    def measure(self, phase: int, samples: int, apart: int, inputs: np.ndarray, recorded: np.ndarray,
                also: Callable[[SampleBlock], tuple[int, str] | None] | None = None) -> Iterator[SampleBlock]:
        """``samples`` samples ``apart`` steps apart, with ``inputs`` one row per step (none: held),
        ``recorded`` (samples, inputs) the block's inputs at each sample. If the car left its valid
        range (:func:`divergence`, then ``also``), the rows up to the first that shows it, then
        DivergenceError."""
        measured, pos, quat = self.car.sampled(samples, apart, inputs, self.play.recorded_bodies)
        steps = self.step + apart * np.arange(1, len(measured) + 1)   # fewer samples after a reset
        yield from self.emit(Sampled(phase, apart, steps, recorded[:len(measured)], measured, pos, quat), also)

    def emit(self, sampled: Sampled, also: Callable[[SampleBlock], tuple[int, str] | None] | None = None
             ) -> Iterator[SampleBlock]:
        """The block of ``sampled`` (measured on this case's car, or on another case's car in the same
        state: :class:`Settled`) on the case's time axis, checked, its progress reported
        (:meth:`measure`)."""
        dt, car, steps, phase = self.play.dt, self.car, sampled.steps, sampled.phase
        self.step = int(steps[-1])
        if self.history is not None:
            self.history.append(sampled)
        block = SampleBlock(self.when.start_s + steps * dt, self.number, phase, (steps - self.input_start) * dt,
                            sampled.recorded, sampled.measured, sampled.pos, sampled.quat)
        self._tally_unconverged(float(block.time_s[0]) - sampled.apart * dt, float(block.time_s[-1]))
        found = [f for f in (divergence(block, car.columns, self.names, car, self.play.scenario),
                             also and also(block)) if f is not None]
        if found:
            row, what = min(found, key=lambda f: f[0])   # the suspension's reason first at one row
            yield block.upto(row)
            raise DivergenceError(float(block.time_s[row]), f"{self.number} '{self.label}'", what)
        yield block
        self.play._report(self.number, self.label, phase, float(block.time_s[-1]))

    def _tally_unconverged(self, from_s: float, to_s: float) -> None:
        """Add the unconverged bushing steps of the block from ``from_s`` to ``to_s`` [s] to the run's tally."""
        forces = self.car.coupling.bushings
        if forces.bank is None or not forces.bank.size:   # the laws are off, or every direction is linear
            return
        bank = forces.bank.bank
        if self._tallied is None:
            self._tallied = np.zeros(bank.size, dtype=np.int64)
        if (bank.failed_steps != self._tallied).any():
            units = ["rad" if ch.quantity == "rotation" else "m" for ch in bank.channels]
            self.play.unconverged.add([self.names[i] for i in forces.bank_idx], units, bank.failed_steps,
                                      self._tallied, bank.worst_residual, bank.tolerances, self.number, from_s, to_s)


class ScenarioRun(PlayedScenario):
    """The cases of a scenario played one after the other on ``vehicle``, each on a fresh rig."""

    def __init__(self, scenario: Scenario, vehicle: VehicleDefinition, duration_scale: float = 1.0,
                 progress: Callable[[Progress], None] | None = None, timestep_s: float | None = None,
                 poses: bool = True):
        super().__init__(scenario, vehicle, duration_scale, progress, KCRig, timestep_s, poses)
        self._settled: Settled | None = None   # the first case's settling, for the others

    def _case(self, rig: KCRig, case: Case, number: int, when: CaseSchedule) -> Iterator[SampleBlock]:
        """The samples of one case from a fresh rig, one every output interval, in blocks of at most
        :data:`BLOCK_SAMPLES` measured in compiled code."""
        dt = self.dt
        every = output_interval(self.scenario, dt)
        blocks = CaseSamples(self, rig, number, case.label, when, sum(when.steps[:2]))
        held = lambda samples: np.zeros((samples, len(INPUT_CHANNELS)))

        def hold(phase: int) -> Iterator[SampleBlock]:
            for samples in blocks_of(when.steps[phase] // every):
                yield from blocks.measure(phase, samples, every, _HELD, held(samples))

        rig.set_inputs(np.zeros(len(INPUT_CHANNELS)))
        settling = tuple(when.steps[:2])
        if self._settled is not None and self._settled.steps == settling:
            yield from self._settled.replay(rig, blocks)
        else:
            # kept only for a later case that settles alike (a diagnosis's runs are one case each)
            wanted = any(tuple(later.steps[:2]) == settling for later in self.plan[number:])
            blocks.history = [] if wanted else None
            with rig.bushing_laws_off():
                yield from blocks.measure(0, 1, 0, _HELD, held(1))
                yield from hold(0)
            yield from hold(1)
            # nor if a bushing's solve failed to converge (its report says where, per case)
            if wanted and not rig.coupling.bushings.bank.bank.failed_steps.any():
                self._settled = Settled(settling, tuple(blocks.history), rig.snapshot())
            blocks.history = None
        for samples in blocks_of(when.steps[2] // every):
            t = (blocks.step - blocks.input_start + np.arange(1, samples * every + 1)) * dt / self.duration_scale
            u = case.inputs(t)
            yield from blocks.measure(2, samples, every, u, u[every - 1::every])


_HELD = np.zeros((0, len(INPUT_CHANNELS)))


def blocks_of(samples: int) -> list[int]:
    """The sizes of ``samples`` samples cut into blocks of at most BLOCK_SAMPLES."""
    return [min(BLOCK_SAMPLES, samples - k) for k in range(0, samples, BLOCK_SAMPLES)]
