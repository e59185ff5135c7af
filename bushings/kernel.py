"""Compiled per-step kernel for a bank of bushing channels (SI units throughout).

One call advances every channel by one implicit (backward-Euler) step to the imposed deflection
``e`` and returns the force and its tangent dF/de. Channel families:

* ladder (linear, elastic, STS, RT, STVS, TVS): ``F = F_el(e) + C·ė + Kpa·(e − u_1) + Σ k_j·(e − q_j)``.
  The ladder step minimises the convex function
  ``½Kpa(e−u_1)² + ½Kr Σ(u_i−u_{i+1})² + ½Kr u_N² + Σ_i [Ff|w_i| + h·Co/(pw+1)·|w_i/h|^(pw+1)]``
  over the node increments ``w = u − u_old``. It is solved exactly in stick–slip by an active-set
  Newton method: stuck nodes are fixed (|imbalance| ≤ Ff), slipping nodes satisfy
  ``ΔF_i = sign(w_i)·(Ff + Co|w_i/h|^pw)``; each Newton step is one tridiagonal solve.
  Nodes that must start slipping get their first guess from a one-node return map.
  Maxwell branches are linear and integrated exactly by backward Euler.
* continuous STS (Coveney, and the n-th root STSn+): an algebraic law with a turning-point stack
  that enforces Masing's law and Madelung's rules (wipe-out of closed minor loops).
"""

from __future__ import annotations

import math

import numba as nb

# Columns of the float parameter matrix P (one row per channel, SI).
P_K0, P_C, P_NSUP, P_NINF, P_SSUP, P_SINF, P_PSUP, P_PINF, P_KPA, P_KR, P_FF, P_CO, P_PW, P_CT, P_NROOT, \
    P_EPS, P_TOL = range(17)
N_PCOLS = 17
# Columns of the int parameter matrix I.
I_KIND, I_NCELL, I_NODE_OFF, I_MX_N, I_MX_OFF = range(5)
N_ICOLS = 5
KIND_LADDER, KIND_CONTINUOUS = 0, 1
#: Turning points kept per continuous-STS channel (nested minor loops beyond this are merged).
STACK_SIZE = 64
# Elastic law: beyond this fraction of the way to the saturation asymptote, extend tangentially
# so that an overshoot in a simulation gives a large finite force instead of an infinite one.
_THETA_MAX = 0.49 * math.pi
_MAX_NEWTON = 80
# Fast-math without 'nnan'/'ninf', so the solver's NaN checks keep working.
_FAST = {"nsz", "arcp", "contract", "afn", "reassoc"}


@nb.njit(cache=True, inline="always", fastmath=_FAST)
def _elastic(x, K0, nsup, ninf, ssup, sinf, psup, pinf):
    """Nonlinear elastic force and tangent (spec eq. 3.10 corrected)."""
    if x > nsup:
        span = ssup - nsup
        th = (x - nsup) / span * (0.5 * math.pi)
        if th > _THETA_MAX:
            t = math.tan(_THETA_MAX)
            slope = psup * t * t * (0.5 * math.pi) / span
            return K0 * x + psup * (t - _THETA_MAX) + slope * (x - nsup - _THETA_MAX / (0.5 * math.pi) * span), K0 + slope
        t = math.tan(th)
        return K0 * x + psup * (t - th), K0 + psup * t * t * (0.5 * math.pi) / span
    if x < ninf:
        span = ninf - sinf
        th = (ninf - x) / span * (0.5 * math.pi)
        if th > _THETA_MAX:
            t = math.tan(_THETA_MAX)
            slope = pinf * t * t * (0.5 * math.pi) / span
            return K0 * x - pinf * (t - _THETA_MAX) + slope * (x - ninf + _THETA_MAX / (0.5 * math.pi) * span), K0 + slope
        t = math.tan(th)
        return K0 * x - pinf * (t - th), K0 + pinf * t * t * (0.5 * math.pi) / span
    return K0 * x, K0


@nb.njit(cache=True, inline="always", fastmath=_FAST)
def _damper(w, h, Ff, Co, pw):
    """Dissipative force magnitude Ff + Co·|w/h|^pw for |w| > 0 and its derivative d/d|w|."""
    aw = abs(w)
    if Co == 0.0:
        return Ff, 0.0
    f = Co * math.exp(pw * math.log(aw / h))  # cheaper than ** here (~14 ns against 20-30 ns)
    return Ff + f, pw * f / aw


@nb.njit(cache=True, fastmath=_FAST)
def _release(a, ks, h, Ff, Co, pw):
    """Slip magnitude of one node with its neighbours held: |a| − ks·w = Ff + Co(w/h)^pw.

    ``a`` is the node's spring imbalance at zero slip (|a| > Ff). The root is bracketed by
    (0, min((|a|−Ff)/ks, h((|a|−Ff)/Co)^(1/pw))); safeguarded Newton.
    """
    excess = abs(a) - Ff
    hi = excess / ks
    if Co == 0.0:
        return hi
    if pw == 1.0:
        return excess / (ks + Co / h)
    hi = min(hi, h * (excess / Co) ** (1.0 / pw))
    lo = 0.0
    w = 0.5 * hi
    for _ in range(60):
        d, dd = _damper(w, h, Ff, Co, pw)
        r = excess + Ff - ks * w - d  # decreasing in w
        if r > 0.0:
            lo = w
        else:
            hi = w
        step = r / (ks + dd)
        wn = w + step
        if wn <= lo or wn >= hi:
            wn = 0.5 * (lo + hi)
        if abs(wn - w) <= 1e-12 * wn:
            return wn
        w = wn
    return w


@nb.njit(cache=True, inline="always", fastmath=_FAST)
def _solve_active(n, st, Kpa, Kr, slope, rhs, cp, dp):
    """Solve (K + diag(slope)) x = rhs in place on the slipping nodes (st ≠ 0); stuck nodes get x = 0.

    K is the ladder stiffness (diagonal k_left + Kr, off-diagonal −Kr); Thomas algorithm.
    """
    for i in range(n):
        if st[i] == 0:
            diag = 1.0
            rhs[i] = 0.0
            lower = 0.0
        else:
            diag = (Kpa if i == 0 else Kr) + Kr + slope[i]
            lower = -Kr if (i > 0 and st[i - 1] != 0) else 0.0
        if i == 0:
            dp[i] = diag
        else:
            m = lower / dp[i - 1]
            dp[i] = diag - m * cp[i - 1]
            rhs[i] -= m * rhs[i - 1]
        if i < n - 1:  # the upper diagonal of row i is the lower diagonal of row i+1
            cp[i] = -Kr if (st[i] != 0 and st[i + 1] != 0) else 0.0
    for i in range(n - 1, -1, -1):
        nxt = rhs[i + 1] if i < n - 1 else 0.0
        rhs[i] = (rhs[i] - cp[i] * nxt) / dp[i]


@nb.njit(cache=True, fastmath=_FAST)
def _ladder_step(e, de, h, n, Kpa, Kr, Ff, Co, pw, tol_x, u, wprev, slope, w, st, dflat, rhs, cp, dp, a0, dval):
    """Advance one ladder of n nodes to deflection e; returns (F_ladder, dF/de, energy dissipated, ok).

    Converged when every node's force residual is below tol_x·(Kpa + 2·Kr), i.e. the nodes are
    placed to about tol_x [m or rad].
    """
    # Sliders are released at their threshold to round-off, whatever tol_x: the stick–slip pattern
    # is exact, and a Coulomb ladder (one linear solve per active set) is solved to round-off.
    tol_stick = 1e-13 * (Kpa + 2.0 * Kr)
    tol = tol_x * (Kpa + 2.0 * Kr) if Co > 0.0 else tol_stick
    # Predictor: one Newton step from the last increment with the last converged slopes (no
    # transcendental calls): the residual of w = wprev at the new step is Kpa·Δe·δ_i1 − (K·wprev)_i.
    for i in range(n):
        st[i] = 0 if wprev[i] == 0.0 else (1 if wprev[i] > 0.0 else -1)
        w[i] = wprev[i]
    for i in range(n):
        if st[i] != 0:
            kw = ((Kpa if i == 0 else Kr) + Kr) * wprev[i]
            if i > 0:
                kw -= Kr * wprev[i - 1]
            if i < n - 1:
                kw -= Kr * wprev[i + 1]
            rhs[i] = (Kpa * de if i == 0 else 0.0) - kw
    _solve_active(n, st, Kpa, Kr, slope, rhs, cp, dp)
    for i in range(n):
        if st[i] != 0 and (wprev[i] + rhs[i]) * st[i] > 0.0:
            w[i] = wprev[i] + rhs[i]
    ok = False
    for _ in range(_MAX_NEWTON):
        # Spring imbalance ΔF_i = k_left(u_{i-1} − u_i) − Kr(u_i − u_{i+1}) at u = u_old + w.
        done = True
        nreleased = 0
        for i in range(n):
            ui = u[i] + w[i]
            left = e if i == 0 else u[i - 1] + w[i - 1]
            kl = Kpa if i == 0 else Kr
            right = 0.0 if i == n - 1 else u[i + 1] + w[i + 1]
            df = kl * (left - ui) - Kr * (ui - right)
            a0[i] = df + (kl + Kr) * w[i]  # imbalance this node would have if it did not slip
            if st[i] == 0:
                rhs[i] = 0.0
                if abs(df) > Ff + tol_stick:
                    done = False
                    # Start slipping: one-node return map as first guess, neighbours held.
                    st[i] = 1 if df > 0.0 else -1
                    w[i] = st[i] * _release(df, kl + Kr, h, Ff, Co, pw)
                    if w[i] == 0.0:  # slip below float range: the node is stuck for all purposes
                        st[i] = 0
                    else:
                        nreleased += 1
            else:
                d, dd = _damper(w[i], h, Ff, Co, pw)
                rhs[i] = df - st[i] * d
                dflat[i] = dd
                dval[i] = d
                if not abs(rhs[i]) <= tol:  # also catches NaN
                    done = False
        if done:
            ok = True
            break
        if nreleased > 0:
            continue  # re-evaluate residuals with the released nodes' first guesses
        # Newton: (K + diag ψ') δ = R on slipping nodes, stuck nodes fixed.
        _solve_active(n, st, Kpa, Kr, dflat, rhs, cp, dp)
        for i in range(n):
            if st[i] == 0:
                continue
            r = rhs[i] / w[i]
            if Co == 0.0:
                # Coulomb ladder: a linear complementarity problem; a node that would reverse sticks
                # and is re-checked (and released if it must) at the next pass.
                if r > -1.0:
                    w[i] += rhs[i]
                else:
                    w[i] = 0.0
                    st[i] = 0
                continue
            if r >= 0.0:
                w[i] += rhs[i]  # growing: Newton approaches the root from below, monotonically
                continue
            if r > -0.9:
                # Shrinking: where the power law dominates the node's stiffness (weight theta),
                # step towards log|w| (w·e^r, here its Padé form), which does not overshoot
                # towards zero as the linear step (w·(1 + r)) does.
                theta = dflat[i] / ((Kpa if i == 0 else Kr) + Kr + dflat[i])
                w[i] *= (1.0 + r * (1.0 - 0.5 * theta)) / (1.0 - 0.5 * theta * r)
                continue
            # Newton would reverse the node or overshoot towards zero on the concave power law:
            # replace its step by the one-node return map with its neighbours held, which sticks
            # it, restarts it in the other direction, or gives a slip inside the bracket.
            ks = (Kpa if i == 0 else Kr) + Kr
            if abs(a0[i]) <= Ff + tol_stick:
                w[i] = 0.0
                st[i] = 0
            else:
                st[i] = 1 if a0[i] > 0.0 else -1
                w[i] = st[i] * _release(a0[i], ks, h, Ff, Co, pw)
                if w[i] == 0.0:
                    st[i] = 0
    # Consistent tangent: du_1/de = Kpa·[A⁻¹]_11 on the final slipping set, with the damper
    # slopes of the converged pass (the factorisation above predates the last update).
    diss = 0.0
    for i in range(n):
        if st[i] != 0:
            diss += dval[i] * abs(w[i])
        u[i] += w[i]
        wprev[i] = w[i]
        slope[i] = dflat[i] if st[i] != 0 else 0.0
    du1 = 0.0
    if st[0] != 0:
        for i in range(n):
            rhs[i] = 0.0
        rhs[0] = 1.0
        _solve_active(n, st, Kpa, Kr, dflat, rhs, cp, dp)
        du1 = Kpa * rhs[0]
    return Kpa * (e - u[0]), Kpa * (1.0 - du1), diss, ok


@nb.njit(cache=True, inline="always", fastmath=_FAST)
def _sts_shape(s, Ct, nroot, A, B):
    """First-loading hysteretic force H0(s) = (Ct(s + A))^(1/n) − B for s ≥ 0, and its slope."""
    v = (Ct * (s + A)) ** (1.0 / nroot)
    return v - B, v / (nroot * (s + A))


@nb.njit(cache=True, inline="always", fastmath=_FAST)
def _branch(x, xo, ho, d, virgin, Ct, nroot, A, B):
    """Hysteretic force on the branch leaving (xo, ho) in direction d (Masing: 2·H0(s/2)), or on the
    first-loading curve when ``virgin``."""
    if virgin:
        f, k = _sts_shape(abs(x), Ct, nroot, A, B)
        return (f if x >= 0.0 else -f), k
    s = d * (x - xo)
    if s < 0.0:
        s = 0.0
    f, k = _sts_shape(0.5 * s, Ct, nroot, A, B)
    return ho + d * 2.0 * f, k


@nb.njit(cache=True, fastmath=_FAST)
def _continuous_step(x, Kpa, Ct, nroot, eps, stack, cs, ck):
    """Continuous STS with turning-point memory; returns (H, dH/dx).

    ``stack[k] = (x_k, H_k)`` reversal points R_1..R_k; ``cs = (x_ext, d)``: furthest point reached
    on the current branch and its direction; ``ck[0] = k``. Reversals smaller than ``eps`` are
    evaluated on the tentative reversed branch but not stored (exact: such a loop closes on itself).
    """
    A = (nroot * Kpa / Ct ** (1.0 / nroot)) ** (nroot / (1.0 - nroot))
    B = (Ct * A) ** (1.0 / nroot)
    for _ in range(2 * STACK_SIZE + 4):
        k = ck[0]
        xext = cs[0]
        d = cs[1]
        if k == 0:
            # First-loading curve: the branch direction is away from the origin.
            if d == 0.0:
                if x == 0.0:
                    return 0.0, Kpa
                d = 1.0 if x > 0.0 else -1.0
                cs[1] = d
                cs[0] = 0.0
                xext = 0.0
            if d * (x - xext) >= 0.0:
                cs[0] = x
                return _branch(x, 0.0, 0.0, d, True, Ct, nroot, A, B)
            hext, _ = _branch(xext, 0.0, 0.0, d, True, Ct, nroot, A, B)
        else:
            xo = stack[k - 1, 0]
            ho = stack[k - 1, 1]
            if d * (x - xext) >= 0.0:
                # Forward on the branch: wipe out a closed minor loop when its bound is passed.
                bound = stack[k - 2, 0] if k >= 2 else -stack[0, 0]
                if d * (x - bound) >= 0.0:
                    ck[0] = k - 2 if k >= 2 else 0
                    cs[0] = bound  # the bound lies on the branch (or first-loading curve) resumed
                    continue
                cs[0] = x
                return _branch(x, xo, ho, d, False, Ct, nroot, A, B)
            hext, _ = _branch(xext, xo, ho, d, False, Ct, nroot, A, B)
        # Moving backwards from the extreme point xext.
        if d * (xext - x) <= eps:
            return _branch(x, xext, hext, -d, False, Ct, nroot, A, B)
        if k == STACK_SIZE:
            # Memory full: merge the innermost older pair so the current origin is kept.
            stack[k - 3, 0] = stack[k - 1, 0]
            stack[k - 3, 1] = stack[k - 1, 1]
            k -= 2
        stack[k, 0] = xext
        stack[k, 1] = hext
        ck[0] = k + 1
        cs[0] = xext
        cs[1] = -d
    return 0.0, Kpa  # unreachable: each pass above either returns or shrinks the stack


@nb.njit(cache=True, fastmath=_FAST)
def step_bank(e, h, P, I, MX, u, wprev, slope, q, eprev, cs, ck, stack, diss, nfail, F, K, work, iwork):
    """Advance all channels of a bank by one step of h seconds to deflections e (in place)."""
    M = e.shape[0]
    for c in range(M):
        x = e[c]
        f, k = _elastic(x, P[c, P_K0], P[c, P_NSUP], P[c, P_NINF], P[c, P_SSUP], P[c, P_SINF],
                        P[c, P_PSUP], P[c, P_PINF])
        cdamp = P[c, P_C]
        de = x - eprev[c]
        if cdamp > 0.0:
            f += cdamp * de / h
            k += cdamp / h
            diss[c] += cdamp * de * de / h
        if I[c, I_KIND] == KIND_LADDER:
            n = I[c, I_NCELL]
            if n > 0:
                o = I[c, I_NODE_OFF]
                fl, kl, dl, ok = _ladder_step(
                    x, de, h, n, P[c, P_KPA], P[c, P_KR], P[c, P_FF], P[c, P_CO], P[c, P_PW], P[c, P_TOL],
                    u[o:o + n], wprev[o:o + n], slope[o:o + n], work[0, :n], iwork[:n], work[1, :n],
                    work[2, :n], work[3, :n], work[4, :n], work[5, :n], work[6, :n])
                f += fl
                k += kl
                diss[c] += dl
                if not ok:
                    nfail[c] += 1
        else:
            fh, kh = _continuous_step(x, P[c, P_KPA], P[c, P_CT], P[c, P_NROOT], P[c, P_EPS],
                                      stack[c], cs[c], ck[c:c + 1])
            f += fh
            k += kh
        o = I[c, I_MX_OFF]
        for j in range(I[c, I_MX_N]):
            km = MX[o + j, 0]
            a = h * km / MX[o + j, 1]
            qn = (q[o + j] + a * x) / (1.0 + a)
            dq = qn - q[o + j]
            diss[c] += MX[o + j, 1] * dq * dq / h
            q[o + j] = qn
            f += km * (x - qn)
            k += km / (1.0 + a)
        eprev[c] = x
        F[c] = f
        K[c] = k
