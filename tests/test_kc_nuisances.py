"""The K&C diagnosis's nuisance algebra: the bounded least squares that holds a rig input's gain and
the rig's mechanics within their bounds, and the one-channel columns held compactly, against the
dense forms they stand for."""

import numpy as np
import pytest
from scipy.optimize import lsq_linear

from elastokin.diagnosis.kc_columns import Columns, OneChannel
from elastokin.diagnosis.kc_transducers import bounded_solve


@pytest.mark.parametrize("seed", range(5))
def test_the_bounded_fit_is_the_bounded_least_squares_optimum(seed):
    """On random problems with correlated columns, some bounded on one or both sides and some held
    (both bounds equal): within the bounds, and its squared error the bounded-variable least squares'
    (scipy's BVLS, written apart) to 1e-10 — where holding each out-of-bounds coefficient and refitting
    the rest once pushes another out of its bounds (columns correlated at 0.9)."""
    rng = np.random.default_rng(seed)
    for _ in range(40):
        n, k = 80, int(rng.integers(2, 14))
        a = rng.standard_normal((n, k))
        a[:, 1] = 0.9 * a[:, 0] + 0.1 * a[:, 1]
        b = 3.0 * rng.standard_normal(n)
        lo = np.where(rng.random(k) < 0.5, -np.inf, -0.3 * rng.random(k))
        hi = np.where(rng.random(k) < 0.5, np.inf, 0.3 * rng.random(k))
        held = rng.random(k) < 0.15
        lo[held] = hi[held] = 0.1
        gram, seen = a.T @ a, a.T @ b
        x = bounded_solve(gram, seen, np.column_stack([lo, hi]), np.linalg.pinv(gram))
        assert np.all(x >= lo) and np.all(x <= hi) and np.all(x[held] == 0.1)
        free = ~held
        ref = lsq_linear(a[:, free], b - a[:, held] @ x[held], bounds=(lo[free], hi[free]), method="bvls").x
        sse = lambda z: float(np.sum((a[:, free] @ z - (b - a[:, held] @ x[held])) ** 2))
        assert sse(x[free]) == pytest.approx(sse(ref), rel=1e-10)


def test_one_channel_columns_act_as_their_dense_forms():
    """Products with a residual, the Gram matrix and a weighted sum of dense and one-channel columns
    (two on one channel, so that their product is kept) equal the dense arrays' to 1e-12, extended by
    dense columns too."""
    rng = np.random.default_rng(7)
    n, c = 50, 4
    ones = [OneChannel(2, rng.standard_normal(n)), OneChannel(0, rng.standard_normal(n)),
            OneChannel(2, rng.standard_normal(n))]
    dense = [rng.standard_normal((n, c)) for _ in range(2)]
    order = [ones[0], dense[0], ones[1], ones[2], dense[1]]
    as_dense = []
    for col in order:
        full = np.zeros((n, c))
        if isinstance(col, OneChannel):
            full[:, col.channel] = col.values
        else:
            full = col
        as_dense.append(full)
    extra = rng.standard_normal((n, c))
    stack = Columns(order, (n, c)).extended([extra])
    flat = np.array([x.ravel() for x in as_dense + [extra]])
    r = rng.standard_normal((n, c))
    coef = rng.standard_normal(len(flat))
    assert stack.products(r) == pytest.approx(flat @ r.ravel(), rel=1e-12, abs=1e-12)
    assert stack.gram() == pytest.approx(flat @ flat.T, rel=1e-12, abs=1e-12)
    assert stack.combine(coef).ravel() == pytest.approx(coef @ flat, rel=1e-12, abs=1e-12)
