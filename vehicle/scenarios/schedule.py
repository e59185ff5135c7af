"""When things happen in a run of a scenario: each case's phases (on the rig: settle with the
bushings linear, settle with their laws on, the input; on the road the same with a straight run at
speed before the input), in whole output intervals, one case after the other on one time axis."""

from __future__ import annotations

import math
from dataclasses import astuple, dataclass

from elastokin.vehicle.scenarios.road_scenario import RoadScenario
from elastokin.vehicle.scenarios.scenario import MAX_TIMESTEP_S, MIN_TIMESTEP_S, Scenario
from elastokin.core.errors import InputError

#: Largest factor on a scenario's durations (slower runs than that are typing errors).
MAX_DURATION_SCALE = 100.0
#: The phases of a case, in order (the ``phase`` signal of a recording is the index): on the rig
#: and on the road.
PHASES = ("settle, bushings linear", "settle, bushing laws on", "input")
ROAD_PHASES = ("at rest, bushings linear", "at rest, bushing laws on", "straight at speed", "input")


@dataclass(frozen=True)
class CaseSchedule:
    """Step counts of a case's phases and its times in the file [s]."""

    steps: tuple[int, ...]          #: steps of each phase, multiples of the output interval
    start_s: float                  #: time of its first sample in the file

    def phase_start_s(self, phase: int, dt: float) -> float:
        """Start of ``phase`` (index in PHASES) in the file [s], for rig steps of ``dt`` [s]."""
        return self.start_s + sum(self.steps[:phase]) * dt

    def end_s(self, dt: float) -> float:
        """Time of the case's last sample in the file [s], for rig steps of ``dt`` [s]."""
        return self.start_s + sum(self.steps) * dt


@dataclass(frozen=True)
class Progress:
    """Where a run is, passed to the progress callback after every recorded sample."""

    case: int              #: 1-based
    cases: int
    label: str
    phase: int             #: index in PHASES (ROAD_PHASES on the road)
    phase_name: str        #: the phase's name
    done_s: float          #: simulated time of the whole run so far [s]
    total_s: float         #: simulated time of the whole run [s]


def schedule(scenario: Scenario | RoadScenario, duration_scale: float, dt: float) -> list[CaseSchedule]:
    """Phase lengths of every case (settle times and inputs scaled by ``duration_scale``), each
    rounded up to whole output intervals, and each case's start in the file: case k+1's first
    sample follows case k's last one by one output interval. InputError for a scale that is not
    finite, positive and at most :data:`MAX_DURATION_SCALE`."""
    if not (math.isfinite(duration_scale) and 0.0 < duration_scale <= MAX_DURATION_SCALE):
        raise InputError(f"expected a duration scale > 0 and at most {MAX_DURATION_SCALE:g}, got {duration_scale}",
                         key="duration_scale")
    every = output_interval(scenario, dt)
    out, start = [], 0.0
    for case in scenario.cases:
        seconds = (*astuple(scenario.settle), case.duration_s)
        steps = tuple(every * math.ceil(round(s * duration_scale / dt, 6) / every) for s in seconds)
        out.append(CaseSchedule(steps, start))
        start += (sum(steps) + every) * dt
    return out


def timestep(scenario: Scenario | RoadScenario, longest_s: float = MAX_TIMESTEP_S) -> float:
    """The run's time step [s]: the longest at most ``longest_s`` that divides the output interval
    and resolves every case's input as written (:meth:`Case.longest_step_s`; a duration scale
    shortens a quick run, not its step), but not below MIN_TIMESTEP_S. 50 Hz outputs step at 2 ms,
    200 Hz at 5/3 ms."""
    interval = 1.0 / scenario.output_rate_hz
    longest = min([longest_s] + [case.longest_step_s() for case in scenario.cases])
    steps = min(math.ceil(round(interval / longest, 9)), max(1, math.floor(round(interval / MIN_TIMESTEP_S, 9))))
    return interval / steps


def check_timestep(scenario: Scenario | RoadScenario, dt: float) -> None:
    """ValueError unless ``dt`` [s] divides the scenario's output interval (else the samples would
    come at another rate than the recording says)."""
    steps = 1.0 / (scenario.output_rate_hz * dt)
    if not (dt > 0.0 and abs(steps - round(steps)) <= 1e-9 * max(1.0, steps)):
        raise ValueError(f"a time step of {dt:g} s does not divide the {1.0 / scenario.output_rate_hz:g} s "
                         f"output interval of {scenario.name}")


def output_interval(scenario: Scenario | RoadScenario, dt: float) -> int:
    """Rig steps of ``dt`` [s] between recorded samples."""
    return max(1, round(1.0 / (scenario.output_rate_hz * dt)))
