"""A model's residual on a K&C campaign's training tests against the rig's errors, with each screened
hypothesis's effect beside them: what :mod:`elastokin.diagnosis.kc_rig_or_car` and
:mod:`elastokin.diagnosis.kc_hidden_cause` fit, from the screening's runs (no new run).

Every fit here is a bounded least-squares problem on the nuisance columns' Gram matrix and their
products with the residual (:func:`~elastokin.diagnosis.kc_transducers.bounded_solve`): a hypothesis
adds one column, its effect (its screening run less the baseline's), whose products with the
nuisance columns are computed once."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Sequence

import numpy as np

from elastokin.diagnosis.kc_catalogue import Hypothesis, parameters
from elastokin.diagnosis.kc_columns import Columns
from elastokin.diagnosis.kc_fits import scaled_magnitude, value_bounds
from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.kc_transducers import Key, bounded_solve


@dataclass(frozen=True)
class Effect:
    """A screened hypothesis's effect on the training rows as the residual sees it (its screening
    run less the baseline's, at its screening values), by its products."""

    hypothesis: Hypothesis
    run: int               #: its screening run's index in :attr:`TrainingFit.runs`
    products: np.ndarray   #: (K,) with the nuisance columns
    own: float             #: with itself
    with_model: float      #: with the model's residual before the nuisances are fitted


@dataclass
class TrainingFit:
    """The model's residual on the training tests against the nuisance columns (:meth:`Scorer.nuisances`),
    and the screened hypotheses' effects (:class:`Effect`) to fit beside them."""

    scorer: Scorer
    base: np.ndarray         #: (N, C) the baseline's rows
    residual: np.ndarray     #: (n, C) the model's raw residual on the training rows, in noise units
    columns: Columns         #: the nuisance columns there
    gram: np.ndarray         #: (K, K) their products with each other
    bounds: np.ndarray       #: (K, 2) each one's bounds
    none: np.ndarray         #: (K,) each one's coefficient of no error
    keys: list[Key | None]   #: each one's key (None for the acquisition's taps)
    seen: np.ndarray         #: (K,) their products with the residual
    fitted: np.ndarray       #: (K,) their coefficients fitted within their bounds
    hypotheses: Sequence[Hypothesis]   #: the screened hypotheses
    #: their screening runs' rows, each (N, C) as read (a RunRows makes them when read: 119 read at once
    #: were 215 MiB of the shipped dataset's diagnosis)
    runs: Sequence[np.ndarray]
    kept: list[int]          #: the hypotheses fitted: those not at a named cause's place

    @cached_property
    def effects(self) -> list[Effect]:
        """Each kept screened hypothesis's :class:`Effect`, computed when first asked for, one at a time
        (never all held: 119 arrays of the training rows' size)."""
        out = []
        for k in self.kept:
            d = self.scorer.seen(self.runs[k] - self.base, self.train)
            out.append(Effect(self.hypotheses[k], k, self.columns.products(d), float(np.sum(d * d)),
                              float(np.sum(d * self.residual))))
        return out

    @cached_property
    def train(self) -> np.ndarray:
        """(N,) the training rows."""
        return ~self.scorer.held_rows

    @cached_property
    def squared(self) -> float:
        """The residual's sum of squares (noise units)."""
        return float(np.sum(self.residual * self.residual))

    def seen_effect(self, e: Effect) -> np.ndarray:
        """(n, C) ``e``'s effect on the training rows as the residual sees it."""
        return self.scorer.seen(self.runs[e.run] - self.base, self.train)

    def error(self, coef: np.ndarray, matrix: np.ndarray, products: np.ndarray) -> float:
        """The RMS residual (1 = the noise) left by columns of Gram ``matrix`` and products ``products``
        with the residual at coefficients ``coef`` (the nuisance columns first)."""
        return math.sqrt(max(self.squared - 2.0 * coef @ products + coef @ matrix @ coef, 0.0) / self.residual.size)

    def beside(self, e: Effect, limits: np.ndarray) -> tuple[np.ndarray, float]:
        """The coefficients (K + 1,) of the nuisance columns within ``limits`` (K, 2) and of ``e``'s
        effect within the scales of it its first parameter's bounds allow (:func:`scales`), fitted
        together; the training error they leave."""
        matrix = np.block([[self.gram, e.products[:, None]], [e.products[None, :], np.array([[e.own]])]])
        both = np.append(self.seen, e.with_model)
        # started from the limits the model's fit holds: one effect more moves few of them
        coef = bounded_solve(matrix, both, np.vstack([limits, scales(e.hypothesis)]),
                             start=np.append(self.fitted, np.nan))
        return coef, self.error(coef, matrix, both)


def training_fit(scorer: Scorer, model: np.ndarray, hypotheses: Sequence[Hypothesis],
                 runs: Sequence[np.ndarray], base: np.ndarray, named: Sequence[Hypothesis] = ()) -> TrainingFit:
    """``model``'s (N, C) :class:`TrainingFit`, with the effects of the hypotheses of the screening
    (``hypotheses``, their runs' rows ``runs`` on the training tests, each (N, C) when read; ``base``:
    the baseline's) but those at the places of ``named`` (the model's own causes)."""
    train = ~scorer.held_rows
    m = scorer.raw(model, train)
    columns, gram, bounds, none, keys = scorer.nuisances(train)
    seen = columns.products(m)
    kept = [k for k, h in enumerate(hypotheses) if all((h.cause, h.location) != (n.cause, n.location) for n in named)]
    return TrainingFit(scorer, base, m, columns, gram, bounds, none, keys, seen, bounded_solve(gram, seen, bounds),
                       hypotheses, runs, kept)


def scales(h: Hypothesis) -> tuple[float, float]:
    """The scales of ``h``'s effect its first parameter's bounds allow (:func:`value_bounds`)."""
    first = parameters(h.cause)[0]
    x0 = first.effect(h.values[first.name])
    lo, hi = sorted(first.effect(v) / x0 for v in value_bounds(first, h.values[first.name])) if x0 else (0.0, 0.0)
    return lo, hi


def scaled(h: Hypothesis, scale: float) -> Hypothesis:
    """``h`` with its effect scaled by ``scale`` (its first parameter as the screening fit moves it)."""
    first = parameters(h.cause)[0]
    value, _, _ = scaled_magnitude(first, h.values[first.name], scale, 0.0)
    return Hypothesis(h.cause, h.location, {**h.values, first.name: value})
