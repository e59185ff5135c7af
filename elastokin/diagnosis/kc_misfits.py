"""Where a model does not fit a K&C campaign (:mod:`elastokin.diagnosis.kc_diagnosis`): the tests, or
stretches of them, whose error is beyond the measurement noise, its correlation counted."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from elastokin.diagnosis.kc_layout import Layout
from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.verdict import misfit, misfit_stretch


@dataclass(frozen=True)
class Misfit:
    """A test a model does not fit, and where in it (:func:`elastokin.diagnosis.verdict.misfit_stretch`)."""

    test: str
    heldout: bool
    error: float          #: the model's RMS error on it (1 = the noise), each recording's zeros its medians
    chance: float         #: the chance that the noise alone shows a stretch as unlikely in the test
    start_s: float        #: the stretch of the test holding the excess: from, to [s of its input]
    end_s: float
    channel: str          #: the channel with the most excess there


def located_misfits(layout: Layout, scorer: Scorer, predicted: np.ndarray) -> list[Misfit]:
    """The tests ``predicted`` does not fit (:func:`elastokin.diagnosis.verdict.misfit`: the RMS error
    over a test or a stretch of it beyond the noise, its correlation counted; every test, training
    or held out), each with where; each recording's zeros taken as its medians, so that one misfit
    does not shift the tests beside it."""
    residual = scorer.residual(predicted, np.ones(len(predicted), dtype=bool), np.median)
    out = []
    for i, t in enumerate(layout.tests):
        error = float(np.sqrt(np.mean(residual[t.rows] ** 2)))
        dt = float(np.median(np.diff(layout.input_time[t.rows]))) if len(t.rows) > 1 else 0.0
        chance, first, last, channel = misfit_stretch(residual[t.rows],
                                                      lambda width: scorer.noise_model.window_dof(width, dt))
        if misfit(error, chance):
            out.append(Misfit(t.name, bool(scorer.heldout[i]), error, chance, float(layout.input_time[t.rows[first]]),
                              float(layout.input_time[t.rows[last]]), layout.channels[channel]))
    return out
