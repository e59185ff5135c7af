"""Where a cause's fit starts and within which bounds (elastokin.diagnosis.fit_starts): one side per
catalogue family for its sided parameters, each side fitted within bounds that stop at zero."""

from __future__ import annotations

import math

import numpy as np
import pytest

from elastokin.diagnosis.catalogue import CAUSES, combined
from elastokin.diagnosis.fit_starts import corner_starts, fit_bounds, side_starts, sides_apart, to_fit

ASYMMETRY, PRELOAD, MULLINS = CAUSES["asymmetry"], CAUSES["preload"], CAUSES["mullins"]


def test_corners_keep_a_family_on_one_side_and_start_its_other_form_alone():
    """Asymmetry (rate and kink sided, power and kink width not): 2 sides × 2 × 2 magnitudes × 2
    powers × 2 widths = 32 corners, never the kink on one side and the progressive part on the
    other; then the kink alone (the progressive part off, its power at rest) at its 2 × 2 signed
    magnitudes and 2 widths, each point once."""
    starts = corner_starts(ASYMMETRY)
    assert starts.shape == (32 + 8, 4) and len(np.unique(starts, axis=0)) == len(starts)
    rate, kink, power, width = starts.T
    assert np.all(np.sign(rate[:32]) == np.sign(kink[:32])) and (rate > 0).sum() == 16
    np.testing.assert_allclose(np.unique(np.abs(kink)), ASYMMETRY.parameters[1].draw)
    np.testing.assert_allclose(np.unique(power), ASYMMETRY.parameters[2].draw)
    np.testing.assert_allclose(np.unique(width), ASYMMETRY.parameters[3].draw)
    alone = starts[32:]
    np.testing.assert_array_equal(alone[:, [0, 2]], np.tile([0.0, 1.0], (8, 1)))
    np.testing.assert_allclose(np.sort(alone[:, 1]), np.repeat(np.r_[-np.array(ASYMMETRY.parameters[1].draw)[::-1],
                                                                     ASYMMETRY.parameters[1].draw], 2))
    # one side per point: the kink alone takes its side from the kink (the rate is zero)
    assert len(sides_apart(ASYMMETRY, starts)) == 2


def test_the_viscous_family_starts_its_dashpot_alone():
    """The dashpot alone (the ladder's dampers at the bound Co = 0.1) is a start, with the dashpot at
    each end of its realistic range: a fit from the dampers' corners stops far from it."""
    cause = CAUSES["viscoelasticity_missing"]
    starts = corner_starts(cause)
    alone = starts[np.isclose(starts[:, 0], math.log(cause.parameters[0].bounds[0]))]
    np.testing.assert_allclose(alone[:, 2], cause.parameters[2].draw)
    assert len(starts) == 8 + 2


def test_a_pair_of_sided_families_is_fitted_on_each_of_its_four_sides():
    pair = combined(ASYMMETRY, PRELOAD)
    starts = corner_starts(pair)
    sides = sides_apart(pair, starts)
    assert len(sides) == 4 and sum(on.sum() for on, _, _ in sides) == len(starts) == 32 * 4
    lo, hi = fit_bounds(pair)
    for on, lo_k, hi_k in sides:
        z = starts[on]
        assert np.all((z >= lo_k) & (z <= hi_k))
        for idx in ([0, 1], [4]):   # each family's sided parameters bounded at zero on their side
            positive = z[0, idx[0]] > 0
            np.testing.assert_array_equal(lo_k[idx], 0.0 if positive else lo[idx])
            np.testing.assert_array_equal(hi_k[idx], hi[idx] if positive else 0.0)
        assert (lo_k[2], hi_k[2], lo_k[3], hi_k[3]) == (lo[2], hi[2], lo[3], hi[3])   # power, width not sided


def test_a_start_is_tried_on_each_side_and_a_zero_takes_the_weak_end_of_its_range():
    values = {"asymmetry": 0.1, "asymmetry_step": 0.0, "asymmetry_power": 1.5, "asymmetry_step_width": 0.5,
              "preload": -2.0}
    pair = combined(ASYMMETRY, PRELOAD)
    starts = side_starts(pair, values)
    weak = ASYMMETRY.parameters[1].draw[0]
    assert starts.shape == (4, 5)
    assert {tuple(np.sign(s[[0, 1, 4]])) for s in starts} == {(1, 1, 1), (1, 1, -1), (-1, -1, 1), (-1, -1, -1)}
    np.testing.assert_allclose(np.abs(starts), np.tile([0.1, weak, 1.5, 0.5, 2.0], (4, 1)))
    assert any(np.array_equal(s, [0.1, weak, 1.5, 0.5, -2.0]) for s in starts)   # the start itself, kept


def test_a_cause_without_a_sided_parameter_has_one_side_and_its_own_bounds():
    starts = corner_starts(MULLINS)
    (on, lo, hi), = sides_apart(MULLINS, starts)
    assert on.all()
    np.testing.assert_array_equal(np.c_[lo, hi], np.c_[fit_bounds(MULLINS)])
    np.testing.assert_allclose(np.unique(starts[:, 1]), np.log(MULLINS.parameters[1].draw))
    np.testing.assert_allclose(to_fit(MULLINS, {"mullins": 0.2, "mullins_shape": math.e}), [0.2, 1.0])
    with pytest.raises(ValueError, match="no starting point"):
        sides_apart(MULLINS, starts[:0])
