"""Sobol' sensitivity indices of a metric from the runs of a Sobol' design (:mod:`elastokin.sweeps.designs`).

With f_A, f_B and f_ABi the metric on the rows of A, B and A_B^i (A with parameter i from B):

- first order (Saltelli et al. 2010, eq. (b) of table 2): S_i = mean(f_B · (f_ABi − f_A)) / V;
- total (Jansen 1999): S_Ti = mean((f_A − f_ABi)²) / (2 V);

with V the variance of f_A and f_B together. These are the estimators of ``scipy.stats.sobol_indices``
and of SALib; they are written here because a sweep's runs are already made, some may have failed
(their samples are left out of every index), and the table is the input. The Ishigami function's
analytic indices check them (tests/test_sweeps.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Indices:
    """Sobol' indices of one metric, one per parameter, and the samples they rest on."""

    first: np.ndarray        #: S_i
    total: np.ndarray        #: S_Ti
    samples: int             #: base samples with every run of theirs finished


def sobol_indices(values: np.ndarray, dimensions: int) -> Indices:
    """The indices of a metric whose ``values`` (one per run, NaN for a failed run) follow a Sobol'
    design of ``dimensions`` parameters (blocks A, B, A_B^1 … A_B^d of equal length)."""
    blocks = np.asarray(values, dtype=float).reshape(dimensions + 2, -1)
    whole = np.all(np.isfinite(blocks), axis=0)
    a, b, ab = blocks[0, whole], blocks[1, whole], blocks[2:, whole]
    if a.size < 2:
        nan = np.full(dimensions, np.nan)
        return Indices(nan, nan.copy(), int(a.size))
    variance = float(np.var(np.concatenate([a, b])))
    if variance == 0.0:
        zero = np.zeros(dimensions)
        return Indices(zero, zero.copy(), int(a.size))
    first = np.mean(b * (ab - a), axis=1) / variance
    total = 0.5 * np.mean((a - ab) ** 2, axis=1) / variance
    return Indices(first, total, int(a.size))
