"""The fit uncertainty of the bench diagnosis against the spread of fits over many draws."""

import numpy as np
import pytest

from vsim_diagnosis.fit_uncertainty import standard_errors

TESTS, SAMPLES, DRAWS = 16, 400, 400


def _fits(error_amplitude: float, seed: int = 7) -> tuple[np.ndarray, np.ndarray]:
    """Fitted slopes and their standard errors over DRAWS campaigns of TESTS tests, y = θ·x + error:
    x a sine of 4 samples a period; the error a model error repeating cycle after cycle (a sine of
    the test's own random amplitude, 45° from x: no correlation from one sample to the next) and
    white noise of standard deviation 1."""
    rng = np.random.default_rng(seed)
    phase = 2.0 * np.pi * np.arange(SAMPLES) / 4.0
    x = np.tile(np.sin(phase), TESTS)
    groups = np.repeat(np.arange(TESTS), SAMPLES)
    fitted, std = [], []
    for _ in range(DRAWS):
        amplitude = np.repeat(rng.normal(0.0, error_amplitude, TESTS), SAMPLES)
        y = 2.0 * x + amplitude * np.tile(np.sin(phase + np.pi / 4.0), TESTS) + rng.normal(0.0, 1.0, len(x))
        theta = float(x @ y / (x @ x))
        r = y - theta * x
        fitted.append(theta)
        std.append(standard_errors(x[:, None], r, groups, len(x) - 1)[0])
    return np.array(fitted), np.array(std)


@pytest.mark.parametrize("error_amplitude", [0.0, 0.5])
def test_the_uncertainty_is_the_spread_of_the_fits_over_draws(error_amplitude):
    fitted, std = _fits(error_amplitude)
    # white noise alone: θ's spread is 1/|x| = 1/sqrt(TESTS·SAMPLES/2); a model error repeating in
    # each test adds a spread of its amplitude·cos 45°/sqrt(TESTS), which no per-sample count sees
    spread = np.sqrt(1.0 / (TESTS * SAMPLES / 2.0) + error_amplitude ** 2 / 2.0 / TESTS)
    assert np.std(fitted) == pytest.approx(spread, rel=0.1)
    assert np.mean(std) == pytest.approx(spread, rel=0.15)
    # 4 standard errors hold the truth in (nearly) every draw
    assert np.mean(np.abs(fitted - 2.0) <= 4.0 * std) >= 0.99


def test_a_model_error_repeating_in_each_test_is_invisible_to_the_linearised_error():
    fitted, std = _fits(0.5)
    x = np.sin(2.0 * np.pi * np.arange(SAMPLES) / 4.0)
    linearised = 1.0 / np.sqrt(TESTS * (x @ x))   # white noise of 1 with no lag-1 correlation
    assert np.std(fitted) > 4.0 * linearised
    assert np.mean(std) > 4.0 * linearised


def test_a_parameter_the_residuals_do_not_see_is_unbounded():
    rng = np.random.default_rng(1)
    J = np.column_stack([rng.normal(size=200), np.zeros(200)])
    std = standard_errors(J, rng.normal(size=200), np.repeat(np.arange(4), 50), 198)
    assert np.isfinite(std[0]) and std[0] > 0.0 and np.isinf(std[1])
