"""Causes a bench campaign cannot tell apart, and the shipped bench programme that would
(:mod:`elastokin.diagnosis.bench_diagnosis`).

As at the K&C level (:mod:`elastokin.diagnosis.kc_alike`): two causes can act alike on the tests
measured (a preload on a progressive law and a stiffening on one side; a slow relaxation and a
little more viscosity). A rival of the named cause is *alike* when it would be named on its own and
the named cause does not beat it as a cause must (:func:`elastokin.diagnosis.verdict.alike`). Both, with
the values fitted on the training tests, then play every shipped bench programme that is a time
series (``models/bushings/benches``) on the measured part, after the dataset's own history and a
rest; the programme where their forces differ most, in units of the load cell's noise (each
prediction's mean removed, as a zero error would be), is the extra test that separates them.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Protocol, Sequence

import numpy as np

from elastokin.bushings.bench.bench_file import load_bench
from elastokin.bushings.bench.programmes import TimeSeries
from elastokin.bushings.parameter_sets import ParameterSet
from elastokin.core.shipped import BENCH_DIR, built_in
from elastokin.diagnosis.verdict import Separation, difference

#: Rest at zero deflection between the dataset's last test and the extra one [s].
REST_BEFORE_S = 5.0


@dataclasses.dataclass(frozen=True)
class Programme:
    """A shipped bench programme that can follow a campaign."""

    name: str
    path: Path
    signal: TimeSeries


def extra_programmes() -> list[Programme]:
    """The shipped bench programmes that are time series (a frequency sweep restarts the part at
    every point: it cannot follow the dataset's history)."""
    out = []
    for name in built_in(BENCH_DIR):
        path = BENCH_DIR / f"{name}.yaml"
        programme = load_bench(path).programme
        if isinstance(programme, TimeSeries):
            out.append(Programme(name, path, programme))
    return out


def load_cell_noise_n(noise: np.ndarray, scale: np.ndarray) -> float:
    """The load cell's noise [N] from the per-record relative noise and the records' force scales
    (half their peak-to-peak force [N]): the median over the records (a load cell's noise is one
    number of newtons, whatever the test)."""
    return float(np.median(noise * scale))


class History(Protocol):
    """A part's history that the models can play (:class:`~elastokin.diagnosis.bench_diagnosis.Replay`)."""

    def continued(self, models: Sequence[ParameterSet], rest_s: float,
                  signals: Sequence[tuple[np.ndarray, np.ndarray]]) -> list[np.ndarray]:
        """The forces [N] of every model (one row each) along each signal (times [s], deflections
        [m]) played after the history and a rest of ``rest_s`` [s] at zero deflection."""


def separations(history: History, models: Sequence[ParameterSet], noise_n: float,
                programmes: Sequence[Programme]) -> list[Separation | None]:
    """For every model after the first (the rivals of ``models[0]``, the named cause's), the
    programme whose forces differ most from the first's in units of ``noise_n`` [N], each played on
    the part after its ``history`` (the dataset's) and :data:`REST_BEFORE_S` of rest; None when
    there is no programme."""
    if not programmes:
        return [None] * (len(models) - 1)
    # each (K, samples of the programme)
    forces = history.continued(models, REST_BEFORE_S, [(p.signal.t_s, p.signal.e_m) for p in programmes])
    out: list[Separation | None] = []
    for k in range(1, len(models)):
        apart = [difference(f[0][:, None], f[k][:, None], noise_n) for f in forces]
        j = int(np.argmax(apart))
        out.append(Separation(programmes[j].name, programmes[j].path, apart[j]))
    return out
