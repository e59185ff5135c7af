"""Shared by the Magic Formula tests: the grid of operating points at which the compiled formula is
compared with a plain-Python evaluation of the published equations."""

from __future__ import annotations

from typing import Callable

import numpy as np

from elastokin.tyres import magic_formula as mf

#: Loads [N], slips, slip angles and inclinations [rad], speeds [m/s] (below VXLOW, about LONGVL,
#: above): the linear range, the peaks and beyond, both signs.
GRID = dict(fz=(1500.0, 4000.0, 6500.0), kappa=(-0.3, -0.04, 0.0, 0.012, 0.15),
            alpha=np.radians((-12.0, -2.0, 0.0, 0.7, 6.0)), gamma=np.radians((-4.0, 0.0, 3.0)), vx=(0.4, 16.7, 35.0))


def assert_formula_is(p: np.record, reference: Callable[..., tuple]) -> dict[str, np.ndarray]:
    """Assert that the compiled ``(Fx, Fy, Mz, My)`` of ``p`` equal ``reference(coefficients, fz, κ, α,
    γ, vx)`` at every point of :data:`GRID` to 1e-9 (relative, or of the largest value) and that the
    grid reaches the nonlinear range; the compiled values (arrays over the grid) by name."""
    c = {name: float(p[name]) for name in mf.DTYPE.names}
    grid = np.meshgrid(*GRID.values(), indexing="ij")
    got = mf.evaluate(p, *grid)
    want = np.vectorize(lambda *x: reference(c, *x), otypes=[float] * 4)(*grid)
    for name, expected in zip(("Fx", "Fy", "Mz", "My"), want):
        scale = np.abs(expected).max()
        np.testing.assert_allclose(got[name], expected, rtol=1e-9, atol=1e-9 * scale, err_msg=name)
    assert np.abs(got["Fy"]).max() > 3000 and np.abs(got["Mz"]).max() > 30     # the grid reaches the nonlinear range
    return got
