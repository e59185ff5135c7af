"""The compared samples of a K&C dataset (:mod:`elastokin.diagnosis.kc_diagnosis`): one row per sample of
a recorded case's input phase, one column per compared channel, and the vehicle run of each case
(a job: a pure function of its scenario, vehicle and duration scale, for any executor)."""

from __future__ import annotations

from contextlib import closing
from dataclasses import dataclass, replace
from typing import Callable, NamedTuple, Sequence

import numpy as np

from elastokin.cluster.executor import Executor, TaskFailed
from elastokin.core.errors import InputError
from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.scenarios.channels import INPUT_CHANNELS
from elastokin.vehicle.scenarios.scenario import Case, Scenario
from elastokin.recordings.kc_dataset import KCDataset
from elastokin.recordings.recorder import simulate

#: Measured channel families compared (the rig inputs are imposed, not compared).
COMPARED = ("wheel_travel", "camber", "toe", "half_track", "steer", "wheel_centre", "pad_height", "pad_fz")


@dataclass(frozen=True)
class Job:
    """One vehicle run of one recorded case (a scenario cut down to that case: each case starts from
    a fresh rig, so alone it gives the samples it gives in its recording)."""

    scenario: Scenario
    vehicle: VehicleDefinition
    duration_scale: float
    channels: tuple[str, ...]     #: the compared channels it gives back (what a remote worker sends)


def compared(phase: np.ndarray, case: np.ndarray) -> np.ndarray:
    """The samples of a case compared (``case``: a mask of its samples): its input phase, from the
    instant the input starts (the last sample of the settle, the car at rest: a filter or a delay
    of the rig's acquisition starts from there)."""
    on = (phase == 2) & case
    start = np.flatnonzero(on[1:] & ~on[:-1] & (phase[:-1] == 1) & case[:-1])
    on[start] = True
    return on


def run_job(job: Job) -> dict[str, np.ndarray]:
    """The compared channels of ``job``'s run over its input phase (a task of the executor)."""
    run = simulate(replace(job.scenario, bushing_model=None), job.vehicle, duration_scale=job.duration_scale)
    on = compared(run.signals["phase"], np.ones(len(run.t_s), dtype=bool))
    return {name: run.signals[name][on] for name in job.channels}


@dataclass(frozen=True)
class Test:
    """One recorded case, the unit of the split between fitting and scoring."""

    name: str
    job: Job                  #: the baseline's run of it
    rows: np.ndarray          #: its rows in the layout
    samples: np.ndarray       #: each row's sample of the input phase (0: its start instant; a damaged
    #: recording lacks some)
    whole: bool               #: from a recording read whole: it holds every sample of the input phase
    period: int = 0           #: samples in a period of its input, repeated (0: not repeated)


class Clock(NamedTuple):
    """Where each compared row lies in its recording (a rig session, its transducers' zeros drifting
    and its noise running on through it)."""

    time_s: np.ndarray          #: (N,) time since the recording started [s]
    recording: np.ndarray       #: (N,) the recording's index
    names: tuple[str, ...]      #: each recording's name, by index


@dataclass
class Layout:
    """The compared samples of the dataset: one row per sample of an input phase, one column per
    compared channel, the tests one after the other."""

    channels: list[str]
    measured: np.ndarray          #: (N, C) in the channels' units
    input_time: np.ndarray        #: (N,) time since its case's input started [s]
    recording: np.ndarray         #: (N,) index of the recording of each row (a rig session: one zero per channel)
    test: np.ndarray              #: (N,) index of the test of each row
    tests: list[Test]
    damage: tuple[str, ...] = ()  #: what the dataset's damaged recordings lack (their cases unrecorded too)
    inputs: np.ndarray | None = None   #: (N, len(INPUT_CHANNELS)) the rig's recorded commands (SI)
    #: (N,) time since its recording started [s] (None: ``input_time``, each test its own recording)
    recording_time_s: np.ndarray | None = None
    recordings: tuple[str, ...] = ()   #: each recording's name, by index (default: "recording k")
    units: tuple[str, ...] = ()        #: each channel's unit (default: none said)

    @classmethod
    def of(cls, data: KCDataset, vehicle: VehicleDefinition) -> "Layout":
        """The compared channels of a dataset, case by case, and the baseline ``vehicle``'s run of each case."""
        first = data.tests[0].run
        channels = [n for n in first.signals if n.rsplit("_", 1)[0] in COMPARED or n.rsplit("_", 2)[0] in COMPARED]
        measured, commands, times, clock, recording, tests, start, unrecorded = [], [], [], [], [], [], 0, []
        for k, t in enumerate(data.tests):
            run, scale = t.run, float(t.run.metadata.extra.get("duration_scale", 1.0))
            phase, number = run.signals["phase"], run.signals["case"].astype(int)
            for c, case in enumerate(t.scenario.cases, start=1):
                on = compared(phase, number == c)
                n = int(on.sum())
                if n == 0:   # only a damaged recording lacks a case's whole input
                    unrecorded.append(f"{t.file.name}: case {c} ({case.label}) has no sample of its input: left out")
                    continue
                measured.append(np.column_stack([run.signals[ch][on] for ch in channels]))
                commands.append(np.column_stack([run.signals[ch][on] if ch in run.signals else np.zeros(n)
                                                 for ch in INPUT_CHANNELS]))
                times.append(run.signals["input_time"][on])
                clock.append(run.t_s[on] - run.t_s[0])
                recording.append(np.full(n, k))
                job = Job(replace(t.scenario, cases=[case]), vehicle, scale, tuple(channels))
                samples = np.arange(n) if run.complete else _samples(times[-1], t.scenario, f"{t.file.name}, case {c}")
                tests.append(Test(f"{t.name} case {c} ({case.label})", job, np.arange(start, start + n), samples,
                                  run.complete, _period(case, scale, t.scenario.output_rate_hz)))
                start += n
        if not tests:
            raise InputError("no recording holds a sample of a case's input: nothing to diagnose",
                             source=str(data.path))
        test = np.concatenate([np.full(len(t.rows), i) for i, t in enumerate(tests)])
        return cls(channels, np.vstack(measured), np.concatenate(times), np.concatenate(recording), test, tests,
                   (*data.damage, *unrecorded), np.vstack(commands), np.concatenate(clock),
                   tuple(t.name for t in data.tests), tuple(first.units[ch] for ch in channels))

    @property
    def clock(self) -> Clock:
        """The rows' recordings by their clock (``recording_time_s``, ``recording``, ``recordings``); a
        layout without the recordings' clock takes each test as its own recording (its ``input_time``
        restarts with each)."""
        if self.recording_time_s is None:
            return Clock(self.input_time, self.test, tuple(f"recording {k}" for k in range(len(self.tests))))
        return Clock(self.recording_time_s, self.recording, self.recordings
                     or tuple(f"recording {k}" for k in range(int(self.recording.max()) + 1)))

    def jobs(self, vehicle: VehicleDefinition, tests: Sequence[int]) -> list[Job]:
        """The runs of ``tests`` (indices) on ``vehicle``."""
        return [replace(self.tests[i].job, vehicle=vehicle) for i in tests]


class RunRows(Sequence[np.ndarray]):
    """The compared rows of sets of simulated runs, each set's held on its tests' rows alone and read
    as (N, C) rows, NaN in the other tests' (a screening's hundred-odd runs on the training tests
    without the held-out tests' NaN: 119 × (N, C) float64 were 255 MiB of the shipped dataset's
    diagnosis)."""

    def __init__(self, layout: Layout, tests: Sequence[Sequence[int]]):
        """``tests``: each set's tests (indices)."""
        self.layout = layout
        self.on = [np.isin(layout.test, list(t)) for t in tests]   #: each set's rows (N,)
        self.held = [np.full((int(on.sum()), len(layout.channels)), np.nan) for on in self.on]

    def place(self, k: int, result: dict[str, np.ndarray], i: int) -> None:
        """A simulated run of test ``i`` (its compared channels over its input phase) into set ``k``."""
        t, n = self.layout.tests[i], len(result[self.layout.channels[0]])
        if (n != len(t.rows)) if t.whole else (t.samples[-1] >= n):
            raise RuntimeError(f"{t.name}: the simulation gave {n} samples of the input phase, the recording "
                               f"{len(t.rows)}{'' if t.whole else f' up to sample {t.samples[-1] + 1}'}")
        at = np.cumsum(self.on[k]) - 1   # each row's place among the set's
        self.held[k][at[t.rows]] = np.column_stack([result[ch][t.samples] for ch in self.layout.channels])

    def __len__(self) -> int:
        return len(self.held)

    def __getitem__(self, k: int | slice) -> np.ndarray | list[np.ndarray]:
        if isinstance(k, slice):
            return [self[j] for j in range(len(self))[k]]
        out = np.full(self.layout.measured.shape, np.nan)
        out[self.on[k]] = self.held[k]
        return out


def run_sets(layout: Layout, pool: Executor, sets: Sequence[tuple[str, Sequence[Job], Sequence[int]]],
             say: Callable[[str], None] = lambda _: None) -> RunRows:
    """The compared rows of each set of runs (what it is, its jobs, the tests they run: NaN
    elsewhere), all in parallel on ``pool``, each run's placed as it comes; progress to ``say``.

    Raises:
        TaskFailed: a run failed (naming its set and test); the others are cancelled at once.
    """
    jobs = [(label, k, t, j) for k, (label, js, tests) in enumerate(sets) for t, j in zip(tests, js)]
    out = RunRows(layout, [tests for _, _, tests in sets])
    each = max(1, len(jobs) // max(len(sets), 1))   # progress once a set's worth is done (none: no set)
    with closing(pool.each(run_job, [j for *_, j in jobs])) as outcomes:
        for done, o in enumerate(outcomes, 1):
            label, k, test, _ = jobs[o.index]
            if o.error:
                raise TaskFailed(f"{label} on {layout.tests[test].name}: {o.error}")
            out.place(k, o.result, test)
            if len(sets) > 1 and done % each == 0:
                say(f"  {done}/{len(jobs)} runs done on {pool.description}")
    return out


def _period(case: Case, duration_scale: float, rate_hz: float) -> int:
    """The samples in a period of ``case``'s input played at ``duration_scale`` and recorded at
    ``rate_hz``, when it repeats (else 0)."""
    return int(round(case.duration_s * duration_scale * rate_hz / case.cycles)) if case.cycles > 1 else 0


def _samples(input_time_s: np.ndarray, scenario: Scenario, where: str) -> np.ndarray:
    """The samples of a case's input phase that a damaged recording holds, from their times since
    the input started [s]: the k-th comes k output intervals after the start (the 0-th), as the
    simulation records them. InputError for samples off the scenario's output rate (a rig recording
    at another rate cannot be matched sample by sample once some are missing)."""
    interval = 1.0 / scenario.output_rate_hz
    k = np.rint(input_time_s / interval).astype(np.int64)
    off = (k < 0) | (np.abs(k * interval - input_time_s) > 1e-6) | np.r_[False, np.diff(k) < 1]
    if off.any():
        i = int(np.argmax(off))
        raise InputError(f"{where}: a sample {input_time_s[i]:.9g} s after the input started is not on the "
                         f"scenario's output rate ({scenario.output_rate_hz:g} Hz), which the diagnosis compares at; "
                         f"expected a recording at that rate")
    return k
