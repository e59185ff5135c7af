"""The fit uncertainty of the bench diagnosis against the spread of fits over many draws."""

import numpy as np
import pytest

from elastokin.diagnosis.fit_uncertainty import standard_errors

TESTS, SAMPLES, DRAWS = 16, 400, 400
PHASE = 2.0 * np.pi * np.arange(SAMPLES) / 4.0
#: Two regressors over a test, 4 samples a period: a sine, and one correlated with it (cos 45°)
COLUMNS = np.column_stack([np.sin(PHASE), np.sin(PHASE + np.pi / 4.0)])


def _fits(error_amplitude: float, columns: np.ndarray, seed: int = 7) -> tuple[np.ndarray, np.ndarray]:
    """Fitted parameters and their standard errors (DRAWS, p) over campaigns of TESTS tests,
    y = columns·θ + error: the error a model error repeating cycle after cycle (a cosine of the
    test's own random amplitude, no correlation from one sample to the next) and white noise of
    standard deviation 1."""
    rng = np.random.default_rng(seed)
    X = np.tile(columns, (TESTS, 1))
    groups = np.repeat(np.arange(TESTS), SAMPLES)
    theta = np.arange(1.0, columns.shape[1] + 1.0)
    fitted, std = [], []
    for _ in range(DRAWS):
        amplitude = np.repeat(rng.normal(0.0, error_amplitude, TESTS), SAMPLES)
        y = X @ theta + amplitude * np.tile(np.cos(PHASE), TESTS) + rng.normal(0.0, 1.0, len(X))
        estimate = np.linalg.lstsq(X, y, rcond=None)[0]
        fitted.append(estimate)
        std.append(standard_errors(X, y - X @ estimate, groups, len(X) - X.shape[1]))
    return np.array(fitted) - theta, np.array(std)


def _spread(error_amplitude: float, columns: np.ndarray) -> np.ndarray:
    """The fitted parameters' true standard deviations: white noise gives (XᵀX)⁻¹; the model error,
    shared by a test's samples, (XᵀX)⁻¹ Xᵀ cos, once per test."""
    inverse = np.linalg.inv(columns.T @ columns)
    per_test = inverse @ columns.T @ np.cos(PHASE)
    return np.sqrt(np.diag(inverse) / TESTS + error_amplitude ** 2 * per_test ** 2 / TESTS)


@pytest.mark.parametrize("error_amplitude", [0.0, 0.5])
@pytest.mark.parametrize("p", [1, 2])
def test_the_uncertainty_is_the_spread_of_the_fits_over_draws(error_amplitude, p):
    columns = COLUMNS[:, :p] if p == 2 else COLUMNS[:, 1:]
    deviation, std = _fits(error_amplitude, columns)
    spread = _spread(error_amplitude, columns)
    assert np.std(deviation, axis=0) == pytest.approx(spread, rel=0.12)
    assert np.mean(std, axis=0) == pytest.approx(spread, rel=0.15)
    # 4 standard errors hold the truth in (nearly) every draw
    assert np.mean(np.abs(deviation) <= 4.0 * std) >= 0.99


def test_a_model_error_repeating_in_each_test_is_invisible_to_the_sample_count():
    """The cluster-robust term is what sees it: from the residuals alone (no lag-1 correlation),
    the linearised error stays at white noise's."""
    columns = COLUMNS[:, 1:]
    deviation, std = _fits(0.5, columns)
    white = _spread(0.0, columns)
    assert np.std(deviation) > 4.0 * white[0] and np.mean(std) > 4.0 * white[0]
    rng = np.random.default_rng(3)
    X = np.tile(columns, (TESTS, 1))
    r = rng.normal(size=len(X))   # the same residual with no test of its own: one group
    assert standard_errors(X, r, np.zeros(len(X)), len(X) - 1)[0] == pytest.approx(white[0], rel=0.1)


def test_a_parameter_the_residuals_do_not_see_is_unbounded():
    rng = np.random.default_rng(1)
    J = np.column_stack([rng.normal(size=200), np.zeros(200)])
    std = standard_errors(J, rng.normal(size=200), np.repeat(np.arange(4), 50), 198)
    assert np.isfinite(std[0]) and std[0] > 0.0 and np.isinf(std[1])
