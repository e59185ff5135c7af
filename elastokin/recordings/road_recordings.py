"""Measured road runs: the logs of a ``measured_steer`` scenario's cases as one recording (source
``road test``), the one place that writes them (``vsim road import``).

Each case's log, resampled as the scenario reads it (:mod:`elastokin.vehicle.scenarios.road_log`),
is placed on the time axis a simulated run of the same scenario has: its first sample at the end of
the case's straight run (the last sample of phase 2), the rest in the input phase, with the
``case``, ``phase`` and ``input_time`` signals of a simulated run, so that every tool reading a
simulated road run (its metrics, ``vsim compare``, plots, replay) reads a measured one the same
way. The signals are those every case logs, under the road run's names and units, and the speed
(the case's ``speed_kmh`` where a log has none). The metadata carries each case's CSV
as read. Nothing about a model is stored.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from elastokin.vehicle.scenarios.road_log import LOG_CHANNELS
from elastokin.vehicle.scenarios.road_scenario import RoadScenario
from elastokin.vehicle.scenarios.schedule import schedule, timestep
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output
from elastokin.core.units import DEG_PER_RAD, per_si
from elastokin.recordings.run_format import SignalSpec
from elastokin.recordings.run_signals import run_metadata
from elastokin.recordings.run_writer import RunWriter

#: The source a measured road run records.
SOURCE = "road test"
#: The group of each logged channel in a road run (``elastokin.recordings.road_signals``).
_GROUPS = {"steering_wheel": "driver", "speed": "vehicle"}
_RUN = (SignalSpec("case", "-", "run"), SignalSpec("phase", "-", "run"), SignalSpec("input_time", "s", "run"))
_NO_POSES = (np.empty((0, 3)), np.empty((0, 4)))


def logged_channels(scenario: RoadScenario) -> list[str]:
    """The channels every case of ``scenario`` logs, in :data:`LOG_CHANNELS`'s order; the speed
    always (a log without one has its case's ``speed_kmh``)."""
    common = set(LOG_CHANNELS)
    for case in scenario.cases:
        common &= {*case.log.channels, "speed"}
    return [c for c in LOG_CHANNELS if c in common]


def write_road_recording(path: str | os.PathLike[str], scenario: RoadScenario, *, overwrite: bool = False) -> Path:
    """Write the measured road run of ``scenario`` (type ``measured_steer``) to ``path`` (MCAP) and
    return the path (module docstring).

    Raises InputError for a scenario of another type, an existing ``path`` without ``overwrite``;
    nothing is written then, nor if writing fails (the file appears complete or not at all).
    """
    if scenario.type != "measured_steer":
        raise InputError(f"a {scenario.type} scenario logs nothing; expected a measured_steer scenario (its cases' "
                         f"CSV logs are the road test)", source=str(scenario.path))
    path = Path(path)
    if path.exists() and not overwrite:
        raise InputError("the output exists; pass --overwrite (overwrite=True) to replace it", source=str(path))
    names = logged_channels(scenario)
    specs = [SignalSpec(n, LOG_CHANNELS[n], _GROUPS.get(n, "vehicle")) for n in names] + list(_RUN)
    dt = timestep(scenario)
    plan = schedule(scenario, 1.0, dt)
    blocks = []
    for k, (case, when) in enumerate(zip(scenario.cases, plan), start=1):
        log = case.log
        t = log.t_s
        logged = dict(log.channels)
        logged["steering_wheel"] = case.steering(t) * DEG_PER_RAD       # the log's, as the car gets it
        logged.setdefault("speed", case.speed(t) * per_si("km/h"))      # a log without one: its case's
        phase = np.where(t > 0.0, 3.0, 2.0)   # a sample on a phase boundary belongs to the phase it ends
        columns = [logged[n] for n in names] + [np.full(t.size, float(k)), phase, t]
        blocks.append((when.phase_start_s(3, dt) + t, np.column_stack(columns)))
    metadata = run_metadata(scenario, plan, 1.0, dt, source=SOURCE)
    with atomic_output(path) as tmp, RunWriter(tmp, signals=specs, bodies=[], geometry=[], metadata=metadata,
                                                overwrite=True) as writer:
        for times, table in blocks:
            for time_s, row in zip(times, table):
                writer.write(time_s, row, *_NO_POSES)
    return path
