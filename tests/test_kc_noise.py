"""The K&C diagnosis's model of the measurement noise (elastokin/diagnosis/kc_noise.py): its
covariance products against their dense closed form."""

from __future__ import annotations

import numpy as np
import pytest

from elastokin.diagnosis.kc_noise import NoiseModel, Segment


@pytest.mark.parametrize("tau_s", [0.3, 40.0])
def test_the_covariance_product_is_the_dense_one_over_each_recording(tau_s):
    """JᵀΣJ for white noise plus an AR(1) noise of correlation time ``tau_s`` (short, and longer
    than the recordings), over two recordings of two tests each, sampled at 100 and 50 Hz, with a
    gap between the tests of a recording: the dense Σ_ij = w δ_ij + a exp(−|tᵢ − tⱼ| / τ) within a
    recording (none across), a the whole variance (the share of it a recording's zero leaves taken
    out), to rounding; listed in any order."""
    rng = np.random.default_rng(1)
    tests = [(0, 0.0, 0.01, 40), (0, 3.0, 0.02, 25), (1, 0.0, 0.02, 30), (1, 1.5, 0.01, 35)]   # recording, start [s], dt, rows
    segments, times, recordings, first = [], [], [], 0
    for k, start, dt, n in tests:
        segments.append(Segment(first, first + n, dt, start, k))
        times.append(start + dt * np.arange(n))
        recordings.append(np.full(n, k))
        first += n
    t, rec = np.concatenate(times), np.concatenate(recordings)
    white, coloured, left = 0.7, 1.3, 0.4
    model = NoiseModel(np.array([white]), np.array([coloured]), np.array([tau_s]), np.array([left]))
    columns = rng.normal(size=(3, len(t)))
    sigma2 = white ** 2 + coloured ** 2
    dense = (white ** 2 * np.eye(len(t)) + coloured ** 2 / left * np.exp(-np.abs(t[:, None] - t[None, :]) / tau_s)
             * (rec[:, None] == rec[None, :])) / sigma2
    expected = columns @ dense @ columns.T
    for order in (segments, segments[::-1]):
        assert np.allclose(model.covariance_product(columns, 0, order), expected, rtol=1e-10, atol=1e-10)
