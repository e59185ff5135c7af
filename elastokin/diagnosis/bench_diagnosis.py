"""Diagnosis of a bushing-bench dataset (spec measured-data §2): replay the measured deflections
through the baseline law, quantify the mismatch, fit every applicable cause of the catalogue on
half of the tests, score it on the other half, and name the cause that explains the mismatch (or
most of it, in part), or say that nothing significant is missing, or that the mismatch is real but
unexplained (:func:`elastokin.diagnosis.verdict.single_verdict`). When the
best cause leaves a mismatch beyond the noise, every pair of causes is fitted the same way, and
two are named when the pair removes most of what the best one left. A rival the tests cannot tell
from a named cause is reported with the shipped programme that would (:mod:`elastokin.diagnosis.bench_alike`).

The measured deflection drives the simulation (as a bench drives the part), record after record
with the rests between them, so that the part's state carries over as on the rig. A constant
load-cell zero error is a nuisance fitted in closed form for every model alike.
"""

from __future__ import annotations

import copy
import itertools
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Sequence

import numpy as np
from scipy.optimize import least_squares

from elastokin.bushings.bench.records import sample_steps
from elastokin.bushings.extended_bank import ExtendedBank
from elastokin.bushings.parameter_sets import ParameterSet
from elastokin.diagnosis.catalogue import PAIR_SEPARATOR, Cause, applicable, combined, parts
from elastokin.diagnosis.bench_alike import extra_programmes, load_cell_noise_n, separations
from elastokin.diagnosis.fit_starts import corner_starts, side_starts, sides_apart, to_fit
from elastokin.diagnosis.fit_uncertainty import standard_errors
from elastokin.diagnosis.verdict import (Outcome, Separation, alike, decide, explained, pair_named, pair_shares,
                                    penalised, second_cause_wanted, single_verdict, split)
from elastokin.recordings.bench_dataset import BenchDataset

#: Function evaluations of a pair's fit, which starts from its two causes' own fits or the best
#: corner of their range (less than half a single cause's 15: each evaluation of a pair of up to 6
#: parameters costs up to 7 replays, and the pair stage fits up to 15 pairs).
PAIR_NFEV = 6
#: Longest step used to simulate a rest between tests [s].
REST_STEP_S = 0.05
#: Ladder solver tolerance of the replays [m]: force errors below 0.3 N, under a load cell's noise.
REPLAY_TOLERANCE_M = 1e-8


@dataclass(frozen=True)
class Replay:
    """The dataset as one deflection history: every record, with the rests between them."""

    e: np.ndarray           #: deflection [m] at each step (T,)
    dts: np.ndarray         #: step [s] (T,)
    record: np.ndarray      #: index of the record a step samples, −1 during rests (T,)
    measured: np.ndarray    #: measured force at the steps of records [N] (T,), 0 during rests
    names: list[str]
    scale: np.ndarray       #: per record: half the peak-to-peak measured force [N]

    @classmethod
    def of(cls, data: BenchDataset) -> "Replay":
        """Lay out a dataset's records in the order played."""
        e, dts, rec, meas = [], [], [], []
        for k, r in enumerate(data.records):
            x = r.record
            n = math.ceil(r.rest_before_s / REST_STEP_S - 1e-9)
            if n:  # at rest at the rig's zero, read as the record's first deflection
                e.append(np.full(n, x.e[0]))
                dts.append(np.full(n, r.rest_before_s / n))
                rec.append(np.full(n, -1))
                meas.append(np.zeros(n))
            e.append(x.e)
            dts.append(sample_steps(x.t))
            rec.append(np.full(len(x.t), k))
            meas.append(x.F)
        scale = np.array([max(np.ptp(r.record.F) / 2.0, 1e-9) for r in data.records])
        return cls(np.concatenate(e), np.concatenate(dts), np.concatenate(rec), np.concatenate(meas),
                   [r.name for r in data.records], scale)

    def continued(self, models: Sequence[ParameterSet], rest_s: float,
                  signals: Sequence[tuple[np.ndarray, np.ndarray]]) -> list[np.ndarray]:
        """Forces (K, samples) of K candidate models along each signal (times [s] on a uniform grid,
        deflections [m]) played after the history and a rest of ``rest_s`` at zero deflection, each
        from the state the history and the rest left (the history played once)."""
        bank = self._bank(models)
        n = max(1, math.ceil(rest_s / REST_STEP_S - 1e-9))
        bank.run(np.r_[self.e, np.zeros(n)], np.r_[self.dts, np.full(n, rest_s / n)])
        return [copy.deepcopy(bank).run(e_m, sample_steps(t_s)).T for t_s, e_m in signals]

    def simulate(self, models: Sequence[ParameterSet]) -> np.ndarray:
        """Forces (K, T) of K candidate models along the history, each from a virgin part."""
        return self._bank(models).run(self.e, self.dts).T

    @staticmethod
    def _bank(models: Sequence[ParameterSet]) -> ExtendedBank:
        return ExtendedBank([m.channel() for m in models], [m.effects_si() for m in models], REPLAY_TOLERANCE_M)

    @cached_property
    def weights(self) -> np.ndarray:
        """Per-step residual weights: each record counts equally, relative to its force level."""
        w = np.zeros(len(self.e))
        for k in range(len(self.names)):
            on = self.record == k
            w[on] = 1.0 / (self.scale[k] * math.sqrt(on.sum()))
        return w

    def residuals(self, forces: np.ndarray, records: np.ndarray) -> np.ndarray:
        """Measured − simulated forces [N] (K, T), with the load-cell zero error fitted on ``records``
        (a boolean mask over records) removed; 0 during rests."""
        w2 = self.weights ** 2 * np.isin(self.record, np.flatnonzero(records))
        raw = self.measured - np.atleast_2d(forces)
        offset = (raw * w2).sum(axis=1, keepdims=True) / w2.sum()
        return np.where(self.record >= 0, raw - offset, 0.0)

    def record_errors(self, residual: np.ndarray) -> np.ndarray:
        """Relative RMS error of each record (RMS residual / half its peak-to-peak force) for one model."""
        out = np.empty(len(self.names))
        for k in range(len(self.names)):
            on = self.record == k
            out[k] = math.sqrt(np.mean(residual[on] ** 2)) / self.scale[k]
        return out

    def noise_floor(self, residual: np.ndarray) -> np.ndarray:
        """Per record, the relative RMS of the white measurement noise in a residual, estimated from
        its sample-to-sample differences (robust: median absolute deviation), which a smooth model
        error hardly affects."""
        out = np.empty(len(self.names))
        for k in range(len(self.names)):
            d = np.diff(residual[self.record == k])
            out[k] = 1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0) / self.scale[k]
        return out


def aggregate(errors: np.ndarray, records: np.ndarray) -> float:
    """Root mean square of per-record relative errors over the selected records."""
    return float(math.sqrt(np.mean(errors[records] ** 2)))


@dataclass
class Candidate:
    """A cause fitted on the training tests and scored on the held-out ones."""

    cause: Cause
    values: dict[str, float]           #: fitted on the training tests (parameter-set units)
    heldout_error: float               #: relative RMS error on held-out tests
    record_errors: np.ndarray          #: per record, with the training-fit values
    score: float = 0.0                 #: held-out error with the parameter penalty (lower is better)
    final: dict[str, float] = field(default_factory=dict)   #: refitted on every test
    #: uncertainty of ``final``: the larger of its standard error (fit_uncertainty) and the shift from ``values``
    std: dict[str, float] = field(default_factory=dict)
    model: ParameterSet | None = None                       #: the extended baseline with ``final``
    fit_s: float = 0.0                 #: wall time of its fit and score [s] (to schedule the longest first)
    #: relative RMS error over every test, each scored by a fit on the other half (computed only when
    #: the held-out half cannot tell it from the best: :func:`_crossed`)
    two_fold_error: float = math.nan


@dataclass
class BenchDiagnosis(Outcome):
    """The outcome: a cause (or none, or unexplained) with its evidence."""

    verdict: str                        #: a catalogue id, two joined by "+", "none" or "unexplained"
    baseline: ParameterSet
    replay: Replay
    heldout: np.ndarray                 #: boolean mask of held-out records
    baseline_errors: np.ndarray         #: per-record relative error of the baseline
    noise: np.ndarray                   #: per-record relative noise floor
    ranking: list[Candidate]
    best: Candidate | None              #: the named cause or pair; else the best single cause
    part: str
    wall_s: float = 0.0
    #: the second stage (:func:`elastokin.diagnosis.verdict.second_cause_wanted`): every pair of causes,
    #: best first; empty when the best single cause left nothing beyond the noise
    pairs: list[Candidate] = field(default_factory=list)
    #: rivals of a single named cause that the tests cannot tell from it (bench_alike), best first
    alike: list[Candidate] = field(default_factory=list)
    #: per rival, the shipped bench programme that separates it from the named cause best
    separations: list[Separation | None] = field(default_factory=list)

    @property
    def heldout_error_before(self) -> float:
        """The baseline's relative RMS error on the held-out tests."""
        return aggregate(self.baseline_errors, self.heldout)

    @property
    def heldout_error_after(self) -> float:
        """The held-out error with the best cause (the baseline's when nothing is missing)."""
        return self.best.heldout_error if self.best is not None and self.verdict != "none" else self.heldout_error_before

    @property
    def explained(self) -> tuple[str, float]:
        """``full``, ``partial`` or ``none``, and the share of the excess over the noise explained
        (:func:`elastokin.diagnosis.verdict.explained`; the tests judged together)."""
        return explained(self.verdict, self.heldout_error_before, self.heldout_error_after,
                         aggregate(self.noise, self.heldout))

    @property
    def shares(self) -> list[float]:
        """Per named cause, the share of the mismatch it explains; of two, each cause's gain averaged
        over the two orders of adding them (:func:`elastokin.diagnosis.verdict.pair_shares`)."""
        if not self.named:
            return []
        if PAIR_SEPARATOR not in self.verdict:
            return [self.explained[1]]
        floor = aggregate(self.noise, self.heldout)
        alone = {c.cause.id: c.heldout_error for c in self.ranking}
        return list(pair_shares(self.heldout_error_before, [alone[c.id] for c in parts(self.verdict)],
                                self.heldout_error_after, floor))


class _Objective:
    """Weighted residuals of a cause with values from a parameter vector in fit coordinates, and
    their Jacobian by finite differences computed as extra channels of one bank run."""

    def __init__(self, replay: Replay, base: ParameterSet, cause: Cause, train: np.ndarray):
        self.replay, self.base, self.cause, self.train = replay, base, cause, train
        on = np.isin(replay.record, np.flatnonzero(train))
        self.w = replay.weights * on
        self.cache: dict[bytes, np.ndarray] = {}

    def values(self, z: np.ndarray) -> dict[str, float]:
        return {p.name: float(math.exp(v) if p.log else v) for p, v in zip(self.cause.parameters, z)}

    def residuals(self, Z: np.ndarray) -> np.ndarray:
        """Weighted residuals (K, T) for K parameter vectors, in one simulation."""
        forces = self.replay.simulate([self.cause.apply(self.base, self.values(z)) for z in Z])
        return self.replay.residuals(forces, self.train) * self.w

    def fun(self, z: np.ndarray) -> np.ndarray:
        key = z.tobytes()
        if key not in self.cache:
            self.cache = {key: self.residuals(z[None])[0]}
        return self.cache[key]

    def jac(self, z: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Forward differences, backward where a step forward would pass the upper bound ``hi`` (a
        sided parameter's bound at zero: its effect switches sides beyond)."""
        r0 = self.fun(z)
        h = 1e-3 * np.maximum(1.0, np.abs(z))
        h = np.where(z + h > hi, -h, h)
        r = self.residuals(z + np.diag(h))
        return ((r - r0) / h[:, None]).T


def fit_cause(replay: Replay, base: ParameterSet, cause: Cause, train: np.ndarray,
              start: dict[str, float] | None = None, max_nfev: int = 15, corners: bool = False
              ) -> tuple[dict[str, float], dict[str, float]]:
    """Least-squares fit of a cause's parameters on the training records, from ``start``, or from the
    best of a few starting points: the corners of the realistic range (no ``start``), or, with
    ``corners``, those and ``start`` with each family's sided parameters on either side; each side
    fitted from its best point within its bounds (:mod:`elastokin.diagnosis.fit_starts`), the best kept
    (from a ``start``, only its side and the best point's: a pair's causes fitted alone chose theirs);
    returns the values and their standard uncertainties (:func:`elastokin.diagnosis.fit_uncertainty.standard_errors`,
    the tests the independent units)."""
    obj = _Objective(replay, base, cause, train)
    if start is None:
        grid = corner_starts(cause)
    else:
        grid = np.vstack([side_starts(cause, start), corner_starts(cause)]) if corners else to_fit(cause, start)[None]
    costs = (obj.residuals(grid) ** 2).sum(axis=1) if len(grid) > 1 else np.zeros(1)
    sides = sides_apart(cause, grid)
    if start is not None:   # only the side of the start (the row 0) and the best point's
        sides = [side for side in sides if side[0][[0, int(np.argmin(costs))]].any()]
    sol = None
    for on, lo, hi in sides:
        z0 = grid[on][int(np.argmin(costs[on]))]
        side = least_squares(obj.fun, np.clip(z0, lo + 1e-9, hi - 1e-9), jac=lambda z, hi=hi: obj.jac(z, hi),
                             bounds=(lo, hi), x_scale=1.0, max_nfev=max_nfev, method="trf", ftol=1e-6, xtol=1e-6)
        sol = side if sol is None or side.cost < sol.cost else sol
    on = obj.w > 0
    std_z = standard_errors(sol.jac[on], sol.fun[on], obj.replay.record[on], int(on.sum()) - len(sol.x))
    values = obj.values(sol.x)
    std = {p.name: float(values[p.name] * s if p.log else s) for p, s in zip(cause.parameters, std_z)}
    return values, std


def _crossed(c: Candidate, replay: Replay, baseline: ParameterSet, heldout: np.ndarray) -> Candidate:
    """``c`` with its two-fold error: refitted on the held-out tests (from its values, and either side
    of a sided parameter) and scored on the training tests, whose errors join its held-out ones."""
    values, _ = fit_cause(replay, baseline, c.cause, heldout, c.values, PAIR_NFEV, corners=True)
    errors = replay.record_errors(replay.residuals(replay.simulate([c.cause.apply(baseline, values)]), heldout)[0])
    c.two_fold_error = aggregate(np.where(heldout, c.record_errors, errors), np.ones(len(heldout), dtype=bool))
    return c


def diagnose_bench(data: BenchDataset, baseline: ParameterSet,
                   progress: Callable[[str], None] | None = None) -> BenchDiagnosis:
    """Diagnose a bench dataset against a baseline parameter set (see the module docstring)."""
    started = time.perf_counter()
    say = progress or (lambda _: None)
    replay = Replay.of(data)
    heldout = split(len(replay.names))
    train = ~heldout
    everything = np.ones(len(replay.names), dtype=bool)
    say(f"baseline {baseline.name} ({baseline.model}) on {len(replay.names)} tests")
    base_res = replay.residuals(replay.simulate([baseline]), train)[0]
    base_errors = replay.record_errors(base_res)
    noise = replay.noise_floor(base_res)

    def score(cause: Cause, start: dict[str, float] | None = None) -> Candidate:
        began = time.perf_counter()
        values, _ = fit_cause(replay, baseline, cause, train, start, PAIR_NFEV if start else 15, corners=True)
        res = replay.residuals(replay.simulate([cause.apply(baseline, values)]), train)[0]
        errors = replay.record_errors(res)
        err = aggregate(errors, heldout)
        say(f"{cause.id}: held-out error {err:.4f} (baseline {aggregate(base_errors, heldout):.4f})")
        return Candidate(cause, values, err, errors, penalised(err, len(cause.parameters)),
                         fit_s=time.perf_counter() - began)

    causes = applicable(baseline)
    say(f"fitting {len(causes)} causes on {int(train.sum())} tests, scoring each on the {int(heldout.sum())} held out")
    # The replays release the GIL: one fit per core.
    with ThreadPoolExecutor(max_workers=min(len(causes), os.cpu_count() or 1) or 1) as pool:
        ranking = sorted(pool.map(score, causes), key=lambda c: c.score)
        before = aggregate(base_errors, heldout)
        floor = aggregate(noise, heldout)
        best = ranking[0] if ranking else None
        verdict = single_verdict(before, best.heldout_error if best else before, floor)
        pairs: list[Candidate] = []
        if best is not None and second_cause_wanted(before, best.heldout_error, floor):
            say(f"{best.cause.id} leaves {best.heldout_error:.4f} (noise {floor:.4f}): fitting every pair of causes")
            # each pair (the better-ranked cause first) starts from its causes' own fits or the corners of
            # their ranges (two effects that hide each other fit badly alone); the pairs whose causes took
            # longest alone go first, so that no long fit runs alone at the end
            combos = sorted(itertools.combinations(ranking, 2), key=lambda ab: -(ab[0].fit_s + ab[1].fit_s))
            pairs = sorted(pool.map(lambda ab: score(combined(ab[0].cause, ab[1].cause),
                                                     {**ab[0].values, **ab[1].values}), combos),
                           key=lambda c: (c.score, c.cause.id))
            if pairs and pair_named(before, best.heldout_error, pairs[0].heldout_error, floor):
                best, verdict = pairs[0], "named"
        in_part = decide(before, best.heldout_error, floor) != "named" if best is not None else False
        rivals = ([c for c in ranking[1:] if alike(before, c.heldout_error, best.heldout_error, floor, in_part)]
                  if verdict == "named" and best is ranking[0] else [])
        if rivals:
            # the held-out half cannot tell them apart: the other half is asked too (two-fold cross-validation)
            say(f"{', '.join(c.cause.id for c in rivals)}: not told from {best.cause.id} by the held-out tests; "
                f"fitting each on them and scoring it on the training tests")
            contenders = sorted(pool.map(lambda c: _crossed(c, replay, baseline, heldout), [best, *rivals]),
                                key=lambda c: penalised(c.two_fold_error, len(c.cause.parameters)))
            both, floor_both = aggregate(base_errors, everything), aggregate(noise, everything)
            best = contenders[0]
            rivals = [c for c in contenders[1:]
                      if alike(both, c.two_fold_error, best.two_fold_error, floor_both, in_part)]
    apart = []
    if rivals:
        say(f"{', '.join(c.cause.id for c in rivals)}: not told from {best.cause.id} by these tests; playing the "
            f"shipped bench programmes after them")
        apart = separations(replay, [c.cause.apply(baseline, c.values) for c in (best, *rivals)],
                            load_cell_noise_n(noise, replay.scale), extra_programmes())
    if verdict == "named":
        say(f"refitting {best.cause.id} on every test")
        best.final, standard = fit_cause(replay, baseline, best.cause, everything, start=best.values, max_nfev=6)
        # the shift from the half-data fit: what half the tests alone would have said
        best.std = {k: max(s, abs(best.final[k] - best.values[k])) for k, s in standard.items()}
        best.model = best.cause.apply(baseline, best.final,
                                      source=f"{baseline.name} extended by {best.cause.id}, fitted by vsim diagnose "
                                             f"on {data.path.name} ({len(replay.names)} bench tests)")
    return BenchDiagnosis(best.cause.id if verdict == "named" else verdict, baseline, replay, heldout,
                          base_errors, noise, ranking, best, data.part, time.perf_counter() - started, pairs,
                          rivals, apart)
