"""Diagnosis of a K&C dataset: what the baseline vehicle gets wrong, the cause, where it sits, the gain.

1. The baseline vehicle plays exactly the recorded tests, case by case (the recordings carry their
   scenarios; a scenario's ``bushings:`` choice is a simulation option and is ignored: the
   vehicle's own laws are the model under test). Every measured channel but the rig inputs is
   compared in units of its measurement noise, estimated from the data (sample-to-sample
   differences of the residual, which a smooth model error hardly affects); each channel's zero
   error in each recording is a nuisance, removed.
2. Screening: every catalogue cause at every place it can sit (:mod:`vsim_diagnosis.kc_catalogue`)
   is run once on the training tests (every other one) at mid-range magnitude (a sided cause, whose
   sign picks another effect, once per sign); its magnitude is fitted by taking the effect
   proportional to it (to its logarithm for a factor on a design value).
3. The best few are run on every test with their fitted magnitudes, refitted once along the effect
   that run gave (a cause with a second parameter, such as a damper's exponent, also along the
   effect of one more run with that parameter moved: both are fitted), run again, and scored on the
   held-out tests: the verdict rests on full vehicle simulations, never on the screening's
   linearisation.

Why not the cheaper screen of replaying each bushing's recorded deflections through the extended
law and mapping the force change through the response to a probe force: in a hysteretic direction
a constant probe force is absorbed by the stick phase, and the mapped prediction of a coupling in
the rear pivot bushing came out up to 18 times too small, with the wrong sign in half of the
channels. Full runs cost more and are right.

The verdict follows :func:`vsim_diagnosis.verdict.decide` with the noise as the floor. Every test
the baseline does not fit is found (the baseline fitted nothing: training tests count), with where
in it the misfit sits; a misfit the held-out tests taken together do not show (confined to a
training test, or to a stretch) makes the verdict "unexplained", not "none".
"""

from __future__ import annotations

import math
import time
from contextlib import closing, nullcontext
from dataclasses import dataclass, field, replace
from typing import Callable, Sequence

import numpy as np

from vehicle.model.definition import VehicleDefinition
from vehicle.scenarios.scenario import Scenario
from vsim_cluster.executor import Executor, TaskFailed, executor as open_executor
from vsim_diagnosis.kc_catalogue import (BUSHING_CAUSES, VEHICLE_CAUSES, Hypothesis, extended_vehicle, locations,
                                         parameters)
from vsim_diagnosis.verdict import Outcome, decide, explained, misfit, misfit_stretch, split
from vsim_recordings.kc_dataset import KCDataset
from vsim_recordings.recorder import simulate

#: Measured channel families compared (the rig inputs are imposed, not compared).
COMPARED = ("wheel_travel", "camber", "toe", "half_track", "steer", "wheel_centre", "pad_height", "pad_fz")
#: Hypotheses re-run on the full vehicle after the screening.
VERIFIED = 3
#: Relative increase of the held-out score per fitted parameter.
PARAMETER_PENALTY = 0.02


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


@dataclass
class Candidate:
    """A hypothesis fitted on the training tests and scored on the held-out ones."""

    hypothesis: Hypothesis
    heldout_error: float                      #: noise-normalised RMS on held-out tests (1 = the noise)
    std: dict[str, float] = field(default_factory=dict)
    screened_error: float = math.nan          #: RMS on the training tests after the screening's fit
    test_errors: np.ndarray | None = None     #: per test, from the full vehicle run
    simulated: np.ndarray | None = None       #: the full vehicle run's rows (verified candidates)

    @property
    def verified(self) -> bool:
        """Scored on the held-out tests by a full vehicle run."""
        return self.simulated is not None

    def penalised(self, error: float) -> float:
        """``error`` raised by the parameter penalty of this hypothesis's cause."""
        return error * (1.0 + PARAMETER_PENALTY * len(parameters(self.hypothesis.cause)))

    @property
    def score(self) -> float:
        """Penalised held-out error (verified) or training error (screened only); lower is better."""
        return self.penalised(self.heldout_error if self.verified else self.screened_error)


@dataclass(frozen=True)
class Misfit:
    """A test a model does not fit, and where in it (:func:`vsim_diagnosis.verdict.misfit_stretch`)."""

    test: str
    heldout: bool
    error: float          #: the model's RMS error on it (1 = the noise), each recording's zeros its medians
    chance: float         #: the chance that the noise alone shows a stretch as unlikely in the test
    start_s: float        #: the stretch of the test holding the excess: from, to [s of its input]
    end_s: float
    channel: str          #: the channel with the most excess there


@dataclass
class KCDiagnosis(Outcome):
    """The outcome of :func:`diagnose_kc`."""

    verdict: str                     #: a cause id, "none" or "unexplained"
    best: Candidate | None
    ranking: list[Candidate]
    heldout: np.ndarray              #: per test, held out from the fits
    test_names: list[str]
    baseline_errors: np.ndarray      #: per test, noise-normalised RMS of the baseline
    heldout_error_before: float
    layout: Layout
    noise: np.ndarray                #: per channel, estimated noise standard deviation (channel units)
    baseline: np.ndarray             #: the baseline's rows
    extended: VehicleDefinition | None   #: the baseline with the named cause
    misfits: list[Misfit] = field(default_factory=list)   #: the tests the baseline does not fit
    misfits_after: list[Misfit] = field(default_factory=list)   #: those the named cause does not fit
    wall_s: float = 0.0

    @property
    def explained(self) -> tuple[str, float]:
        """``full``, ``partial`` or ``none``, and the share of the excess over the noise explained
        (:func:`vsim_diagnosis.verdict.explained`)."""
        return explained(self.verdict, self.heldout_error_before, self.heldout_error_after, 1.0,
                         bool(self.misfits_after))

    @property
    def heldout_error_after(self) -> float:
        """The held-out error with the named cause (the baseline's when none is named)."""
        return self.best.heldout_error if self.named else self.heldout_error_before


class _Scorer:
    """Residuals in noise units, each channel's zero error in each recording removed; errors per test."""

    def __init__(self, layout: Layout, baseline: np.ndarray, heldout: np.ndarray):
        self.layout, self.heldout = layout, heldout
        self.held_rows = heldout[layout.test]
        self.noise = self._noise(layout.measured - baseline)

    def _noise(self, residual: np.ndarray) -> np.ndarray:
        """Per channel: the white noise of the residual from its sample-to-sample differences within
        each test (robust: median absolute deviation), which a smooth model error hardly affects;
        channels of one quantity share their median."""
        d = np.vstack([np.diff(residual[t.rows], axis=0) for t in self.layout.tests])
        per = 1.4826 * np.median(np.abs(d - np.median(d, axis=0)), axis=0) / math.sqrt(2.0)
        family = [c.rsplit("_", 1)[0] for c in self.layout.channels]
        out = np.array([np.median([p for p, g in zip(per, family) if g == f]) for f in family])
        return np.maximum(out, 1e-9)

    def residual(self, predicted: np.ndarray, rows: np.ndarray, zero: Callable[..., np.ndarray] = np.mean
                 ) -> np.ndarray:
        """(measured − predicted) / noise on the selected rows (a boolean mask), each channel's
        ``zero`` over the selected rows of each recording removed (its zero error): the mean, in
        which the residual stays affine in the prediction (the fits), or the median, which a misfit
        confined to a stretch does not move for the rest of its recording (the misfits' search)."""
        r = self.layout.measured[rows] - predicted[rows]
        rec = self.layout.recording[rows]
        for k in np.unique(rec):
            r[rec == k] -= zero(r[rec == k], axis=0)
        return r / self.noise

    def test_errors(self, predicted: np.ndarray) -> np.ndarray:
        """Per test, the RMS residual (1 = the noise)."""
        r2 = (self.residual(predicted, np.ones(len(predicted), dtype=bool)) ** 2).mean(axis=1)
        return np.array([math.sqrt(r2[t.rows].mean()) for t in self.layout.tests])

    def heldout_error(self, predicted: np.ndarray) -> float:
        """The RMS residual on the held-out tests (1 = the noise)."""
        r = self.residual(predicted, np.ones(len(predicted), dtype=bool))[self.held_rows]
        return float(math.sqrt(np.mean(r ** 2)))


def _nominal(cause: str) -> dict[str, float]:
    """Mid-range values of a cause's parameters (geometric mean for log parameters)."""
    return {p.name: (math.sqrt(p.draw[0] * p.draw[1]) if p.log else 0.5 * (p.draw[0] + p.draw[1]))
            for p in parameters(cause)}


def fit(h: Hypothesis, signature: np.ndarray, base: np.ndarray, scorer: _Scorer,
        slope: np.ndarray | None = None) -> Candidate:
    """Fit ``h`` on the training tests: its first parameter with the effect taken proportional to it
    (to its logarithm for a factor) from the ``signature`` (the rows of a vehicle run with
    ``h.values`` minus the baseline's); given ``slope`` (the rows' derivative with respect to the
    second parameter at ``h.values``), the second too, linearly along it. Each parameter fitted gets
    its uncertainty in ``std``; the candidate is scored by its training error (``screened_error``)."""
    params = parameters(h.cause)
    first = params[0]
    at = dict(h.values)
    train = ~scorer.held_rows
    mismatch = scorer.residual(base, train).ravel()
    # the signature and the slope in noise units (the residual is affine in the prediction)
    columns = [mismatch - scorer.residual(base + d, train).ravel() for d in (signature, slope) if d is not None]
    gram = np.array([[float(np.dot(a, b)) for b in columns] for a in columns])
    if len(columns) == 2 and np.linalg.det(gram) <= 1e-9 * gram[0, 0] * gram[1, 1]:
        columns, gram = columns[:1], gram[:1, :1]   # the second parameter changes nothing the first does not
    coef = np.linalg.solve(gram, [float(np.dot(c, mismatch)) for c in columns]) if gram[0, 0] > 0.0 \
        else np.zeros(len(columns))
    std = {}
    if len(columns) == 2:
        second = params[1]
        moved = float(np.clip(at[second.name] + coef[1], *second.bounds))
        coef[1] = moved - at[second.name]
        coef[0] = float(np.dot(columns[0], mismatch - coef[1] * columns[1])) / gram[0, 0]
        at[second.name] = moved
    # the residual variance, inflated for sample-to-sample correlation (a smooth model error is not
    # white noise: n samples are worth n(1 − ρ)/(1 + ρ))
    r = mismatch - sum(c * x for c, x in zip(coef, columns))
    rho = float(np.clip(np.dot(r[1:], r[:-1]) / max(np.dot(r, r), 1e-300), 0.0, 0.999))
    s2 = float(np.dot(r, r)) / max(len(r) - len(columns), 1) * (1.0 + rho) / (1.0 - rho)
    var = np.diag(np.linalg.inv(gram)) * s2 if gram[0, 0] > 0.0 else np.full(len(columns), math.inf)
    if len(columns) == 2:
        std[params[1].name] = math.sqrt(var[1])
    x0 = first.effect(at[first.name])
    lo, hi = first.bounds
    if not first.signed or (first.sided and x0 > 0.0):
        lo = max(lo, 0.0)
    if first.sided and x0 < 0.0:
        hi = min(hi, 0.0)
    # clipped before from_effect: a hypothesis with almost no effect gets a huge coefficient (a factor's exp overflowed)
    value = float(np.clip(first.from_effect(min(coef[0] * x0, first.effect(hi))), lo, hi))
    scale = first.effect(value) / x0
    std_first = math.sqrt(var[0])
    std[first.name] = abs(value * x0) * std_first if first.factor else abs(x0) * std_first
    rest = sum(c * x for c, x in zip(coef[1:], columns[1:]))
    trained = float(math.sqrt(np.mean((mismatch - scale * columns[0] - rest) ** 2)))
    return Candidate(replace(h, values={**at, first.name: value}), math.nan, std, screened_error=trained)


def nudged(h: Hypothesis) -> tuple[Hypothesis, float]:
    """``h`` with its second parameter moved by a quarter of its realistic range (inwards from a
    bound), and the move: the run that gives the rows' slope along that parameter."""
    second = parameters(h.cause)[1]
    value, step = h.values[second.name], 0.25 * (second.draw[1] - second.draw[0])
    if value + step > second.bounds[1]:
        step = -step
    return replace(h, values={**h.values, second.name: value + step}), step


def hypotheses(vehicle: VehicleDefinition) -> list[Hypothesis]:
    """Every catalogue cause at every place it can sit in ``vehicle``, at mid-range values; a sided
    cause once per sign."""
    out = []
    for c in (*BUSHING_CAUSES, *VEHICLE_CAUSES):
        first, values = parameters(c)[0], _nominal(c)
        out += [Hypothesis(c, loc, {**values, first.name: sign * values[first.name]})
                for loc in locations(vehicle, c) for sign in first.signs]
    return out


def diagnose_kc(data: KCDataset, vehicle: VehicleDefinition, *, executor: Executor | None = None,
                progress: Callable[[str], None] | None = None) -> KCDiagnosis:
    """Diagnose a K&C dataset against a baseline vehicle (see the module docstring); the vehicle runs
    go to ``executor`` (default: :func:`vsim_cluster.executor.executor`'s, a local Dask cluster
    unless ``VSIM_SCHEDULER`` names another). Every run is a pure function of its job: the verdict
    is the same bits on any executor."""
    started = time.perf_counter()
    say = progress or (lambda _: None)
    layout = Layout.of(data, vehicle)
    every = range(len(layout.tests))
    heldout = split(len(layout.tests))
    training = [i for i in every if not heldout[i]]
    candidates = hypotheses(vehicle)
    with nullcontext(executor) if executor is not None else open_executor() as pool:
        def rows(vehicles: list[VehicleDefinition], tests: Sequence[int]) -> list[np.ndarray]:
            """The compared rows of each vehicle on ``tests`` (NaN elsewhere), the runs in parallel."""
            n = len(tests)
            flat: list[dict[str, np.ndarray]] = [{}] * (n * len(vehicles))
            jobs = [j for v in vehicles for j in layout.jobs(v, tests)]
            with closing(pool.each(run_job, jobs)) as outcomes:   # a failure cancels the others at once
                for done, o in enumerate(outcomes, 1):
                    if o.error:
                        raise TaskFailed(f"vehicle {o.index // n + 1} of {len(vehicles)} on "
                                         f"{layout.tests[tests[o.index % n]].name}: {o.error}")
                    flat[o.index] = o.result
                    if len(vehicles) > 1 and done % n == 0:
                        say(f"  {done}/{len(flat)} runs done on {pool.description}")
            return [layout.stack(flat[i * n:(i + 1) * n], tests) for i in range(len(vehicles))]

        say(f"baseline {vehicle.name} on {len(data.tests)} recordings, {len(layout.tests)} tests "
            f"({int(heldout.sum())} held out)")
        (base,) = rows([vehicle], every)
        scorer = _Scorer(layout, base, heldout)
        before = scorer.heldout_error(base)
        say(f"held-out error of the baseline: {before:.3f} (1 = the measurement noise); one run of each of "
            f"{len(candidates)} hypotheses at mid-range magnitude on the {len(training)} training tests")
        signatures = rows([extended_vehicle(vehicle, [h]) for h in candidates], training)
        screened = sorted((fit(h, sig - base, base, scorer) for h, sig in zip(candidates, signatures)),
                          key=lambda c: c.score)
        for c in screened[:VERIFIED]:
            say(f"  {c.hypothesis.label}: training error {c.screened_error:.3f} with {_fmt(c.hypothesis.values)}")
        top = screened[:VERIFIED]
        say(f"the best {len(top)} on every test with their fitted magnitudes, then refitted along the effect they gave")
        _verify(top, rows([extended_vehicle(vehicle, [c.hypothesis]) for c in top], every), scorer)
        # a cause with a second parameter: one more run with it moved, on the training tests, for its slope
        moves = [nudged(c.hypothesis) if len(parameters(c.hypothesis.cause)) > 1 else None for c in top]
        if any(moves):
            say(f"  {sum(map(bool, moves))} with a second parameter: run with it moved, to fit it too")
        moved = iter(rows([extended_vehicle(vehicle, [m[0]]) for m in moves if m], training))
        refit = [fit(c.hypothesis, c.simulated - base, base, scorer,
                     None if m is None else (next(moved) - c.simulated) / m[1])
                 for c, m in zip(top, moves)]
        for a, b in zip(top, refit):
            # the linearised uncertainty ignores the model's nonlinearity; the refit's shift shows it
            b.std = {k: max(s, abs(b.hypothesis.values[k] - a.hypothesis.values[k])) for k, s in b.std.items()}
        _verify(refit, rows([extended_vehicle(vehicle, [c.hypothesis]) for c in refit], every), scorer)
        top = sorted((min(a, b, key=lambda c: c.score) for a, b in zip(top, refit)), key=lambda c: c.score)
    best = top[0]
    errors = scorer.test_errors(base)
    found = located_misfits(layout, scorer, base)
    for m in found:
        say(f"the baseline does not fit {m.test}{' (held out)' if m.heldout else ''}: {m.error:.2f} × the noise, "
            f"most between {m.start_s:.2f} and {m.end_s:.2f} s of its input, in {m.channel}")
    verdict = decide(before, best.heldout_error, 1.0, bool(found))
    say(f"{best.hypothesis.label}: held-out error {before:.3f} -> {best.heldout_error:.3f}: {verdict}")
    left = located_misfits(layout, scorer, best.simulated) if verdict == "named" else []
    for m in left:
        say(f"  with it, {m.test} is still not fitted: {m.error:.2f} × the noise")
    return KCDiagnosis(best.hypothesis.cause if verdict == "named" else verdict, best, top + screened[VERIFIED:],
                       heldout, [t.name for t in layout.tests], errors, before, layout, scorer.noise,
                       base, extended_vehicle(vehicle, [best.hypothesis]) if verdict == "named" else None, found,
                       left, time.perf_counter() - started)


def located_misfits(layout: Layout, scorer: _Scorer, predicted: np.ndarray) -> list[Misfit]:
    """The tests ``predicted`` does not fit (:func:`vsim_diagnosis.verdict.misfit`: the RMS error
    over a test or a stretch of it beyond the noise; every test, training or held out), each with
    where; each recording's zeros taken as its medians, so that one misfit does not shift the tests
    beside it."""
    residual = scorer.residual(predicted, np.ones(len(predicted), dtype=bool), np.median)
    out = []
    for i, t in enumerate(layout.tests):
        error = float(np.sqrt(np.mean(residual[t.rows] ** 2)))
        chance, first, last, channel = misfit_stretch(residual[t.rows])
        if misfit(error, chance):
            out.append(Misfit(t.name, bool(scorer.heldout[i]), error, chance, float(layout.input_time[t.rows[first]]),
                              float(layout.input_time[t.rows[last]]), layout.channels[channel]))
    return out


def _verify(candidates: list[Candidate], simulated: list[np.ndarray], scorer: _Scorer) -> None:
    for c, rows in zip(candidates, simulated):
        c.simulated = rows
        c.heldout_error = scorer.heldout_error(rows)
        c.test_errors = scorer.test_errors(rows)


def _fmt(values: dict[str, float]) -> str:
    return ", ".join(f"{k} = {v:.4g}" for k, v in values.items())

