"""Rig errors that a car cause would explain as well (issue 53 item 3): what the diagnosis took out
as the rig's (its transducers' calibration, its inputs' transducers, its pads' friction, its body
clamp's compliance), told from the car's causes or not.

The rig's errors are fitted with every hypothesis and take what they can explain first, so that no
car cause is named for what a rig error does. But a car cause can act on a campaign as a rig error
does (a lower ball joint's height on camber as the camber heads' gain, a bushing's lateral
stiffness on a lateral-force test as its load cells' gain): then the campaign cannot say which of
the two it was, and the verdict must say so. For each group of rig errors the data show
(:data:`GROUPS`), the group is held at no error and every hypothesis of the screening is fitted in
its stead on the training tests (its effect from its screening run, the other nuisances refitted
with it, all in the nuisances' span: no run). A hypothesis that explains what the group explained
as a cause must (:func:`elastokin.diagnosis.verdict.decide` against the model with the group held)
and that the group does not beat as a cause must beat its rival, nor beats it
(:func:`elastokin.diagnosis.verdict.told_apart`: one that explains more than the group did is a cause
missed, not the group's rival) is reported beside the group with the check that separates them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from elastokin.diagnosis.kc_catalogue import Hypothesis, parameters
from elastokin.diagnosis.kc_fits import scaled_magnitude, value_bounds
from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.kc_rig_mechanics import BY_KEY, RIG
from elastokin.diagnosis.kc_transducers import CROSS, GAIN, INPUT_GAIN, Key, Reading, bounded_solve
from elastokin.diagnosis.verdict import decide, told_apart

#: Groups of rig errors held together, by the kinds of :class:`Reading` they hold (a rig element:
#: each alone), with what they are and the check that tells them from the car.
GROUPS = {
    "transducers": ((GAIN, CROSS), "the wheel sensors' and load cells' calibration",
                    "a static calibration of the transducers separates them"),
    "inputs": ((INPUT_GAIN,), "the rig inputs' transducers",
               "a calibration of the pads' displacement and force transducers against a reference separates them"),
    "pad_friction_n": ((RIG,), BY_KEY["pad_friction_n"].label,
                       "the pads' breakaway force measured with the car off them separates them"),
    **{key: ((RIG,), BY_KEY[key].label, "the body's motion measured against the bedplate under the test's loads "
                                        "(dial gauges at the clamps) separates them")
       for key in BY_KEY if key.startswith("clamp_")},
}
#: Rivals reported per group, best first.
RIVALS = 2


@dataclass(frozen=True)
class RigOrCar:
    """A group of rig errors the data show and the car causes that would explain what it explains."""

    group: str                        #: what the group is (:data:`GROUPS`)
    readings: tuple[Reading, ...]     #: the group's errors the data show, most significant first
    rivals: tuple[Hypothesis, ...]    #: the car causes fitted in its stead, best first
    remedy: str                       #: the check that tells them apart
    error_held: float                 #: the training error with the group held at no error (1 = the noise)
    error_rivals: tuple[float, ...]   #: with each rival in its stead
    error: float                      #: with the group fitted (the model's)


def _members(keys: Sequence[Key | None], name: str) -> np.ndarray:
    """Which nuisance columns (their ``keys``) belong to the group ``name``."""
    kinds = GROUPS[name][0]
    return np.array([k is not None and k[0] in kinds and (k[0] != RIG or k[1] == name) for k in keys], dtype=bool)


def rig_or_car(scorer: Scorer, model: np.ndarray, readings: Sequence[Reading],
               screened: Sequence[tuple[Hypothesis, np.ndarray]], base: np.ndarray,
               named: Sequence[Hypothesis] = ()) -> list[RigOrCar]:
    """For each group of rig errors of which ``readings`` (fitted beside ``model``'s rows) shows one,
    the hypotheses of the screening (``screened``: each with its run's rows on the training tests;
    ``base``: the baseline's) that explain what the group explains as well, but ``named`` (the
    model's own causes); the groups that have any (module docstring)."""
    train = ~scorer.held_rows
    m = scorer.raw(model, train)
    columns, gram, bounds, none, keys = scorer.nuisances(train)
    seen, mm, size = columns.products(m), float(np.sum(m * m)), m.size
    error = lambda coef, matrix, products: math.sqrt(max(mm - 2.0 * coef @ products + coef @ matrix @ coef, 0.0)
                                                     / size)
    fitted = error(bounded_solve(gram, seen, bounds), gram, seen)
    out = []
    effects = None   # each hypothesis's effect and its products with the columns, computed once
    for name, (_, what, remedy) in GROUPS.items():
        members = _members(keys, name)
        shown = sorted((g for g in readings if g.said and _members([(g.kind, g.channel, g.source)], name)[0]),
                       key=lambda g: -abs(g.value) / g.std if g.std > 0.0 else -math.inf)
        if not shown:
            continue
        held = bounds.copy()
        held[members] = none[members, None]
        error_held = error(bounded_solve(gram, seen, held), gram, seen)
        if effects is None:
            effects = []
            for h, rows in screened:
                if any((h.cause, h.location) == (n.cause, n.location) for n in named):
                    continue
                d = m - scorer.raw(model + (rows - base), train)
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
            out.append(RigOrCar(what, tuple(shown), tuple(_scaled(h, k) for _, h, k in rivals), remedy, error_held,
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
