"""A car cause the rig's errors may hide (issue 53 item 2), and what it would make of the rig errors the
report shows.

The rig's errors are fitted beside every hypothesis and take first what they can explain, so that no
car cause is named for what a rig error does. A car cause that acts on a campaign much as they do (a
bushing's missing viscoelasticity as the acquisition's lag and the pads' cross-talk) is then left to
them, and what they leave of it is too little to name (:func:`elastokin.diagnosis.verdict.decide`: a
tenth of the error). Yet the data may still prefer it beside them beyond chance, and the readings the
report shows are the rig's only if the car is the model: on a slow-suite draw of a missing
viscoelasticity at the front pivot's lateral direction, the pads' Fz-from-Fy cross-talk read 1.01 ±
0.15 % for the chain's 1.57 %.

Each hypothesis of the screening is fitted beside the rig's errors (its effect from its screening run:
no new run). Of those whose magnitude stands off none by more than the family-wise threshold over the
places tried (:data:`HIDDEN_ALPHA`; its uncertainty counting the residual's correlation and the tests'
disagreement, as every reading's) and which move a shown reading past its standard uncertainty, the
one that lowers the model's training error most is said, with those readings and what they read with
it: the report gives both, and the campaign cannot tell which holds. The threshold holds for every
place at once, so saying any that passes it keeps the chance of one said by chance within
:data:`HIDDEN_ALPHA`; one that fits better without passing it (a slow effect that takes the noise's
wander, or a misfit one test shows alone) is not said, nor does it silence one that passes."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.stats import norm

from elastokin.diagnosis.kc_catalogue import Hypothesis
from elastokin.diagnosis.kc_training_fit import TrainingFit, scaled
from elastokin.diagnosis.kc_transducers import Reading, held_at_limits

#: The chance that a campaign without a hidden cause has one said: its magnitude's threshold is the
#: two-sided normal quantile of this over the places tried (Bonferroni), 3.9 standard uncertainties
#: over the default car's 99.
HIDDEN_ALPHA = 0.01


@dataclass(frozen=True)
class HiddenCause:
    """The car cause the data prefer beside the rig's errors, and the shown readings it moves."""

    hypothesis: Hypothesis   #: at its fitted values
    z: float                 #: its fitted magnitude's distance from none [standard uncertainties]
    threshold: float         #: the distance it had to pass [standard uncertainties]
    error: float             #: the training error with it beside the rig's errors (1 = the noise)
    error_without: float     #: the model's
    #: the shown readings it moves past their standard uncertainty, each with itself as fitted with it
    #: (its value and standard uncertainty then)
    moved: tuple[tuple[Reading, Reading], ...]


def hidden_cause(fit: TrainingFit, readings: Sequence[Reading]) -> HiddenCause | None:
    """Of ``fit``'s screened hypotheses whose magnitude, fitted beside the rig's errors, stands off none
    beyond the threshold and which move a reading of ``readings`` the data show (:attr:`Reading.said`)
    past its standard uncertainty, the one that lowers its model's training error most (module
    docstring); else None."""
    tried = [(e, *fit.beside(e, fit.bounds)) for e in fit.effects if e.own > 0.0] \
        if any(g.said for g in readings) else []
    if not tried:
        return None
    places = len({(e.hypothesis.cause, e.hypothesis.location) for e, _, _ in tried})
    threshold = float(norm.isf(HIDDEN_ALPHA / (2 * places)))
    without = fit.error(fit.fitted, fit.gram, fit.seen)
    at = {k: i for i, k in enumerate(fit.keys) if k is not None}
    for e, coef, error in sorted(tried, key=lambda t: t[2]):
        if error >= without:
            break
        moves = [(g, i) for g in readings if g.said and (i := at.get(g.key)) is not None
                 and abs(coef[i] - fit.fitted[i]) > g.std]
        if not moves:
            continue
        d = fit.seen_effect(e)
        left = fit.residual - fit.columns.combine(coef[:-1]) - coef[-1] * d
        std = np.sqrt(fit.scorer.variances(left, fit.columns.extended([d]), fit.train))
        z = abs(float(coef[-1] / std[-1])) if std[-1] > 0.0 else 0.0
        if z > threshold:
            held = held_at_limits(coef[:-1], fit.bounds)
            moved = tuple((g, g.moved(float(coef[i] - fit.fitted[i]), float(std[i]), bool(held[i]))) for g, i in moves)
            return HiddenCause(scaled(e.hypothesis, float(coef[-1])), z, threshold, error, without, moved)
    return None
