"""The compared samples of a K&C dataset (:mod:`elastokin.diagnosis.kc_diagnosis`): one row per sample of
a recorded case's input phase, one column per compared channel, and the vehicle run of each case
(a job: a pure function of its scenario, vehicle and duration scale, for any executor)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.scenarios.scenario import Scenario
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


def run_job(job: Job) -> dict[str, np.ndarray]:
    """The compared channels of ``job``'s run over its input phase (a task of the executor)."""
    run = simulate(replace(job.scenario, bushing_model=None), job.vehicle, duration_scale=job.duration_scale)
    on = run.signals["phase"] == 2
    return {name: run.signals[name][on] for name in job.channels}


@dataclass(frozen=True)
class Test:
    """One recorded case, the unit of the split between fitting and scoring."""

    name: str
    job: Job                  #: the baseline's run of it
    rows: np.ndarray          #: its rows in the layout


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

    @classmethod
    def of(cls, data: KCDataset, vehicle: VehicleDefinition) -> "Layout":
        """The compared channels of a dataset, case by case, and the baseline ``vehicle``'s run of each case."""
        first = data.tests[0].run
        channels = [n for n in first.signals if n.rsplit("_", 1)[0] in COMPARED or n.rsplit("_", 2)[0] in COMPARED]
        measured, times, recording, tests, start = [], [], [], [], 0
        for k, t in enumerate(data.tests):
            run, scale = t.run, float(t.run.metadata.extra.get("duration_scale", 1.0))
            phase, number = run.signals["phase"], run.signals["case"].astype(int)
            for c, case in enumerate(t.scenario.cases, start=1):
                on = (phase == 2) & (number == c)
                n = int(on.sum())
                measured.append(np.column_stack([run.signals[ch][on] for ch in channels]))
                times.append(run.signals["input_time"][on])
                recording.append(np.full(n, k))
                job = Job(replace(t.scenario, cases=[case]), vehicle, scale, tuple(channels))
                tests.append(Test(f"{t.name} case {c} ({case.label})", job, np.arange(start, start + n)))
                start += n
        test = np.concatenate([np.full(len(t.rows), i) for i, t in enumerate(tests)])
        return cls(channels, np.vstack(measured), np.concatenate(times), np.concatenate(recording), test, tests)

    def jobs(self, vehicle: VehicleDefinition, tests: Sequence[int]) -> list[Job]:
        """The runs of ``tests`` (indices) on ``vehicle``."""
        return [replace(self.tests[i].job, vehicle=vehicle) for i in tests]

    def stack(self, results: Sequence[dict[str, np.ndarray]], tests: Sequence[int]) -> np.ndarray:
        """(N, C) rows of simulated runs of ``tests``; NaN in the rows of the others."""
        out = np.full(self.measured.shape, np.nan)
        for result, i in zip(results, tests):
            rows = self.tests[i].rows
            if len(result[self.channels[0]]) != len(rows):
                raise RuntimeError(f"{self.tests[i].name}: the simulation gave {len(result[self.channels[0]])} "
                                   f"samples of the input phase, the recording {len(rows)}")
            out[rows] = np.column_stack([result[ch] for ch in self.channels])
        return out
