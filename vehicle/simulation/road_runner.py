"""Playing a road scenario: the cases one after the other on one time axis, each on a freshly built
car, yielding the samples that a recording keeps in blocks (:mod:`elastokin.recordings.recorder`).

Each case goes through :data:`elastokin.vehicle.scenarios.schedule.ROAD_PHASES`: 0, at rest and braked with
every bushing direction linear (the car settles on its tyres); 1, at rest with the bushing laws on
from their virgin state; 2, launched at the case's speed (wheels rolling without slip) and run
straight with the speed held (the steering wheel at the input's first angle); 3, the input: the
steering wheel and the driver's speed as the scenario says. The car runs in the world's x direction at the start of phase 2.

A run stops with :class:`~elastokin.vehicle.simulation.runner.DivergenceError` when the suspension leaves
its valid range (as on the rig) or, once at speed, when the body's sideslip exceeds the
scenario's limit (the car spun) or a wheel stays off the ground longer than allowed; the samples
up to the one that shows it are yielded first.
"""

from __future__ import annotations

import math
from typing import Callable, Iterator

import numpy as np

from elastokin.vehicle.model.definition import CORNERS, VehicleDefinition
from elastokin.vehicle.scenarios.road_scenario import RoadCase, RoadScenario, steering_and_speed
from elastokin.vehicle.scenarios.schedule import ROAD_PHASES, CaseSchedule, Progress, output_interval
from elastokin.vehicle.simulation.outputs import MeasuredColumns, SampleBlock
from elastokin.vehicle.simulation.road import N_INPUTS, RoadCar
from elastokin.vehicle.simulation.runner import CaseSamples, PlayedScenario, blocks_of
from elastokin.core.units import DEG_PER_RAD

#: The brake that holds the car while it settles [N·m per wheel] (far above what the slope of the
#: settling car asks).
SETTLE_BRAKE_NM = 500.0


def road_divergence(block: SampleBlock, columns: MeasuredColumns, scenario: RoadScenario, lifted_s: np.ndarray,
                    dt_s: float) -> tuple[int, str] | None:
    """The first row of ``block`` (at speed) at which the body's sideslip exceeds the scenario's
    limit (the car spun) or a wheel has been off the ground too long, and what; None if none.
    ``lifted_s`` (per wheel, updated here) is how long each wheel has been off the ground, ``dt_s``
    the time between rows."""
    sideslip = block.measured[:, columns.of("sideslip")]
    load = block.measured[:, columns.wheel("Fz_N")]
    for row in range(len(sideslip)):
        if abs(sideslip[row]) > scenario.limits.sideslip_rad:
            return row, (f"body sideslip {sideslip[row] * DEG_PER_RAD:.1f} deg beyond the limit "
                         f"{scenario.limits.sideslip_rad * DEG_PER_RAD:g} deg (the car spun)")
        for k, corner in enumerate(CORNERS):
            lifted_s[k] = lifted_s[k] + dt_s if load[row, k] <= 0.0 else 0.0
            if lifted_s[k] > scenario.limits.wheel_lift_s:
                return row, (f"wheel {corner} off the ground for {lifted_s[k]:.2f} s, beyond the limit "
                             f"{scenario.limits.wheel_lift_s:g} s")
    return None


class RoadRun(PlayedScenario):
    """The cases of a road scenario played one after the other on ``vehicle``, each on a fresh car."""

    phases = ROAD_PHASES

    def __init__(self, scenario: RoadScenario, vehicle: VehicleDefinition, duration_scale: float = 1.0,
                 progress: Callable[[Progress], None] | None = None, timestep_s: float | None = None,
                 poses: bool = True):
        super().__init__(scenario, vehicle, duration_scale, progress, lambda v, o, b: RoadCar(v, options=o, built=b), timestep_s,
                         poses)

    def _case(self, car: RoadCar, case: RoadCase, number: int, when: CaseSchedule) -> Iterator[SampleBlock]:
        """The samples of one case from a fresh car, one every output interval, in blocks of at most
        :data:`~elastokin.vehicle.simulation.runner.BLOCK_SAMPLES`."""
        dt, scenario = self.dt, self.scenario
        every = output_interval(scenario, dt)
        blocks = CaseSamples(self, car, number, case.label, when, sum(when.steps[:3]))
        lifted = np.zeros(len(CORNERS))
        # at speed only: before, wheels touch down and the body's slip means nothing
        at_speed = lambda b: road_divergence(b, car.columns, scenario, lifted, every * dt)

        def hold(phase: int, speed: float, angle: float = 0.0) -> Iterator[SampleBlock]:
            for samples in blocks_of(when.steps[phase] // every):
                held = math.isnan(speed)   # the throttle held: no inputs, the speed controller idle
                u = _NO_INPUTS if held else car.drive_inputs(np.full(samples * every, angle),
                                                             np.full(samples * every, speed))
                yield from blocks.measure(phase, samples, every, u, np.array([[angle, speed]] * samples),
                                          at_speed if phase >= 2 else None)

        car.set_brakes(SETTLE_BRAKE_NM)
        with car.bushing_laws_off():
            yield from blocks.measure(0, 1, 0, _NO_INPUTS, np.array([[0.0, math.nan]]))
            yield from hold(0, math.nan)
        yield from hold(1, math.nan)
        car.set_brakes(0.0)
        car.set_speed(case.speed_mps)
        yield from hold(2, case.speed_mps, float(case.steering(np.zeros(1))[0]))   # straight at the input's first angle
        for samples in blocks_of(when.steps[3] // every):
            t = (blocks.step - blocks.input_start + np.arange(1, samples * every + 1)) * dt / self.duration_scale
            steering, speed = steering_and_speed(case, t, scenario.throttle)
            ahead = case.steering(t + car.rack_lead_s / self.duration_scale)
            at_samples = slice(every - 1, None, every)
            yield from blocks.measure(3, samples, every, car.drive_inputs(ahead, speed),
                                      np.column_stack([steering[at_samples], speed[at_samples]]), at_speed)


_NO_INPUTS = np.zeros((0, N_INPUTS))
