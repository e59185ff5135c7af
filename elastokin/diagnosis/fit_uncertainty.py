"""Standard uncertainties of a least-squares fit whose residuals are not white noise.

A model error left by a fit (a baseline law integrated at the rig's samples where the part is
continuous, a form the family approximates) is correlated along a test and repeats cycle after
cycle, so the samples of one test are not independent: the textbook covariance s²(JᵀJ)⁻¹ then
claims a precision the data do not have (a kink's width 0.19 ± 0.012 mm where 0.40 was hidden).
The tests of a campaign are the independent units: the cluster-robust ("sandwich") covariance with
one cluster per test (Liang & Zeger 1986; the CR1 small-sample factor G/(G − 1)) measures how much
they disagree, whatever the correlation within each.
"""

from __future__ import annotations

import numpy as np


def standard_errors(J: np.ndarray, r: np.ndarray, groups: np.ndarray, dof: int,
                    noise: np.ndarray | None = None) -> np.ndarray:
    """Standard uncertainties (p,) of the parameters of a least-squares fit at its optimum: J (n, p)
    the residuals' Jacobian, r (n,) the residuals, ``groups`` (n,) the independent unit (test) each
    residual belongs to, ``dof`` the fit's degrees of freedom: :func:`clustered_errors` of JᵀJ and
    each unit's scores (and ``noise``, JᵀΣJ for a model of the noise, if given)."""
    units = np.unique(groups)
    return clustered_errors(J.T @ J, np.array([J[groups == g].T @ r[groups == g] for g in units]), r, dof, noise)


def clustered_errors(gram: np.ndarray, scores: np.ndarray, r: np.ndarray, dof: int,
                     noise: np.ndarray | None = None) -> np.ndarray:
    """Standard uncertainties (p,) of the parameters of a least-squares fit at its optimum, from the
    Jacobian's Gram matrix JᵀJ (p, p), each independent unit's scores J_gᵀ r_g (G, p), the residuals
    r (n,) in the order their correlation runs and ``dof`` the fit's degrees of freedom. The largest of
    the linearised error (its residual variance inflated for the residuals' sample-to-sample
    correlation ρ: n samples are worth n(1 − ρ)/(1 + ρ)), the cluster-robust one (module
    docstring) and, given ``noise`` = JᵀΣJ (p, p) for a model Σ of the noise's covariance, the error
    that noise gives (JᵀJ)⁻¹JᵀΣJ(JᵀJ)⁻¹ (a slow noise, which one ρ of all the residuals undercounts).
    A parameter the residuals do not depend on (a null column of J) has an unbounded uncertainty, the
    others taken from the rest of J; all are unbounded when the rest cannot be inverted."""
    rho = float(np.clip(np.dot(r[1:], r[:-1]) / max(np.dot(r, r), 1e-300), 0.0, 0.999))
    s2 = float(np.dot(r, r)) / max(dof, 1) * (1.0 + rho) / (1.0 - rho)
    norms = np.sqrt(np.clip(np.diag(gram), 0.0, None))
    seen = norms > 1e-9 * max(float(np.sqrt(max(np.trace(gram), 0.0))), 1e-300)
    std = np.full(len(gram), np.inf)
    try:
        bread = np.linalg.inv(gram[np.ix_(seen, seen)])
    except np.linalg.LinAlgError:
        return std
    scores = scores[:, seen]
    # centred: at a bound, or where the fit stopped short, the scores do not sum to zero, and what
    # they share is no disagreement between the tests
    scores = scores - scores.mean(axis=0)
    factor = len(scores) / (len(scores) - 1) if len(scores) > 1 else 1.0
    robust = np.diag(bread @ (scores.T @ scores) @ bread) * factor
    modelled = np.diag(bread @ noise[np.ix_(seen, seen)] @ bread) if noise is not None else 0.0
    std[seen] = np.sqrt(np.clip(np.maximum(np.maximum(np.diag(bread) * s2, robust), modelled), 0.0, None))
    return std
