"""Playing a road scenario: the cases one after the other on one time axis, each on a freshly built
car, yielding the samples that a recording keeps (:mod:`vsim_recordings.recorder`).

Each case goes through :data:`vehicle.scenarios.schedule.ROAD_PHASES`: 0, at rest and braked with
every bushing direction linear (the car settles on its tyres); 1, at rest with the bushing laws on
from their virgin state; 2, launched at the case's speed (wheels rolling without slip) and run
straight with the speed held; 3, the input: the steering wheel and the driver's speed as the
scenario says. The car runs in the world's x direction at the start of phase 2.

A run stops with :class:`~vehicle.simulation.runner.DivergenceError` when the suspension leaves
its valid range (as on the rig) or, once at speed, when the body's sideslip exceeds the
scenario's limit (the car spun) or a wheel stays off the ground longer than allowed; the sample
that shows it is yielded first.
"""

from __future__ import annotations

import math
from typing import Callable, Iterator

import numpy as np

from vehicle.model.definition import CORNERS, VehicleDefinition
from vehicle.model.elements import BuildOptions
from vehicle.scenarios.road_scenario import RoadCase, RoadScenario, steering_and_speed
from vehicle.scenarios.schedule import ROAD_PHASES, CaseSchedule, Progress, output_interval
from vehicle.simulation.outputs import RoadOutputs, RoadSample
from vehicle.simulation.road import RoadCar
from vehicle.simulation.runner import DivergenceError, PlayedScenario, check_divergence
from vsim_core.units import DEG_PER_RAD

#: The brake that holds the car while it settles [N·m per wheel] (far above what the slope of the
#: settling car asks).
SETTLE_BRAKE_NM = 500.0


def check_road(car: RoadCar, o: RoadOutputs, scenario: RoadScenario, time_s: float, case: str,
               lifted_s: np.ndarray, dt_s: float) -> None:
    """Raise DivergenceError if the car left its valid range; ``lifted_s`` (per wheel, updated here)
    is how long each wheel has been off the ground, ``dt_s`` the time since the last check."""
    check_divergence(car, o, scenario, time_s, case)
    if abs(o.sideslip) > scenario.limits.sideslip_rad:
        raise DivergenceError(time_s, case, f"body sideslip {o.sideslip * DEG_PER_RAD:.1f} deg beyond the limit "
                                            f"{scenario.limits.sideslip_rad * DEG_PER_RAD:g} deg (the car spun)")
    for k, corner in enumerate(CORNERS):
        lifted_s[k] = lifted_s[k] + dt_s if o.wheels[corner].tyre[0] <= 0.0 else 0.0
        if lifted_s[k] > scenario.limits.wheel_lift_s:
            raise DivergenceError(time_s, case, f"wheel {corner} off the ground for {lifted_s[k]:.2f} s, beyond the "
                                                f"limit {scenario.limits.wheel_lift_s:g} s")


class RoadRun(PlayedScenario):
    """The cases of a road scenario played one after the other on ``vehicle``, each on a fresh car."""

    phases = ROAD_PHASES

    def __init__(self, scenario: RoadScenario, vehicle: VehicleDefinition, duration_scale: float = 1.0,
                 progress: Callable[[Progress], None] | None = None, timestep_s: float = BuildOptions.timestep):
        super().__init__(scenario, vehicle, duration_scale, progress, lambda v, o: RoadCar(v, options=o), timestep_s)

    def _case(self, car: RoadCar, case: RoadCase, number: int, when: CaseSchedule) -> Iterator[RoadSample]:
        """The samples of one case from a fresh car, one every output interval."""
        d, dt, scenario = car.data, self.dt, self.scenario
        every = output_interval(scenario, dt)
        bodies = np.arange(1, car.model.nbody)
        name = f"{number} '{case.label}'"
        input_start = sum(when.steps[:3])
        lifted = np.zeros(len(CORNERS))
        step = 0

        def sample(phase: int, steering: float, speed: float) -> Iterator[RoadSample]:
            t = when.start_s + step * dt
            o = car.measure()
            yield RoadSample(t, number, phase, (step - input_start) * dt, steering, speed, o, d.xpos[bodies],
                             d.xquat[bodies])
            if phase >= 2:   # at speed: before, wheels touch down and the body's slip means nothing
                check_road(car, o, scenario, t, name, lifted, every * dt)
            else:
                check_divergence(car, o, scenario, t, name)
            self._report(number, case.label, phase, t)

        def hold(phase: int, speed: float) -> Iterator[RoadSample]:
            nonlocal step
            u = car.drive_inputs(np.zeros(every), np.full(every, speed))
            for _ in range(when.steps[phase] // every):
                if math.isnan(speed):
                    car.step(every)
                else:
                    car.play(u)
                step += every
                yield from sample(phase, 0.0, speed)

        car.set_brakes(SETTLE_BRAKE_NM)
        with car.bushing_laws_off():
            yield from sample(0, 0.0, math.nan)
            yield from hold(0, math.nan)
        yield from hold(1, math.nan)
        car.set_brakes(0.0)
        car.set_speed(case.speed_mps)
        yield from hold(2, case.speed_mps)
        for _ in range(when.steps[3] // every):
            t = (step - input_start + np.arange(1, every + 1)) * dt / self.duration_scale
            steering, speed = steering_and_speed(case, t, scenario.throttle)
            ahead = case.steering(t + car.rack_lead_s / self.duration_scale)
            car.play(car.drive_inputs(ahead, speed))
            step += every
            yield from sample(3, float(steering[-1]), float(speed[-1]))
