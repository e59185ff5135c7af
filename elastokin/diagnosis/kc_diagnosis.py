"""Diagnosis of a K&C dataset: what the baseline vehicle gets wrong, the cause, where it sits, the gain.

1. The baseline vehicle plays exactly the recorded tests, case by case (the recordings carry their
   scenarios; a scenario's ``bushings:`` choice is a simulation option and is ignored: the
   vehicle's own laws are the model under test). Every measured channel but the rig inputs is
   compared in units of its measurement noise, white and coloured, estimated from the data
   (differences of the residual that a model error cancels from, :mod:`elastokin.diagnosis.kc_noise`);
   each channel's zero error in each recording is a nuisance, removed, and so are each acquisition
   path's response (a low-pass filter and a delay behind the rig inputs, :mod:`elastokin.diagnosis.kc_lags`:
   estimated on the baseline, what is left of it fitted with every hypothesis) and the rig's
   transducers' errors (the inputs' and the channels' gains, cross-talk, zeros drifting through the
   recordings of repeated tests, :mod:`elastokin.diagnosis.kc_transducers`) and its own mechanics (its
   pads' friction, its body clamp's compliance, :mod:`elastokin.diagnosis.kc_rig_mechanics`): fitted
   with every hypothesis; what they take out that a car cause would explain as well is said
   (:mod:`elastokin.diagnosis.kc_rig_or_car`), and so is a car cause they may hide, which the data
   prefer beside them below the naming threshold, with what it makes of the readings shown
   (:mod:`elastokin.diagnosis.kc_hidden_cause`); the rig inputs' gains the verdict shows act on the
   named causes' change too, read from the baseline and the causes run again under them. When the
   verdict shows the pads' friction (not proportional in its effect, nor apart from a car cause that
   sticks and slips too), all of this runs again on a rig with it, its column then the change from it.
2. Screening: every catalogue cause at every place it can sit (:mod:`elastokin.diagnosis.kc_catalogue`)
   is run once on the training tests (every other one) at mid-range magnitude (a sided cause, whose
   sign picks another effect, or one whose effect is not odd in its magnitude, such as a cross
   stiffness, once per sign); its magnitude is fitted by taking the effect
   proportional to it (to its logarithm for a factor on a design value).
3. The best few are run on every test with their fitted magnitudes, refitted once along the effect
   that run gave (a cause with a second parameter, such as a damper's exponent, also along the
   effect of one more run with that parameter moved: both are fitted), run again, and scored on the
   held-out tests: the verdict rests on full vehicle simulations, never on the screening's
   linearisation.
4. A rival that the campaign cannot tell from the best (:mod:`elastokin.diagnosis.kc_alike`) is reported
   with the shipped test that would separate them.
5. When the best leaves a mismatch beyond the noise, or a test it does not fit: every other
   hypothesis beside it, its magnitude fitted on what the best's run leaves from its own screening
   run; the best few run beside it on every test (a second cause with a shape parameter once more,
   with it moved), both magnitudes and that shape refitted together, run again and scored (a refit
   worse than where it started once more at half its step: the linearised step can overshoot); the best
   pair whose second magnitude stands off no effect (:func:`elastokin.diagnosis.kc_fits.significant`) is
   named when :func:`elastokin.diagnosis.verdict.pair_named` says so.

Why not the cheaper screen of replaying each bushing's recorded deflections through the extended
law and mapping the force change through the response to a probe force: in a hysteretic direction
a constant probe force is absorbed by the stick phase, and the mapped prediction of a coupling in
the rear pivot bushing came out up to 18 times too small, with the wrong sign in half of the
channels. Full runs cost more and are right.

The verdict follows :func:`elastokin.diagnosis.verdict.single_verdict` with the noise as the floor. Every test
the baseline does not fit is found (the baseline fitted nothing: training tests count), with where
in it the misfit sits; a misfit the held-out tests taken together do not show (confined to a
training test, or to a stretch) makes the verdict "unexplained", not "none".
"""

from __future__ import annotations

import math
import time
from contextlib import nullcontext
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Callable, Iterable, Sequence

import numpy as np

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.cluster.executor import Executor, executor as open_executor
from elastokin.diagnosis.catalogue import PAIR_SEPARATOR
from elastokin.diagnosis.kc_alike import alike, extra_scenarios, run_unless_diverged, separations
from elastokin.diagnosis.kc_catalogue import (BUSHING_CAUSES, VEHICLE_CAUSES, Hypothesis, extended_vehicle, locations,
                                         parameters)
from elastokin.diagnosis.kc_fits import Candidate, fit, fit_pair, halfway, kept, nominal, nudged, significant, verify
from elastokin.diagnosis.kc_transducers import (INPUT_GAIN, STEP, Reading, drift_columns, input_column, inputs_scaled,
                                                moved, reading_columns, stepped)
from elastokin.diagnosis.kc_lags import PathResponse
from elastokin.diagnosis.kc_misfits import Misfit, located_misfits
from elastokin.diagnosis.kc_rig_mechanics import (BY_KEY, ELEMENTS, RIG, element_column, element_jobs,
                                                   not_proportional, on_rig)
from elastokin.diagnosis.kc_hidden_cause import HiddenCause, hidden_cause
from elastokin.diagnosis.kc_rig_or_car import RigOrCar, rig_or_car
from elastokin.diagnosis.kc_training_fit import training_fit
from elastokin.diagnosis.kc_noise import NoiseModel, coloured_noise
from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.kc_layout import Job, Layout, RunRows, run_sets
from elastokin.diagnosis.verdict import (Outcome, Separation, decide, explained, pair_named, pair_shares,
                                    second_cause_wanted, single_verdict, split)
from elastokin.recordings.kc_dataset import KCDataset

#: Hypotheses re-run on the full vehicle after the screening.
VERIFIED = 3


@dataclass
class KCDiagnosis(Outcome):
    """The outcome of :func:`diagnose_kc`."""

    verdict: str                     #: a cause id, two joined by "+", "none" or "unexplained"
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
    #: the second stage (:func:`elastokin.diagnosis.verdict.second_cause_wanted`): other hypotheses run
    #: beside ``best``, best first (their errors and rows are the pair's); empty when not needed
    pairs: list[Candidate] = field(default_factory=list)
    second: Candidate | None = None       #: the second cause named (one of ``pairs``), if any
    #: held-out error of the second cause alone, at its own single fit as ``best`` is (for its share)
    second_alone_error: float = math.nan
    #: verified rivals of a single named cause that the campaign cannot tell from it (kc_alike), best first
    alike: list[Candidate] = field(default_factory=list)
    #: per rival, the shipped test the dataset lacks that separates it from the named cause best
    #: (None: none ran for both)
    separations: list[Separation | None] = field(default_factory=list)
    extra_tests: int = 0                  #: shipped rig tests the dataset lacks (read when there are rivals)
    #: each acquisition path's filter and delay behind the rig inputs, fitted beside the final model
    #: (:mod:`elastokin.diagnosis.kc_lags`) and taken out of every comparison
    responses: list[PathResponse] = field(default_factory=list)
    #: the measurement noise, white and coloured, estimated from the baseline's residual (:mod:`elastokin.diagnosis.kc_noise`)
    noise_model: NoiseModel | None = None
    #: the rig's errors (the moved rig inputs' gains, the measured channels' gains and cross-talk,
    #: the rig's own mechanics), fitted beside the final model and taken out of every comparison
    #: (:mod:`elastokin.diagnosis.kc_transducers`, :mod:`elastokin.diagnosis.kc_rig_mechanics`)
    rig_errors: list[Reading] = field(default_factory=list)
    #: the rig errors taken out that car causes would explain as well (:mod:`elastokin.diagnosis.kc_rig_or_car`)
    rig_or_car: list[RigOrCar] = field(default_factory=list)
    #: the car cause the data prefer beside the rig's errors, below the naming threshold, and the shown
    #: rig errors it moves (:mod:`elastokin.diagnosis.kc_hidden_cause`); None when none is found
    hidden: HiddenCause | None = None

    @property
    def final(self) -> Candidate:
        """The candidate whose run is the extended model's: the pair's when two causes are named."""
        return self.second if self.second is not None else self.best

    @property
    def causes(self) -> list[Candidate]:
        """The named causes, the first found first (each candidate's hypothesis is its cause, with the
        values fitted together when there are two)."""
        if self.second is None:
            return [self.best] if self.named else []
        return [self.second.beside or self.best, self.second]

    @property
    def explained(self) -> tuple[str, float]:
        """``full``, ``partial`` or ``none``, and the share of the excess over the noise explained
        (:func:`elastokin.diagnosis.verdict.explained`)."""
        return explained(self.verdict, self.heldout_error_before, self.heldout_error_after, 1.0,
                         bool(self.misfits_after))

    @property
    def shares(self) -> list[float]:
        """Per named cause, the share of the mismatch it explains; of two, each one's gain averaged over
        the two orders of adding them (:func:`elastokin.diagnosis.verdict.pair_shares`)."""
        if self.second is None:
            return [self.explained[1]] if self.named else []
        return list(pair_shares(self.heldout_error_before, [self.best.heldout_error, self.second_alone_error],
                                self.second.heldout_error, 1.0))

    @property
    def heldout_error_after(self) -> float:
        """The held-out error with the named cause(s) (the baseline's when none is named)."""
        return self.final.heldout_error if self.named else self.heldout_error_before


def hypotheses(vehicle: VehicleDefinition) -> list[Hypothesis]:
    """Every catalogue cause at every place it can sit in ``vehicle``, at mid-range values; a sided
    cause once per side (all its sided parameters on it), a cause whose effect has an even part
    once per sign of its magnitude (:attr:`elastokin.diagnosis.catalogue.Parameter.signs`)."""
    out = []
    for c in (*BUSHING_CAUSES, *VEHICLE_CAUSES):
        params, values = parameters(c), nominal(c)
        signed = [p.name for p in params if p.sided or p.even_part]
        out += [Hypothesis(c, loc, {**values, **{k: sign * values[k] for k in signed}})
                for loc in locations(vehicle, c) for sign in params[0].signs]
    return out


def diagnose_kc(data: KCDataset, vehicle: VehicleDefinition, *, executor: Executor | None = None,
                progress: Callable[[str], None] | None = None) -> KCDiagnosis:
    """Diagnose a K&C dataset against a baseline vehicle (see the module docstring); the vehicle runs
    go to ``executor`` (default: :func:`elastokin.cluster.executor.executor`'s, a local Dask cluster
    unless ``VSIM_SCHEDULER`` names another). Every run is a pure function of its job: the verdict
    is the same bits on any executor."""
    started = time.perf_counter()
    say = progress or (lambda _: None)
    layout = Layout.of(data, vehicle)
    with nullcontext(executor) if executor is not None else open_executor() as pool:
        out, explain = _diagnosis(layout, vehicle, pool, say)
        at = not_proportional({g.channel: g.value for g in out.rig_errors if g.kind == RIG and g.said})
        if at:
            say(f"the rig shows {', '.join(f'{BY_KEY[k].label} {v:.3g} {BY_KEY[k].unit}' for k, v in at.items())}, "
                f"not proportional in its effect: every run again on a rig with it")
            out, explain = _diagnosis(on_rig(layout, at), vehicle, pool, say, at)
        explain()
    return replace(out, layout=layout, wall_s=time.perf_counter() - started)


def _diagnosis(layout: Layout, vehicle: VehicleDefinition, pool: Executor, say: Callable[[str], None],
               rig_at: dict[str, float] | None = None) -> tuple[KCDiagnosis, Callable[[], None]]:
    """:func:`diagnose_kc`'s verdict with its runs on ``pool``, each test on its job's rig; ``rig_at``:
    the rig elements' values [their units] that rig adds to the scenarios' (their columns then the
    change from them). With it, what explains the verdict that only the last pass needs (its rivals
    run on the shipped tests, the rig errors car causes would explain as well), to call on it."""
    every = range(len(layout.tests))
    heldout = split(len(layout.tests))
    training = [i for i in every if not heldout[i]]
    candidates = hypotheses(vehicle)

    runs = partial(run_sets, layout, pool, say=say)

    def rows(vehicles: list[VehicleDefinition], tests: Sequence[int]) -> RunRows:
        """The compared rows of each vehicle on ``tests`` (NaN elsewhere), the runs in parallel."""
        return runs([(f"vehicle {k + 1} of {len(vehicles)}", layout.jobs(v, tests), tests)
                     for k, v in enumerate(vehicles)])

    say(f"baseline {vehicle.name} on {len(np.unique(layout.recording))} recordings, {len(layout.tests)} tests "
        f"({int(heldout.sum())} held out)")
    (base,) = rows([vehicle], every)
    scorer = rig_scorer(layout, base, heldout, runs, say, rig_at)
    before = scorer.heldout_error(base)
    say(f"held-out error of the baseline: {before:.3f} (1 = the measurement noise); one run of each of "
        f"{len(candidates)} hypotheses at mid-range magnitude on the {len(training)} training tests")
    signatures = rows([extended_vehicle(vehicle, [h]) for h in candidates], training)
    screened = _best_per_place(fit(h, sig - base, base, scorer) for h, sig in zip(candidates, signatures))
    for c in screened[:VERIFIED]:
        say(f"  {c.hypothesis.label}: training error {c.screened_error:.3f} with {_fmt(c.hypothesis.values)}")
    top = screened[:VERIFIED]
    say(f"the best {len(top)} on every test with their fitted magnitudes, then refitted along the effect they gave")
    verify(top, rows([extended_vehicle(vehicle, [c.hypothesis]) for c in top], every), scorer)
    shaped = sum(len(parameters(c.hypothesis.cause)) > 1 for c in top)
    if shaped:
        say(f"  {shaped} with a second parameter: run with it moved, to fit it too")
    slopes = _slopes(top, lambda hs: rows([extended_vehicle(vehicle, [h]) for h in hs], training))
    refit = [fit(c.hypothesis, c.simulated - base, base, scorer, s) for c, s in zip(top, slopes)]
    top = kept(top, refit, rows([extended_vehicle(vehicle, [c.hypothesis]) for c in refit], every), scorer)
    best = top[0]
    found = located_misfits(layout, scorer, base)
    left = located_misfits(layout, scorer, best.simulated)
    pairs: list[Candidate] = []
    second, alone = None, math.nan
    # the tests not fitted by the best single cause, or by the baseline if that cause makes things worse
    unfitted = left if best.heldout_error < before else found
    if second_cause_wanted(before, best.heldout_error, 1.0, bool(unfitted)):
        say(f"{best.hypothesis.label} leaves {best.heldout_error:.3f} × the noise"
            f"{' and tests it does not fit' if left else ''}: every other hypothesis beside it")
        others = ((h, sig) for h, sig in zip(candidates, signatures)   # each read as it is fitted
                  if (h.cause, h.location) != (best.hypothesis.cause, best.hypothesis.location))
        pairs = _second_stage(best, others, base, scorer,
                              lambda hs, tests: rows([extended_vehicle(vehicle, h) for h in hs], tests), every,
                              training)
        # a second cause whose magnitude is not told from none is the first's joint refit, not a cause
        k = next((i for i, c in enumerate(pairs) if significant(c)), len(pairs))
        for c in pairs[:k]:
            say(f"  beside it, {c.hypothesis.label} is not told from no effect: {_fmt(c.hypothesis.values)}")
        if k < len(pairs) and pair_named(before, best.heldout_error, pairs[k].heldout_error, 1.0):
            second = pairs[k]
            single = _alone(second.hypothesis, top + screened[VERIFIED:])
            if not single.verified:   # its single fit, run on every test as the first cause's was
                single = replace(single)
                verify([single], rows([extended_vehicle(vehicle, [single.hypothesis])], every), scorer)
            alone = single.heldout_error
    rivals = alike(best, top, before) if second is None and decide(before, best.heldout_error, 1.0) == "named" else []
    errors = scorer.test_errors(base)
    for m in found:
        say(f"the baseline does not fit {m.test}{' (held out)' if m.heldout else ''}: {m.error:.2f} × the noise, "
            f"most between {m.start_s:.2f} and {m.end_s:.2f} s of its input, in {m.channel}")
    if second is not None:
        verdict = "named"
        say(f"{best.hypothesis.label} + {second.hypothesis.label}: held-out error {before:.3f} -> "
            f"{best.heldout_error:.3f} -> {second.heldout_error:.3f}: both named")
        left = located_misfits(layout, scorer, second.simulated)
    else:
        verdict = single_verdict(before, best.heldout_error, 1.0, bool(found))
        say(f"{best.hypothesis.label}: held-out error {before:.3f} -> {best.heldout_error:.3f}: {verdict}")
    left = left if verdict == "named" else []
    for m in left:
        say(f"  with it, {m.test} is still not fitted: {m.error:.2f} × the noise")
    out = KCDiagnosis(verdict, best, top + screened[VERIFIED:], heldout, [t.name for t in layout.tests], errors,
                      before, layout, scorer.noise, base, None, found, left, 0.0, pairs, second, alone, rivals)
    if verdict == "named":
        named = [c.hypothesis for c in out.causes]
        out.verdict = PAIR_SEPARATOR.join(h.cause for h in named)
        out.extended = extended_vehicle(vehicle, named)
    model = out.final.simulated if out.named else base
    out.responses = scorer.responses(model)
    out.noise_model = scorer.noise_model

    def under_inputs(factors: dict[str, float]) -> RunRows:
        say("the baseline and the named causes again with the commands the car got through the rig inputs' gains")
        return runs([(f"{label} under the inputs' gains", inputs_scaled(layout.jobs(v, every), factors), every)
                     for label, v in (("the baseline", vehicle), ("the named causes", out.extended))])

    out.rig_errors, model = scorer.rig_errors_under_inputs(model, _effects(out, base), under_inputs)
    for g in out.rig_errors:
        if g.said:
            say(f"{g.label}: {g.text} (taken out)")
    for q, (white, coloured, tau) in coloured_noise(layout.channels, scorer.noise_model).items():
        say(f"the {q} channels' noise is coloured: {coloured / white:.2g} × their white noise, correlated over "
            f"{tau:.2g} s (counted in the noise, its uncertainties and thresholds)")
    for r in out.responses:
        say(f"the {r.path}' channels lag the rig inputs by {1e3 * r.lag_s:.2f} ms at low frequency: "
            f"{f'a {r.cutoff_hz:.3g} Hz low-pass, then ' if r.cutoff_hz else ''}{1e3 * r.delay_s:.2f} ± "
            f"{1e3 * r.std_s:.2g} ms (taken out)")

    def explain() -> None:
        if rivals:   # the shipped scenarios read only then
            extra = extra_scenarios({t.job.scenario.name for t in layout.tests})
            say(f"{best.hypothesis.label} cannot be told apart on these tests from "
                f"{', '.join(c.hypothesis.label for c in rivals)}: both run on the {len(extra)} shipped tests the "
                f"dataset lacks")
            out.separations = separations([extended_vehicle(vehicle, [c.hypothesis]) for c in (best, *rivals)],
                                          extra, layout.channels, scorer.noise,
                                          float(np.median([t.job.duration_scale for t in layout.tests])),
                                          lambda jobs: pool.map(run_unless_diverged, jobs))
            out.extra_tests = len(extra)
        fit = training_fit(scorer, model, candidates, signatures, base, [c.hypothesis for c in out.causes])
        out.rig_or_car = rig_or_car(fit, out.rig_errors)
        for c in out.rig_or_car:
            say(f"what {c.group} took out, {' or '.join(h.label for h in c.rivals)} would explain as well "
                f"({c.error_held:.3f} -> {c.error:.3f} with it, {' and '.join(f'{e:.3f}' for e in c.error_rivals)} "
                f"with them): this campaign cannot tell them apart")
        out.hidden = hidden_cause(fit, out.rig_errors)
        if out.hidden is not None:
            h = out.hidden
            say(f"beside the rig's errors the data prefer {h.hypothesis.label} ({_fmt(h.hypothesis.values)}, "
                f"{h.z:.1f} standard uncertainties off none; training error {h.error_without:.4f} -> {h.error:.4f}): "
                f"with it, {', '.join(f'{g.label} {g.text} -> {w.text}' for g, w in h.moved)}")
    return out, explain


def rig_scorer(layout: Layout, base: np.ndarray, heldout: np.ndarray,
               runs: Callable[[list[tuple[str, list[Job], Sequence[int]]]], RunRows],
               say: Callable[[str], None] = lambda _: None, rig_at: dict[str, float] | None = None) -> Scorer:
    """The scorer of a campaign's ``layout`` with every rig error the diagnosis fits beside the causes
    (the acquisition's lags, estimated on the baseline; the rig inputs' transducers; its mechanics;
    its measuring transducers' gains, cross-talks and drifts):
    ``base`` (N, C) the baseline's rows, ``heldout`` (tests,) the held-out tests; ``runs`` runs sets of
    jobs (:func:`~elastokin.diagnosis.kc_layout.run_sets`): here the baseline's with each moved rig
    input's command stepped and on a rig with each element of its mechanics moved; ``rig_at`` as
    :class:`~elastokin.diagnosis.kc_scorer.Scorer`'s."""
    every = range(len(layout.tests))
    movers = moved(layout)
    say(f"the baseline with each of the {len(movers)} rig inputs moved × {1 + STEP:g} (its transducer's gain), "
        f"and on a rig with each of {len(ELEMENTS)} elements of its mechanics moved (the pads' friction, the "
        f"body clamp's compliance)")
    nuisances = runs([(f"{ch} × {1 + STEP:g}", stepped(layout, ch, tests), tests) for ch, tests in movers.items()]
                     + [(e.label, element_jobs(layout, e), every) for e in ELEMENTS])
    return Scorer(layout, base, heldout, {**{(INPUT_GAIN, ch, None): input_column(r, base)
                                             for ch, r in zip(movers, nuisances)},
                                          **{(RIG, e.key, None): element_column(r, base, e)
                                             for e, r in zip(ELEMENTS, nuisances[len(movers):])},
                                          **reading_columns(layout, base), **drift_columns(layout)}, rig_at)


def _second_stage(best: Candidate, others: Iterable[tuple[Hypothesis, np.ndarray]], base: np.ndarray, scorer: Scorer,
                  rows: Callable[[list[list[Hypothesis]], Sequence[int]], Sequence[np.ndarray]],
                  every: Sequence[int], training: Sequence[int]) -> list[Candidate]:
    """Every other hypothesis beside ``best``: its magnitude fitted on what ``best``'s run leaves, its
    effect taken from its own screening run (``others``: hypothesis, rows); the best VERIFIED run
    beside ``best`` on every test (``rows`` of the vehicles with the hypotheses listed), both
    magnitudes refitted together along the effects those runs gave (:func:`fit_pair`), run again and
    scored on the held-out tests (a refit worse than its start once more at half its step,
    :func:`halfway`); the candidates carry the pair's errors and rows, best first."""
    screened = _best_per_place(fit(h, sig - base, best.simulated, scorer) for h, sig in others)
    top = screened[:VERIFIED]
    verify(top, rows([[best.hypothesis, c.hypothesis] for c in top], every), scorer)
    slopes = _slopes(top, lambda hs: rows([[best.hypothesis, h] for h in hs], training))   # beside the first
    refits = [(c, fit_pair(best, c, base, scorer, s)) for c, s in zip(top, slopes)]
    moved = [(c, r) for c, r in refits if r is not None]

    def run(pairs: list[Candidate]) -> Sequence[np.ndarray]:
        return rows([[r.beside.hypothesis, r.hypothesis] for r in pairs], every)

    # two magnitudes and a shape moved at once along their linearised effects can overshoot (a Mullins
    # softening's magnitude and shape trade): a refit worse than its start is tried at half its step
    halves = [halfway(best, c, r) for c, r in moved]   # with the fit's own uncertainties, before kept widens them
    better = kept([c for c, _ in moved], [r for _, r in moved], run([r for _, r in moved]), scorer) if moved else []
    over = [(c, half) for (c, _), half in zip(moved, halves) if any(b is c for b in better)]   # its start kept
    if over:
        tried = kept([c for c, _ in over], [h for _, h in over], run([h for _, h in over]), scorer)
        better = [b for b in better if all(b is not c for c, _ in over)] + tried
    return sorted(better + [c for c, r in refits if r is None], key=lambda c: c.score)


def _slopes(top: list[Candidate], run_moved: Callable[[list[Hypothesis]], Sequence[np.ndarray]]
            ) -> list[np.ndarray | None]:
    """Per candidate, its rows' slope along its cause's second parameter, from one more run on the
    training tests with that parameter moved (:func:`elastokin.diagnosis.kc_fits.nudged`; ``run_moved``
    gives the rows of those hypotheses' runs); None for a cause with one parameter."""
    moves = [nudged(c.hypothesis) if len(parameters(c.hypothesis.cause)) > 1 else None for c in top]
    moved = iter(run_moved([m[0] for m in moves if m]) if any(moves) else [])
    return [None if m is None else (next(moved) - c.simulated) / m[1] for c, m in zip(top, moves)]


def _effects(d: KCDiagnosis, base: np.ndarray) -> list[np.ndarray]:
    """The named causes' effects on the compared rows (N, C): the first's run less the baseline's, a
    second's the pair's run less the first's."""
    if not d.named:
        return []
    if d.second is None:
        return [d.best.simulated - base]
    return [d.best.simulated - base, d.second.simulated - d.best.simulated]


def _alone(h: Hypothesis, ranking: list[Candidate]) -> Candidate:
    """The single stage's candidate of ``h``'s cause at its place (:func:`_place`), fitted alone."""
    return next(c for c in ranking if _place(c.hypothesis) == _place(h))


def _place(h: Hypothesis) -> tuple:
    """What a hypothesis names: its cause, its place and, for a sided cause, its side (the sign of its
    first parameter); not the screening sign of a cause whose effect is not odd, fitted either way."""
    first = parameters(h.cause)[0]
    return h.cause, h.location, math.copysign(1.0, h.values[first.name]) if first.sided else 1.0


def _best_per_place(candidates: Iterable[Candidate]) -> list[Candidate]:
    """The candidates best first, only the best of those naming one thing (:func:`_place`: a cause
    screened on both signs is fitted from each)."""
    out, seen = [], set()
    for c in sorted(candidates, key=lambda c: c.score):
        if _place(c.hypothesis) not in seen:
            seen.add(_place(c.hypothesis))
            out.append(c)
    return out


def _fmt(values: dict[str, float]) -> str:
    return ", ".join(f"{k} = {v:.4g}" for k, v in values.items())

