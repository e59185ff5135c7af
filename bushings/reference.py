"""Independent reference integrator for verification only: explicit Euler on the inverted ladder law.

It integrates each node's velocity ``v_i = sign(ΔF_i)·((|ΔF_i| − Ff)/Co)^(1/pw)`` (zero below the
threshold) with adaptive sub-steps small enough for explicit stability, the way the thesis did
inside ADAMS. It shares no code with the implicit kernel, so agreement between the two is a real
check. It is slow and needs Co > 0 (RT, STVS); never use it in a simulation.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from elastokin.bushings.parameters import ChannelParams


@nb.njit(cache=True)
def _explicit(e, dt, n, K0, Kpa, Kr, Ff, Co, pw, safety, max_sub):
    u = np.zeros(n)
    v = np.zeros(n)
    F = np.empty(e.shape[0])
    F[0] = K0 * e[0] + Kpa * e[0]
    lam = max(Kpa + 2.0 * Kr, 4.0 * Kr)  # Gershgorin bound on the ladder stiffness eigenvalues
    inv = 1.0 / pw
    substeps = 0
    for k in range(1, e.shape[0]):
        t = 0.0
        while t < dt:
            x = e[k - 1] + (e[k] - e[k - 1]) * (t / dt)
            gmax = 0.0
            for i in range(n):
                left = x if i == 0 else u[i - 1]
                kl = Kpa if i == 0 else Kr
                right = 0.0 if i == n - 1 else u[i + 1]
                df = kl * (left - u[i]) - Kr * (u[i] - right)
                ex = abs(df) - Ff
                if ex > 0.0:
                    g = (ex / Co) ** inv
                    v[i] = g if df > 0.0 else -g
                    gmax = max(gmax, inv * g / ex)
                else:
                    v[i] = 0.0
            # Explicit stability: h·g'·λ < 2; the safety factor also sets the accuracy.
            hs = dt - t
            if gmax > 0.0:
                hs = min(hs, safety * 2.0 / (lam * gmax))
                hs = max(hs, dt / max_sub)
            for i in range(n):
                u[i] += hs * v[i]
            t += hs
            substeps += 1
        F[k] = K0 * e[k] + Kpa * (e[k] - u[0])
    return F, substeps


def explicit_reference(ch: ChannelParams, e_m: np.ndarray, dt_s: float, safety: float = 0.2,
                       max_substeps: int = 1_000_000) -> tuple[np.ndarray, int]:
    """Force history [N] of a linear-elastic RT/STVS channel for deflections ``e_m`` sampled every
    ``dt_s`` (linear in between), and the number of explicit sub-steps taken."""
    if ch.Co <= 0.0 or ch.n_cells == 0 or ch.continuous:
        raise ValueError("the explicit reference needs a ladder with a power-law damper (RT or STVS)")
    if math.isfinite(ch.N_sup) or ch.maxwell_k or ch.C:
        raise ValueError("the explicit reference covers linear elasticity without parallel dampers")
    F, n_sub = _explicit(np.asarray(e_m, dtype=float), float(dt_s), ch.n_cells, ch.K0, ch.Kpa, ch.Kr,
                         ch.Ff, ch.Co, ch.pw, safety, max_substeps)
    return F, int(n_sub)
