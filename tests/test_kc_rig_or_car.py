"""Rig errors a car cause would explain as well (:mod:`elastokin.diagnosis.kc_rig_or_car`), and the
calibration's bound that keeps a transducer's error from taking a car cause's effect, on small
synthetic campaigns whose every column is known."""

import numpy as np
import pytest

from elastokin.diagnosis.kc_catalogue import Hypothesis
from elastokin.diagnosis import kc_layout
from elastokin.diagnosis.kc_rig_or_car import rig_or_car
from elastokin.diagnosis.kc_scorer import Scorer
from elastokin.diagnosis.kc_training_fit import training_fit
from elastokin.diagnosis.kc_transducers import CALIBRATION_BOUND
from elastokin.diagnosis.verdict import split

NOISE = 0.002
NOMINAL_OFFSET_MM = 2.0


def campaign(channels: list[str], scales: list[float], seed: int = 5, extra: np.ndarray | float = 0.0
             ) -> tuple[Scorer, np.ndarray]:
    """Four tests of one smooth response per channel, measured as ``scales`` × it, plus ``extra``
    (N, C) and white noise of NOISE, each channel's gain a nuisance: the scorer and the baseline's
    rows (N, C)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, 4000)
    base = np.column_stack([np.sin((2 + k) * np.pi * t + k) for k in range(len(channels))])
    measured = base * scales + extra + NOISE * rng.standard_normal(base.shape)
    tests = [kc_layout.Test(name, None, rows, np.arange(1000), True)
             for name, rows in zip("abcd", np.split(np.arange(4000), 4))]
    layout = kc_layout.Layout(channels, measured, np.zeros(4000), np.zeros(4000, dtype=int),
                              np.repeat(np.arange(4), 1000), tests)
    gains = {("gain", c, None): np.where(np.arange(len(channels)) == k, base, 0.0) for k, c in enumerate(channels)}
    return Scorer(layout, base, split(4), gains), base


def test_a_rig_error_a_car_cause_would_explain_as_well_is_said_with_it():
    """A channel reading 2 % high (its transducer's gain) where one hypothesis's effect is that very
    scaling and another's moves the other channel too: the gain is taken out, and the first is said to
    explain it as well (at the value that scales its effect to it), the second not (the other
    channel's gain held where the data have it, at none); with the rival's effect on a second channel
    beyond the noise, nothing is said."""
    scorer, base = campaign(["c_x", "c_y"], [1.02, 1.0])
    readings = scorer.rig_errors(base)
    assert readings[0].value == pytest.approx(0.02, abs=1e-3) and readings[0].said and not readings[1].said
    alike_h = Hypothesis("hardpoint", ("front", "lower_ball_joint", "z"), {"offset": NOMINAL_OFFSET_MM})
    apart = Hypothesis("hardpoint", ("front", "tie_rod_inner", "z"), {"offset": NOMINAL_OFFSET_MM})
    effect = 0.01 * base * [1.0, 0.0]   # the nominal offset scales c_x by 1 %
    screened = [(alike_h, base + effect), (apart, base + effect + 0.01 * base * [0.0, 1.0])]
    (said,) = rig_or_car(training_fit(scorer, base, *zip(*screened), base), readings)
    assert [h.location for h in said.rivals] == [alike_h.location]
    assert said.rivals[0].values["offset"] == pytest.approx(2.0 * NOMINAL_OFFSET_MM, rel=0.05)
    assert said.readings == (readings[0],) and said.error_held > 1.5 > said.error_rivals[0]
    assert rig_or_car(training_fit(scorer, base, *zip(*screened[1:]), base), readings) == []


def test_each_family_of_rig_errors_is_held_apart_from_the_others():
    """Both camber heads reading 2 % high and a toe head 2 % low: a hardpoint tilting both cambers
    by 1 % per 2 mm is said to explain the camber heads' gains (both, at 4 mm), though it explains
    nothing of the toe head's, which stays taken out beside it; the toe head's family has no rival."""
    scorer, base = campaign(["camber_fl", "camber_fr", "toe_fl"], [1.02, 1.02, 0.98])
    readings = scorer.rig_errors(base)
    assert [round(g.value, 3) for g in readings] == [0.02, 0.02, -0.02] and all(g.said for g in readings)
    strut = Hypothesis("hardpoint", ("front", "strut_top", "y"), {"offset": NOMINAL_OFFSET_MM})
    screened = [(strut, base + 0.01 * base * [1.0, 1.0, 0.0])]
    (said,) = rig_or_car(training_fit(scorer, base, *zip(*screened), base), readings)
    assert said.group == "the camber transducers' calibration" and "camber transducers" in said.remedy
    assert {g.channel for g in said.readings} == {"camber_fl", "camber_fr"}
    assert said.rivals[0].values["offset"] == pytest.approx(2.0 * NOMINAL_OFFSET_MM, rel=0.05)
    assert said.error_rivals[0] == pytest.approx(said.error, rel=0.01) and said.error_held > 1.5


@pytest.mark.parametrize("sign", [-1.0, 1.0])
def test_a_transducer_error_beyond_a_calibrated_rigs_is_held_at_its_bound(sign):
    """A channel 4 % off (twice a calibrated rig's worst, as a car cause acting as a gain makes it):
    its gain is read at the calibration's bound and said to be there, the rest left in the residual
    for the car's causes (the 1.5 % beyond the bound: 0.015 of the response's RMS over the noise);
    a channel 1 % off is read at its value."""
    scorer, base = campaign(["c_x", "c_y"], [1.0 + sign * 0.04, 1.0 + sign * 0.01])
    far, near = scorer.rig_errors(base)
    assert far.value == sign * CALIBRATION_BOUND and far.at_bound and "at its bound" in far.text
    assert near.value == pytest.approx(sign * 0.01, abs=5 * near.std) and not near.at_bound
    left = scorer.residual(base, np.ones(4000, dtype=bool))
    expected = (0.04 - CALIBRATION_BOUND) * np.sqrt(np.mean(base[:, 0] ** 2)) / NOISE
    assert np.sqrt(np.mean(left[:, 0] ** 2)) == pytest.approx(np.hypot(expected, 1.0), rel=0.05)
