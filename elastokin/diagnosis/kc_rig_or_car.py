"""Rig errors that a car cause would explain as well (issue 53 item 3): what the diagnosis took out
as the rig's (its transducers' calibration, its inputs' transducers, its pads' friction, its body
clamp's compliance), told from the car's causes or not.

The rig's errors are fitted with every hypothesis and take what they can explain first, so that no
car cause is named for what a rig error does. But a car cause can act on a campaign as a rig error
does (a lower ball joint's height on camber as the camber heads' gain, a bushing's lateral stiffness
on a lateral-force test as its load cells' gain): then the campaign cannot say which of the two it
was, and the verdict must say so. For each family of rig errors the data show (:func:`families`: the
readings of one kind on one quantity, a camber head's gain on every wheel where it shows; a rig
element alone), those readings are held at no error and every hypothesis of the screening is fitted
in their stead on the training tests (its effect from its screening run, the acquisition's taps
refitted with it, all in the nuisances' span: no run), the other rig errors held where the model has
them: a rival explains what those readings took out, not what another wheel's or another kind's
calibration would have to take in its stead. A hypothesis that explains what they explained as a
cause must (:func:`elastokin.diagnosis.verdict.decide` against the model with them held) and that
they do not beat as a cause must beat its rival, nor beats them
(:func:`elastokin.diagnosis.verdict.told_apart`: one that explains more than they did is a cause
missed, not their rival) is reported beside them with the check that separates them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable, Sequence

import numpy as np

from elastokin.diagnosis.kc_catalogue import Hypothesis, parameters
from elastokin.diagnosis.kc_fits import scaled_magnitude, value_bounds
from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.kc_rig_mechanics import BY_KEY, RIG
from elastokin.diagnosis.kc_transducers import CROSS, DRIFT, GAIN, INPUT_GAIN, Reading, bounded_solve
from elastokin.diagnosis.verdict import decide, told_apart
from elastokin.vehicle.scenarios.channels import channel_quantity

#: A transducer family's description and the check that tells it from the car, by kind (its
#: quantity and source filled in).
TRANSDUCER_FAMILIES = {
    GAIN: ("the {quantity} transducers' calibration",
           "a static calibration of the {quantity} transducers separates them"),
    CROSS: ("the {quantity} transducers' cross-talk from {source}",
            "a static calibration of the {quantity} transducers with {source} moved alone separates them"),
    INPUT_GAIN: ("the {quantity} inputs' transducers",
                 "a calibration of the {quantity} transducers against a reference separates them"),
    DRIFT: ("the {quantity} transducers' zeros drifting through {source}",
            "the {quantity} channels recorded with the rig at rest before and after the test separate them"),
}
#: The rig's mechanics: each element's check.
RIG_REMEDIES = {"pad_friction_n": "the pads' breakaway force measured with the car off them separates them",
                **{key: "the body's motion measured against the bedplate under the test's loads (dial gauges at "
                        "the clamps) separates them" for key in BY_KEY if key.startswith("clamp_")}}
#: Rivals reported per family, best first.
RIVALS = 2


@dataclass(frozen=True)
class RigOrCar:
    """A family of rig errors the data show and the car causes that would explain what it explains."""

    group: str                        #: what the family is (:func:`families`)
    readings: tuple[Reading, ...]     #: its errors the data show, most significant first
    rivals: tuple[Hypothesis, ...]    #: the car causes fitted in their stead, best first
    remedy: str                       #: the check that tells them apart
    error_held: float                 #: the training error with them held at no error (1 = the noise)
    error_rivals: tuple[float, ...]   #: with each rival in their stead
    error: float                      #: with them fitted (the model's)


def families(readings: Sequence[Reading]) -> list[tuple[str, str, tuple[Reading, ...]]]:
    """The rig errors the data show (:attr:`Reading.said`) in families held together: the readings
    of one kind on one quantity with one source (a camber head's gain, on every wheel where it
    shows), a rig element alone; each as (what it is, the check that separates it from the car, its
    readings most significant first)."""
    out: dict[tuple, list[Reading]] = {}
    for g in readings:
        if g.said:
            family = (g.kind, g.channel if g.kind == RIG else channel_quantity(g.channel), g.source)
            out.setdefault(family, []).append(g)
    said = []
    for (kind, quantity, source), shown in out.items():
        what, remedy = ((BY_KEY[quantity].label, RIG_REMEDIES[quantity]) if kind == RIG else
                        (text.format(quantity=quantity, source=source) for text in TRANSDUCER_FAMILIES[kind]))
        said.append((what, remedy, tuple(sorted(shown, key=lambda g: -abs(g.value) / g.std if g.std > 0.0
                                                else -math.inf))))
    return said


def rig_or_car(scorer: Scorer, model: np.ndarray, readings: Sequence[Reading],
               screened: Iterable[tuple[Hypothesis, np.ndarray]], base: np.ndarray,
               named: Sequence[Hypothesis] = ()) -> list[RigOrCar]:
    """For each family of rig errors ``readings`` (fitted beside ``model``'s rows) shows
    (:func:`families`), the hypotheses of the screening (``screened``: each with its run's rows on the
    training tests; ``base``: the baseline's) that explain what they explain as well, but ``named``
    (the model's own causes); the families that have any (module docstring)."""
    train = ~scorer.held_rows
    m = scorer.raw(model, train)
    columns, gram, bounds, none, keys = scorer.nuisances(train)
    seen, mm, size = columns.products(m), float(np.sum(m * m)), m.size
    error = lambda coef, matrix, products: math.sqrt(max(mm - 2.0 * coef @ products + coef @ matrix @ coef, 0.0)
                                                     / size)
    fitted_at = bounded_solve(gram, seen, bounds)
    fitted = error(fitted_at, gram, seen)
    rig = np.array([k is not None for k in keys], dtype=bool)   # the rig's errors, not the acquisition's taps
    out = []
    effects = None   # each hypothesis's effect and its products with the columns, computed once
    for what, remedy, shown in families(readings):
        held = bounds.copy()
        held[rig] = fitted_at[rig, None]
        shown_keys = {(g.kind, g.channel, g.source) for g in shown}
        members = np.array([k in shown_keys for k in keys], dtype=bool)
        held[members] = none[members, None]
        error_held = error(bounded_solve(gram, seen, held), gram, seen)
        if effects is None:
            effects = []
            for h, rows in screened:
                if any((h.cause, h.location) == (n.cause, n.location) for n in named):
                    continue
                d = scorer.seen(rows - base, train)
                effects.append((h, columns.products(d), float(np.sum(d * d)), float(np.sum(d * m))))
        tried = {}   # the best of each place (a cause screened on both signs is fitted from each)
        for h, products, dd, dm in effects:
            if dd == 0.0:
                continue
            matrix = np.block([[gram, products[:, None]], [products[None, :], np.array([[dd]])]])
            both = np.append(seen, dm)
            coef = bounded_solve(matrix, both, np.vstack([held, _scales(h)]))
            e = error(coef, matrix, both)
            if e < tried.get((h.cause, h.location), (math.inf,))[0]:
                tried[(h.cause, h.location)] = (e, h, coef[-1])
        rivals = sorted((t for t in tried.values() if decide(error_held, t[0], 1.0) == "named"
                         and not told_apart(t[0], fitted, 1.0) and not told_apart(fitted, t[0], 1.0)),
                        key=lambda t: t[0])[:RIVALS]
        if rivals:
            out.append(RigOrCar(what, shown, tuple(_scaled(h, k) for _, h, k in rivals), remedy, error_held,
                                tuple(e for e, _, _ in rivals), fitted))
    return out


def _scales(h: Hypothesis) -> tuple[float, float]:
    """The scales of ``h``'s effect its first parameter's bounds allow (:func:`value_bounds`)."""
    first = parameters(h.cause)[0]
    x0 = first.effect(h.values[first.name])
    lo, hi = sorted(first.effect(v) / x0 for v in value_bounds(first, h.values[first.name])) if x0 else (0.0, 0.0)
    return lo, hi


def _scaled(h: Hypothesis, scale: float) -> Hypothesis:
    """``h`` with its effect scaled by ``scale`` (its first parameter as the screening fit moves it)."""
    first = parameters(h.cause)[0]
    value, _, _ = scaled_magnitude(first, h.values[first.name], scale, 0.0)
    return Hypothesis(h.cause, h.location, {**h.values, first.name: value})
