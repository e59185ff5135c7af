"""Playing a scenario on the K&C rig: the cases one after the other on one time axis, each from a
freshly built rig, yielding the samples that a recording keeps (:mod:`vsim_recordings.recorder`
records them in a file or in memory).

Each case goes through the three phases of :data:`vehicle.scenarios.schedule.PHASES`: 0, rest with
every bushing direction linear at its reference stiffness (the car settles under gravity); 1, rest
with the bushing laws switched on from their virgin state; 2, the input. Case k+1's first sample
follows case k's last one by one output interval.

A run stops with :class:`DivergenceError` (time, bushing, direction, value) when the state turns
non-finite, MuJoCo reports an unstable acceleration, a bushing deflects beyond the scenario's
limits or a loop closure opens beyond its bound; the sample that shows it is yielded first, so that
a recording keeps it.
"""

from __future__ import annotations

import functools
from typing import Any, Callable, Iterator

import mujoco
import numpy as np

from vehicle.model.definition import CORNERS, VehicleDefinition, is_rotation
from vehicle.model.elements import BuildOptions
from vehicle.scenarios.channels import INPUT_CHANNELS
from vehicle.scenarios.road_scenario import RoadScenario
from vehicle.scenarios.scenario import Case, Scenario
from vehicle.scenarios.schedule import PHASES, CaseSchedule, Progress, output_interval, schedule
from vehicle.simulation.outputs import RigOutputs, Sample
from vehicle.simulation.rig import KCRig
from vsim_core.units import DEG_PER_RAD, MM_PER_M


class DivergenceError(RuntimeError):
    """The simulation left its valid range; the message names time, bushing, direction and value."""

    def __init__(self, time_s: float, case: str, what: str):
        """``case`` names the case (number and label), ``what`` says what left its range."""
        super().__init__(f"diverged at t = {time_s:.3f} s (case {case}): {what}")
        self.time_s, self.case, self.what = time_s, case, what


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
    rotation, limit = _deflection_limits(names, scenario.limits.rotation_rad, scenario.limits.translation_m)
    ratio = np.abs(o.bushing_deflection) / limit
    i = int(np.argmax(ratio))
    if ratio[i] > 1.0:
        bushing, direction = names[i].split(".")
        scale, unit = (DEG_PER_RAD, "deg") if rotation[i] else (MM_PER_M, "mm")
        raise DivergenceError(time_s, case, f"bushing {bushing}, direction {direction}: deflection "
                                            f"{o.bushing_deflection[i] * scale:.3f} {unit} beyond the limit "
                                            f"{limit[i] * scale:g} {unit}")
    if o.closure_error > scenario.limits.closure_error_m:
        raise DivergenceError(time_s, case, f"loop-closure error {o.closure_error * MM_PER_M:.3f} mm beyond the "
                                            f"limit {scenario.limits.closure_error_m * MM_PER_M:g} mm")


@functools.lru_cache(maxsize=8)
def _deflection_limits(names: tuple[str, ...], rotation_rad: float, translation_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Which bushing directions turn, and each one's deflection limit (computed once per run, not per sample)."""
    rotation = np.array([is_rotation(n) for n in names])
    return rotation, np.where(rotation, rotation_rad, translation_m)


class PlayedScenario:
    """What every play of a scenario shares, on the rig or on the road: the schedule of its cases,
    the first case's car (``mount(vehicle, options)``), the simulated time and the time spent in
    the compiled stepping loop. ``duration_scale`` multiplies every duration (settle phases,
    periods, holds) for quick runs; ``progress`` is called after every sample with a :class:`Progress`;
    ``timestep_s`` is the car's time step (its convergence is measured in tools/benchmarks)."""

    #: Names of a case's phases (the ``phase`` signal is the index).
    phases: tuple[str, ...] = PHASES

    def __init__(self, scenario: Scenario | RoadScenario, vehicle: VehicleDefinition, duration_scale: float,
                 progress: Callable[[Progress], None] | None, mount: Callable[[VehicleDefinition, BuildOptions], Any],
                 timestep_s: float = BuildOptions.timestep):
        self.scenario, self.vehicle, self.duration_scale = scenario, vehicle, duration_scale
        self.progress, self._mount = progress, mount
        self.options = BuildOptions(bushing_model=scenario.bushing_model, timestep=timestep_s)
        self.dt = self.options.timestep
        self.plan = schedule(scenario, duration_scale, self.dt)   # checks the scale before the build
        #: The first case's car (each later case builds its own).
        self.car = mount(vehicle, self.options)
        self.total_s = self.plan[-1].end_s(self.dt)
        #: Wall time the cases spent in the compiled stepping loop [s] (their cars' ``stepping_s``).
        self.stepping_s = 0.0

    def bodies(self) -> list[str]:
        """Names of the model's bodies whose poses the samples carry (the world excepted)."""
        m = self.car.model
        return [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, i) for i in range(1, m.nbody)]

    def samples(self) -> Iterator[Any]:
        """Every sample of every case, in time order, each case on a fresh car (the subclass's ``_case``)."""
        car = self.car
        for k, (case, when) in enumerate(zip(self.scenario.cases, self.plan), start=1):
            if k > 1:
                car = self._mount(self.vehicle, self.options)
            try:
                yield from self._case(car, case, k, when)
            finally:
                self.stepping_s += car.stepping_s

    def _report(self, number: int, label: str, phase: int, time_s: float) -> None:
        """Tell ``progress`` (if any) where the run is."""
        if self.progress is not None:
            self.progress(Progress(number, len(self.scenario.cases), label, phase, self.phases[phase], time_s,
                                   self.total_s))


class ScenarioRun(PlayedScenario):
    """The cases of a scenario played one after the other on ``vehicle``, each on a fresh rig."""

    def __init__(self, scenario: Scenario, vehicle: VehicleDefinition, duration_scale: float = 1.0,
                 progress: Callable[[Progress], None] | None = None, timestep_s: float = BuildOptions.timestep):
        super().__init__(scenario, vehicle, duration_scale, progress, KCRig, timestep_s)

    def _case(self, rig: KCRig, case: Case, number: int, when: CaseSchedule) -> Iterator[Sample]:
        """The samples of one case from a fresh rig, one every output interval."""
        m, d = rig.model, rig.data
        dt, scenario = self.dt, self.scenario
        every = output_interval(scenario, dt)
        bodies = np.arange(1, m.nbody)
        rest = np.zeros(len(INPUT_CHANNELS))
        design = rig.measure()
        design_z = np.array([design.wheels[c].wheel_centre[2] for c in CORNERS])
        name = f"{number} '{case.label}'"
        input_start = sum(when.steps[:2])
        step = 0

        def sample(phase: int, inputs: np.ndarray) -> Iterator[Sample]:
            t = when.start_s + step * dt
            o = rig.measure()
            yield Sample(t, number, phase, (step - input_start) * dt, inputs, o, design_z, d.xpos[bodies],
                         d.xquat[bodies])
            check_divergence(rig, o, scenario, t, name)
            self._report(number, case.label, phase, t)

        def hold(phase: int) -> Iterator[Sample]:
            nonlocal step
            for _ in range(when.steps[phase] // every):
                rig.step(every)
                step += every
                yield from sample(phase, rest)

        rig.set_inputs(rest)
        with rig.bushing_laws_off():
            yield from sample(0, rest)
            yield from hold(0)
        yield from hold(1)
        for _ in range(when.steps[2] // every):
            u = case.inputs((step - input_start + np.arange(1, every + 1)) * dt / self.duration_scale)
            rig.play(u)
            step += every
            yield from sample(2, u[-1])
