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
from typing import Sequence

import numpy as np

from elastokin.diagnosis.kc_catalogue import Hypothesis
from elastokin.diagnosis.kc_training_fit import TrainingFit, scaled
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


def rig_or_car(fit: TrainingFit, readings: Sequence[Reading]) -> list[RigOrCar]:
    """For each family of rig errors ``readings`` (fitted beside the model of ``fit``) shows
    (:func:`families`), the screened hypotheses of ``fit`` that explain what they explain as well;
    the families that have any (module docstring)."""
    fitted = fit.error(fit.fitted, fit.gram, fit.seen)
    rig = np.array([k is not None for k in fit.keys], dtype=bool)   # the rig's errors, not the acquisition's taps
    out = []
    for what, remedy, shown in families(readings):
        held = fit.bounds.copy()
        held[rig] = fit.fitted[rig, None]
        shown_keys = {g.key for g in shown}
        members = np.array([k in shown_keys for k in fit.keys], dtype=bool)
        held[members] = fit.none[members, None]
        error_held = fit.error(bounded_solve(fit.gram, fit.seen, held), fit.gram, fit.seen)
        tried = {}   # the best of each place (a cause screened on both signs is fitted from each)
        for e in fit.effects:
            if e.own == 0.0:
                continue
            coef, error = fit.beside(e, held)
            h = e.hypothesis
            if error < tried.get((h.cause, h.location), (math.inf,))[0]:
                tried[(h.cause, h.location)] = (error, h, coef[-1])
        rivals = sorted((t for t in tried.values() if decide(error_held, t[0], 1.0) == "named"
                         and not told_apart(t[0], fitted, 1.0) and not told_apart(fitted, t[0], 1.0)),
                        key=lambda t: t[0])[:RIVALS]
        if rivals:
            out.append(RigOrCar(what, shown, tuple(scaled(h, k) for _, h, k in rivals), remedy, error_held,
                                tuple(e for e, _, _ in rivals), fitted))
    return out

