"""Fitting hypotheses on a K&C campaign's compared rows (:mod:`elastokin.diagnosis.kc_diagnosis`),
scored by :class:`elastokin.diagnosis.kc_scorer.Scorer`: a hypothesis's magnitude fitted with its
effect taken proportional to it from a vehicle run (one cause, a second parameter along one more
run, or two causes together); candidates verified by full runs."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Sequence

import numpy as np

from elastokin.diagnosis.catalogue import Parameter
from elastokin.diagnosis.kc_catalogue import Hypothesis, parameters
from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.verdict import penalised

#: Standard uncertainties by which a fitted magnitude must stand off no effect to be a cause found.
SIGNIFICANT = 2.0


@dataclass
class Candidate:
    """A hypothesis fitted on the training tests and scored on the held-out ones."""

    hypothesis: Hypothesis
    heldout_error: float                      #: noise-normalised RMS on held-out tests (1 = the noise)
    std: dict[str, float] = field(default_factory=dict)
    screened_error: float = math.nan          #: RMS on the training tests after the screening's fit (NaN
    #: for a candidate no linearised fit gave: :func:`halfway`)
    test_errors: np.ndarray | None = None     #: per test, from the full vehicle run
    simulated: np.ndarray | None = None       #: the full vehicle run's rows (verified candidates)
    #: a second cause's: the first cause as refitted together with it (:func:`fit_pair`, or halfway
    #: there: :func:`halfway`); the run and errors above are then the pair's
    beside: "Candidate | None" = None
    #: its magnitude's distance from no effect in the fit's own standard uncertainty (:func:`separation`),
    #: before :func:`kept` widens the uncertainty to the refit's shift
    z: float = math.nan

    @property
    def verified(self) -> bool:
        """Scored on the held-out tests by a full vehicle run."""
        return self.simulated is not None

    @property
    def fitted(self) -> int:
        """The parameters its score is penalised for: once verified, every parameter of the cause (the
        model it names); screened only, those the screening fitted (``std``'s), not a second parameter
        held where the screening ran it, which gave the fit no freedom."""
        return len(parameters(self.hypothesis.cause)) if self.verified else len(self.std)

    @property
    def score(self) -> float:
        """Held-out error (verified) or training error (screened only), :func:`penalised` for the
        parameters :attr:`fitted`; lower is better."""
        return penalised(self.heldout_error if self.verified else self.screened_error, self.fitted)


def nominal(cause: str) -> dict[str, float]:
    """Mid-range values of a cause's parameters (geometric mean for log parameters); a family's shape
    parameter at its first form (its default), so that a screening run is the first parameter's
    effect alone, scaled with it, and the second-parameter refit finds the shape."""
    return {p.name: (p.default if p.default is not None else
                     math.sqrt(p.draw[0] * p.draw[1]) if p.log else 0.5 * (p.draw[0] + p.draw[1]))
            for p in parameters(cause)}


def fit(h: Hypothesis, signature: np.ndarray, base: np.ndarray, scorer: Scorer,
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
    effects = [d for d in (signature, slope) if d is not None]
    limits = np.array([(-math.inf, math.inf)] + [np.subtract(_side_bounds(params[1], at[first.name]),
                                                             at[params[1].name]) for _ in effects[1:]])
    coef, left, columns = scorer.fit_effects(base, effects, train, limits)
    if len(columns) == 2 and _alike(_gram([c.ravel() for c in columns])):
        # the second parameter changes nothing the first does not
        effects, limits = effects[:1], limits[:1]
        coef, left, columns = scorer.fit_effects(base, effects, train, limits)
    std = {}
    if len(columns) == 2:
        second = params[1]
        at[second.name] = float(np.clip(at[second.name] + coef[1], *_side_bounds(second, at[first.name])))
    var = scorer.variances(left.ravel(), [c.ravel() for c in columns], train)
    if len(columns) == 2:
        std[params[1].name] = math.sqrt(var[1])
    value, std[first.name], scale = scaled_magnitude(first, at[first.name], coef[0], math.sqrt(var[0]))
    if not math.isclose(scale, coef[0], rel_tol=1e-9):   # held where its bounds allow, the rest refitted
        limits[0] = scale
        _, left, _ = scorer.fit_effects(base, effects, train, limits)
    trained = float(math.sqrt(np.mean(left ** 2)))
    return Candidate(replace(h, values={**at, first.name: value}), math.nan, std, screened_error=trained,
                     z=separation(first, value, std[first.name]))


def fit_pair(first: Candidate, second: Candidate, base: np.ndarray, scorer: Scorer,
             slope: np.ndarray | None = None) -> Candidate | None:
    """Both causes' magnitudes (first parameters) refitted together on the training tests, each effect
    taken proportional to its magnitude from the runs (``first``'s alone, ``second``'s beside it);
    given ``slope`` (the pair's rows' derivative with respect to the second cause's second parameter),
    that parameter too, linearly along it, as :func:`fit` does: the second cause with the first, as
    refitted, ``beside`` it; None when the two effects are alike on the campaign (nothing to refit)."""
    train = ~scorer.held_rows
    free = (-math.inf, math.inf)
    effects, limits = [first.simulated - base, second.simulated - first.simulated], np.array([free, free])
    coef, left, columns = scorer.fit_effects(base, effects, train, limits)   # the second's effect: its own
    if _alike(_gram([c.ravel() for c in columns])):
        return None                          # the two act alike on the campaign: nothing to refit
    at = dict(second.hypothesis.values)
    extra = {}
    if slope is not None:
        magnitude, shape_p = parameters(second.hypothesis.cause)[:2]
        wide = np.vstack([limits, np.subtract(_side_bounds(shape_p, at[magnitude.name]), at[shape_p.name])])
        shaped = scorer.fit_effects(base, [*effects, slope], train, wide)
        if not _alike(_gram([c.ravel() for c in shaped[2]])):   # else it changes nothing the two do not
            coef, left, columns = shaped
            effects, limits = [*effects, slope], wide
            extra = {shape_p.name: math.sqrt(scorer.variances(left.ravel(), [c.ravel() for c in columns], train)[2])}
            at[shape_p.name] = float(np.clip(at[shape_p.name] + coef[2], *_side_bounds(shape_p, at[magnitude.name])))
    sd = np.sqrt(scorer.variances(left.ravel(), [c.ravel() for c in columns[:2]], train))
    out, scales = [], []
    for c, k, s in zip((first, second), coef, sd):
        p = parameters(c.hypothesis.cause)[0]
        values = at if c is second else c.hypothesis.values
        value, std, scale = scaled_magnitude(p, values[p.name], float(k), float(s))
        # the first's uncertainty at least its shift (the second's: :func:`kept`)
        out.append(Candidate(replace(c.hypothesis, values={**values, p.name: value}), math.nan,
                             {**c.std, **(extra if c is second else {}),
                              p.name: max(std, abs(value - values[p.name])) if c is first else std},
                             z=separation(p, value, std)))
        scales.append(scale)
    if not np.allclose(scales, coef[:2], rtol=1e-9, atol=0.0):   # held where their bounds allow, the rest refitted
        limits[:2] = np.array(scales)[:, None]
        _, left, _ = scorer.fit_effects(base, effects, train, limits)
    out[1].screened_error = float(math.sqrt(np.mean(left ** 2)))
    out[1].beside = out[0]
    return out[1]


def halfway(first: Candidate, start: Candidate, refit: Candidate) -> Candidate:
    """A pair refit's step halved: every parameter of the second cause halfway from ``start`` (its
    screening fit, beside ``first`` as fitted alone) to ``refit`` (:func:`fit_pair`), and the first
    cause's halfway from ``first`` to ``refit.beside``, each on the scale the fit moved it along (a
    magnitude on its effect's, a factor's logarithm; a second parameter linearly); the refit's
    uncertainties (taken before :func:`kept` widens them)."""
    def mid(a: Candidate, b: Candidate) -> Candidate:
        magnitude, *rest = parameters(a.hypothesis.cause)
        x, y = a.hypothesis.values, b.hypothesis.values
        values = {**y, **{p.name: 0.5 * (x[p.name] + y[p.name]) for p in rest if p.name in x and p.name in y},
                  magnitude.name: magnitude.from_effect(0.5 * (magnitude.effect(x[magnitude.name])
                                                               + magnitude.effect(y[magnitude.name])))}
        return Candidate(replace(b.hypothesis, values=values), math.nan, dict(b.std),
                         z=separation(magnitude, values[magnitude.name], b.std[magnitude.name]))

    out = mid(start, refit)
    out.beside = mid(first, refit.beside)
    return out


def _gram(columns: list[np.ndarray]) -> np.ndarray:
    """The columns' dot products with each other (the normal equations' matrix)."""
    return np.array([[float(np.dot(a, b)) for b in columns] for a in columns])


def _alike(gram: np.ndarray) -> bool:
    """Whether columns (their ``gram`` matrix) are dependent to within round-off: the last changes
    nothing the others do not, and they cannot be fitted apart."""
    return bool(np.linalg.det(gram) <= 1e-9 * np.prod(np.diag(gram)))


def _side_bounds(second: Parameter, first_value: float) -> tuple[float, float]:
    """A second parameter's bounds; a sided one's on the side of the family's first (one side per
    family, as the virtual rig draws it)."""
    lo, hi = second.bounds
    if second.sided:
        return (max(lo, 0.0), hi) if first_value >= 0.0 else (lo, min(hi, 0.0))
    return lo, hi


def value_bounds(p: Parameter, at: float) -> tuple[float, float]:
    """The values a fit may move a first parameter to from ``at``: its bounds, not below none for
    one not signed, on ``at``'s side for a sided one."""
    x0 = p.effect(at)
    lo, hi = p.bounds
    if not p.signed or (p.sided and x0 > 0.0):
        lo = max(lo, 0.0)
    if p.sided and x0 < 0.0:
        hi = min(hi, 0.0)
    return lo, hi


def scaled_magnitude(p: Parameter, at: float, coef: float, sd: float) -> tuple[float, float, float]:
    """A first parameter's value when its effect at ``at`` is scaled by ``coef`` (standard deviation
    ``sd``), kept within its bounds and on its side: the value, its uncertainty, and the scale of the
    effect it gives."""
    x0 = p.effect(at)
    lo, hi = value_bounds(p, at)
    # clipped before from_effect: a hypothesis with almost no effect gets a huge coefficient (a factor's exp overflowed)
    value = float(np.clip(p.from_effect(min(coef * x0, p.effect(hi))), lo, hi))
    scale = p.effect(value) / x0 if x0 != 0.0 else 0.0   # at no effect (clipped to it): none from here
    return value, (abs(value * x0) if p.factor else abs(x0)) * sd, scale


def separation(p: Parameter, value: float, std: float) -> float:
    """How many standard uncertainties ``std`` a magnitude ``value`` of ``p`` stands off no effect, on
    the scale its effect grows with (a factor's logarithm); NaN for a null or unbounded uncertainty
    (a hypothesis fitted from no effect at all), which does not tell."""
    std = std / value if p.factor else std
    return abs(p.effect(value)) / std if 0.0 < std < math.inf else math.nan


def significant(c: Candidate) -> bool:
    """Whether a candidate's magnitude (its first parameter) stands over SIGNIFICANT of its fit's
    standard uncertainties off no effect (``c.z``). Not the uncertainty :func:`kept` reports: the
    shift from a screening value that a second parameter, fitted since, has moved says nothing of
    whether the effect is there."""
    return c.z > SIGNIFICANT


def nudged(h: Hypothesis) -> tuple[Hypothesis, float]:
    """``h`` with its second parameter moved by a quarter of its realistic range (inwards from a
    bound), and the move: the run that gives the rows' slope along that parameter."""
    first, second = parameters(h.cause)[:2]
    value, step = h.values[second.name], 0.25 * (second.draw[1] - second.draw[0])
    lo, hi = _side_bounds(second, h.values[first.name])
    if value + step > hi:
        step = -step
    return replace(h, values={**h.values, second.name: value + step}), step


def kept(first: list[Candidate], refit: list[Candidate], simulated: Sequence[np.ndarray], scorer: Scorer
         ) -> list[Candidate]:
    """Of each candidate and its refit (whose runs are ``simulated``), the better, best first; a
    refit's uncertainty at least its shift (the linearised one ignores the model's nonlinearity)."""
    for a, b in zip(first, refit):
        b.std = {k: max(s, abs(b.hypothesis.values[k] - a.hypothesis.values[k])) for k, s in b.std.items()}
    verify(refit, simulated, scorer)
    return sorted((min(a, b, key=lambda c: c.score) for a, b in zip(first, refit)), key=lambda c: c.score)


def verify(candidates: list[Candidate], simulated: Sequence[np.ndarray], scorer: Scorer) -> None:
    """Give each candidate its full vehicle run's rows (``simulated``) and their errors."""
    for c, rows in zip(candidates, simulated):
        c.simulated = rows
        c.heldout_error = scorer.heldout_error(rows)
        c.test_errors = scorer.test_errors(rows)
