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
import numpy as np

from elastokin.bushings.parameters import MAX_CELLS

# Columns of the float parameter matrix P (one row per channel, SI).
P_K0, P_C, P_NSUP, P_NINF, P_SSUP, P_SINF, P_PSUP, P_PINF, P_KPA, P_KR, P_FF, P_CO, P_PW, P_CT, P_NROOT, \
    P_EPS, P_TOL = range(17)
N_PCOLS = 17
# Columns of the int parameter matrix I.
I_KIND, I_NCELL, I_MX_N, I_MX_OFF, I_LADDER, I_CV_N, I_CV_OFF = range(7)
N_ICOLS = 7
KIND_LADDER, KIND_CONTINUOUS = 0, 1
#: Turning points kept per continuous-STS channel (nested minor loops beyond this are merged).
STACK_SIZE = 64
# Elastic law: beyond this fraction of the way to the saturation asymptote, extend tangentially
# so that an overshoot in a simulation gives a large finite force instead of an infinite one.
_THETA_MAX = 0.49 * math.pi
_MAX_NEWTON = 80
#: Tolerance [m or rad] of the sliders' release, and of a Coulomb ladder's whole solve (round-off).
STICK_TOLERANCE = 1e-13
#: Relative Newton step above which a growing node takes the power-law step of _grow.
_R_GROW = 0.02
#: Relative predictor step up to which a node gets the second-order correction of the predictor.
_R_CORRECT = 3.0
#: Growth ratio beyond which _grow steps a node from the cap directly (r·w would overflow).
_R_HUGE = 1e12
#: Least slip [m or rad] the power law's slope pw·f/|w| is taken at: below it (a node released by
#: a subnormal amount when pw is small) the slope would overflow to inf.
_W_FLOOR = 1e-250
# Fast-math without 'nnan'/'ninf', so the solver's NaN checks keep working.
_FAST = {"nsz", "arcp", "contract", "afn", "reassoc"}
# Rows of a channel's ladder array, its state and the solver's work rows side by side, so that a
# step copies nothing in or out: left spring stiffness of each node (a row rather than a test on
# the node index, which would make LLVM peel the loops instead of vectorising them), node slips w
# (the last step's on entry), slip directions (±1, 0 = stuck), power-law forces and slopes (the
# last step's on entry, on slipping nodes), residuals / Newton steps, zero-slip imbalances a0,
# relative Newton steps, for the solve: diagonal mantissas and powers of 2 (see _scale_diagonal),
# back-substitution factors (see _solve_active); and the node positions u (column 0: the input e).
#
# The rows lie _ST apart in one flat array (channels side by side, see place_ladders), as offsets
# added to the node index. A stride known at compile time lets LLVM prove that the rows never
# overlap (with the runtime stride of a 2-D array it tested every pair of rows before each vector
# loop); at least 256 elements keeps its store-to-load-forwarding heuristic from narrowing the
# vectors for the j ± 1 neighbour reads.
_NROWS = 12
_ST = 260  # ≥ 256, and ≥ MAX_CELLS padded to a multiple of 4, plus the input and ground columns
_KL, _W, _SG, _PSI, _DFL, _RHS, _A0, _RR, _AP, _SC, _DP, _U = range(0, _NROWS * _ST, _ST)
# ln 2 split so that k·_LN2_HI is exact for |k| < 2^20.
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10


def place_ladders(cells: np.ndarray) -> tuple[np.ndarray, int]:
    """Where each channel's ladder of cells[c] nodes starts in the bank's ladder array, and that
    array's length. The ladders lie side by side in blocks of _NROWS rows of _ST columns (channel
    c's row r at offset + r·_ST), each _width wide, so that a bank's ladders share pages and cache
    lines instead of taking 25 KB each."""
    n_max = int(np.max(cells, initial=0))
    if n_max > MAX_CELLS:
        raise ValueError(f"ladder models take at most {MAX_CELLS} cells, got {n_max}")
    offsets = np.zeros(len(cells), dtype=np.int64)
    block, used = 0, 0
    for c, n in enumerate(cells):
        width = _width(int(n))
        if used + width > _ST:
            block, used = block + 1, 0
        offsets[c] = block * _NROWS * _ST + used
        used += width
    return offsets, (block + 1) * _NROWS * _ST


def _width(n: int) -> int:
    """Columns of a ladder of n nodes: the input column, the nodes padded to a multiple of 4 (see
    _ladder_step) and the ground column, rounded up to a multiple of 4."""
    return 0 if n == 0 else ((n + 3) // 4 * 4 + 2 + 3) // 4 * 4


assert _width(MAX_CELLS) <= _ST, "a row must hold the longest ladder"


def reset_ladders(L: np.ndarray, P: np.ndarray, I: np.ndarray) -> None:
    """Unload the ladders of a bank with parameters P, I in its ladder array L (see place_ladders):
    node i in column i + 1 of each row, padding nodes with no spring to their left (never loaded)."""
    L[:] = 0.0
    for c in range(len(P)):
        n, o = I[c, I_NCELL], I[c, I_LADDER]
        if n > 0:
            L[o + _KL + 1] = P[c, P_KPA]
            L[o + _KL + 2:o + _KL + n + 1] = P[c, P_KR]
            L[o + _SC:o + _SC + _width(n)] = 1.0


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


@nb.njit(cache=True, inline="always", fastmath=_FAST, error_model="numpy")
def _pow(x, p):
    """x**p for x > 0 and 0 ≤ p ≤ 1 (not below e^-708), relative error < 3e-10 + 7.2e-10·p +
    2e-16·p·|ln x|.

    Branch-free exp(p·ln x) from the bits of x (no libm call), so that LLVM vectorises the node
    loop that calls it: the power law's exp and log calls were most of the solver's cost. The
    series stop at 1e-9 rather than at round-off: each term kept is an operation on every node in
    every pass, and a power-law force of 100 N then errs by 1e-7 N, far below the solver's force
    tolerance (tolerance·(Kpa + 2·Kr): 0.07 N for fig5_9_caption at the bank's default tolerance).
    """
    tiny = x < 2.0 ** -900
    x = x * 2.0 ** 200 if tiny else x
    # x = 2^k·m with m in [√½, √2): k from the exponent bits, as an exact double.
    b = np.float64(x).view(np.int64)
    k = (b - 0x3FE6A09E667F3BCD) >> 52
    m = np.int64(b - (k << 52)).view(np.float64)
    kd = float(np.int32(k)) - (200.0 if tiny else 0.0)
    # log m = 2·atanh(s), s = (m − 1)/(m + 1), |s| ≤ 0.172: series to s^9 (the rest < 7.2e-10).
    s = (m - 1.0) / (m + 1.0)
    s2 = s * s
    s4 = s2 * s2
    q = (1.0 / 3.0 + s2 * (1.0 / 5.0)) + s4 * (1.0 / 7.0 + s2 * (1.0 / 9.0))
    y = max(p * (kd * _LN2_HI + (kd * _LN2_LO + (2.0 * s + 2.0 * s * s2 * q))), -708.0)
    # exp y = 2^j·e^r, |r| ≤ ½·ln 2: Taylor to r^8 (the rest < 3e-10 of e^r); 2^j from its bits.
    j = np.floor(y * (1.0 / _LN2_HI) + 0.5)
    r = (y - j * _LN2_HI) - j * _LN2_LO
    r2 = r * r
    e = (1.0 + r) + r2 * ((1.0 / 2.0 + r * (1.0 / 6.0)) + r2 * ((1.0 / 24.0 + r * (1.0 / 120.0)) + r2 * (
        (1.0 / 720.0 + r * (1.0 / 5040.0)) + r2 * (1.0 / 40320.0))))
    return e * np.int64(np.float64(j + 6755399441056767.0).view(np.int64) << 52).view(np.float64)


@nb.njit(cache=True, fastmath=_FAST)
def _release(a, ks, h, Ff, Co, pw):
    """Slip magnitude of one node with its neighbours held: |a| − ks·w = Ff + Co(w/h)^pw.

    ``a`` is the node's spring imbalance at zero slip (|a| > Ff). Newton in log w from the smaller
    of the springs-only and damper-only slips, which lies above the root: the residual is concave
    in log w, so the iterates fall monotonically onto the root (Newton in w from below climbs the
    power law slowly: ~7 iterations against ~2).
    """
    excess = abs(a) - Ff
    ws = excess / ks
    if Co == 0.0:
        return ws
    if pw == 1.0:
        return excess / (ks + Co / h)
    ls = math.log(ws / h)
    lp = math.log(excess / Co) / pw
    if ls < lp:
        w = ws
        f = Co * math.exp(pw * ls)  # damper force at w
    else:
        w = h * math.exp(lp)  # 0 if below float range: the node stays stuck
        f = excess
    for _ in range(60):
        dy = (excess - ks * w - f) / (ks * w + pw * f)
        w *= math.exp(dy)
        f *= math.exp(pw * dy)
        if abs(dy) <= 1e-12:
            break
    return w


@nb.njit(cache=True, inline="always", fastmath=_FAST, error_model="numpy")
def _scale_diagonal(m, S, Kr):
    """Diagonal of K + diag S[_DFL] over Kr (≥ 1), split exactly as S[_AP]·2^e, S[_AP] in [1, 2),
    S[_SC] = 2^-e, on nodes 1..m (K: the ladder stiffness, diagonal k_left + Kr)."""
    for j in range(1, m + 1):
        b = np.float64((S[_KL + j] + Kr + S[_DFL + j]) / Kr).view(np.int64)
        S[_AP + j] = np.int64((b & 0x000FFFFFFFFFFFFF) | 0x3FF0000000000000).view(np.float64)
        S[_SC + j] = np.int64(0x7FE0000000000000 - (b & 0x7FF0000000000000)).view(np.float64)


@nb.njit(cache=True, inline="always", fastmath=_FAST, error_model="numpy")
def _solve_active(n, m, S, Kr):
    """Solve (K + diag S[_DFL]) x = S[_RHS] in place on the slipping nodes; x = 0 on stuck nodes.

    S[_RHS] must be 0 on stuck nodes. Thomas algorithm with its pivots taken as ratios of successive
    leading minors of each block of slipping nodes: the minors' recurrence chains only multiply-adds,
    and the divisions, off the chain, overlap (a chain of divisions was most of the solve's time).
    The minors are scaled by Kr and by the diagonal's powers of 2, which bounds them within
    [~4^-n, 2^n] whatever the slopes. The forward sweep leaves x_j = S[_DP]·x_{j+1} + S[_RHS] (Kr
    times the reciprocal pivot, and the eliminated right-hand side over the pivot; 0 on stuck nodes,
    which decouples their neighbours), so the back substitution's chain is one multiply-add per node.
    """
    _scale_diagonal(m, S, Kr)
    kri = 1.0 / Kr
    # Recurrences carried in locals, not re-read from S.
    d2, d1 = 0.0, 1.0  # minors before node j; (0, 1) starts a block
    sc = 1.0  # S[_SC + j - 1]
    q = 0.0  # reciprocal pivot of node j - 1
    y = 0.0  # eliminated right-hand side of node j - 1
    for j in range(1, n + 1):
        if S[_SG + j] == 0.0:
            S[_DP + j] = 0.0
            d2, d1 = 0.0, 1.0
            q = 0.0
            continue
        scj = S[_SC + j]
        d = S[_AP + j] * d1 - (scj * sc) * d2
        y = S[_RHS + j] + Kr * q * y
        q = d1 / d * (scj * kri)
        S[_DP + j] = Kr * q
        S[_RHS + j] = q * y
        d2, d1 = d1, d
        sc = scj
    x = 0.0
    for j in range(n, 0, -1):
        x = S[_DP + j] * x + S[_RHS + j]
        S[_RHS + j] = x


@nb.njit(cache=True, inline="always", fastmath=_FAST, error_model="numpy")
def _grow(n, S, Kr, pw):
    """Step the slipping nodes whose Newton step r·w (r = S[_RR] ≥ _R_GROW) grows them much
    (S[_W] = w on entry).

    Newton climbs the concave power law from below, monotonically but slowly: a node that speeds up
    tenfold in a step took several passes. Where the power law dominates the node's stiffness
    (weight theta), step instead to where the power law alone gives the force increase Newton asks
    of it, w·(1 + pw·r)^(1/pw); blend with Newton's step by theta, and cap at the step the node's
    springs alone would take (its damper force can only grow).
    """
    for j in range(1, n + 1):
        r = S[_RR + j]
        if S[_SG + j] == 0.0 or r < _R_GROW:
            continue
        dfl = S[_DFL + j]
        ks = S[_KL + j] + Kr
        theta = dfl / (ks + dfl)
        if r > _R_HUGE:
            # a node slipping a round-off amount (even a subnormal one): r, r·w and (1 + pw·r)^(1/pw)
            # may overflow. The same step from Newton's d = r·w, in logarithms: log r from d and w,
            # and (1 + pw·r)^(1/pw) / r = pw^(1/pw)·r^(1/pw − 1) (pw·r ≫ 1; the −1 of g is below round-off)
            w, d = S[_W + j], S[_RHS + j]
            log_r = math.log(abs(d)) - math.log(max(abs(w), 5e-324))
            growth = (1.0 - theta) + theta * math.exp(min(math.log(pw) / pw + (1.0 / pw - 1.0) * log_r, 700.0))
            S[_W + j] = w + d * min(growth, (ks + dfl) / ks)
            continue
        g = (1.0 - theta) * r + theta * (math.exp(math.log1p(pw * r) / pw) - 1.0)
        S[_W + j] *= 1.0 + min(g, r * (ks + dfl) / ks)


@nb.njit(cache=True, fastmath=_FAST, error_model="numpy")
def _ladder_step(e, de, h, n, Kpa, Kr, Ff, Co, pw, tol_x, S):
    """Advance one ladder of n nodes to deflection e; returns (F_ladder, dF/de, energy dissipated,
    residual): ``residual`` 0 when the solve converged, else the nodes' worst force residual over
    Kpa + 2·Kr [m or rad] (NaN for a residual that is not a number; see :func:`_ladder_residual`).

    Converged when every node's force residual is below tol_x·(Kpa + 2·Kr), i.e. the nodes are
    placed to about tol_x [m or rad]. ``S`` starts at the channel's ladder (see :func:`place_ladders`);
    node i is column i + 1, and columns 0 and n + 1 onwards hold the boundaries (input, ground), so
    the node loops need no branches and, run to a multiple of 4 nodes, vectorise whole. The rows
    carried from step to step are _KL, _W, _SG, _U and _DFL (the predictor reads the last slopes;
    on stuck nodes they are junk, which the solve never uses); the others are written before they
    are read, except the boundary columns, which stay 0 (1 for _SC; column 0 of _U takes e).
    Stuck and padding nodes have w = 0.
    """
    # Sliders are released at their threshold to round-off, whatever tol_x: the stick–slip pattern
    # is exact, and a Coulomb ladder (one linear solve per active set) is solved to round-off.
    tol_stick = STICK_TOLERANCE * (Kpa + 2.0 * Kr)
    tol = tol_x * (Kpa + 2.0 * Kr) if Co > 0.0 else tol_stick
    m = (n + 3) // 4 * 4
    S[_U + 0] = e  # the input: column 0 of the positions u_old + w (w = 0 there)
    # Predictor: one Newton step from the last increment with the last converged slopes (no
    # transcendental calls): the residual of the last step's slips w_prev (row _W on entry) at the new
    # step is Kpa·Δe·δ_i1 − (K·w_prev)_i.
    nprev = 0
    for j in range(1, m + 1):
        nprev += 0 if S[_SG + j] == 0.0 else 1
    if nprev > 0:  # else every node stuck: the step would move none
        for j in range(1, m + 1):
            r = -((S[_KL + j] + Kr) * S[_W + j] - Kr * S[_W + j - 1] - Kr * S[_W + j + 1])
            S[_RHS + j] = r if S[_SG + j] != 0.0 else 0.0
        S[_RHS + 1] += Kpa * de if S[_SG + 1] != 0.0 else 0.0
        _solve_active(n, m, S, Kr)
        # Newton's step d leaves each node the residual −½·g''·d² = ½(1 − pw)·g'·d²/w of its concave
        # power law g (g'' = (pw − 1)·g'/w): add the node's own correction for it, that residual
        # over its stiffness k + g', where d is not much larger than w. On the benchmark, the steps
        # that need a third pass fall from 40 % to 25 %.
        for j in range(1, m + 1):
            w = S[_W + j]
            d = S[_RHS + j]
            dfl = S[_DFL + j]
            c = 0.5 * (1.0 - pw) * dfl * d * d / (w if w != 0.0 else 1.0) / (S[_KL + j] + Kr + dfl)
            wn = w + d + (c if abs(d) < _R_CORRECT * abs(w) else 0.0)
            S[_W + j] = wn if wn * S[_SG + j] > 0.0 else w
    ok = False
    for _ in range(_MAX_NEWTON):
        # Spring imbalance ΔF_i = k_left(u_{i-1} − u_i) − Kr(u_i − u_{i+1}) at u = u_old + w, the
        # power law Co·|w/h|^pw and its slope (junk where w = 0, never used), residuals of the
        # slipping nodes; a0 = ΔF + (k_left + Kr)·w: the imbalance the node would have if it did
        # not slip (ΔF itself on stuck nodes).
        nslip = 0  # slipping nodes whose residual is above tol (or NaN)
        nstuck = 0  # stuck nodes whose imbalance is above the slider threshold
        for j in range(1, m + 1):
            kl = S[_KL + j]
            pos = S[_U + j] + S[_W + j]
            df = kl * ((S[_U + j - 1] + S[_W + j - 1]) - pos) - Kr * (pos - (S[_U + j + 1] + S[_W + j + 1]))
            S[_A0 + j] = df + (kl + Kr) * S[_W + j]
            aw = max(abs(S[_W + j]), _W_FLOOR) if S[_W + j] != 0.0 else h
            f = Co * _pow(aw / h, pw) if Co > 0.0 else 0.0
            S[_PSI + j] = f
            S[_DFL + j] = pw * f / aw
            sg = S[_SG + j]
            r = df - sg * (Ff + f)
            S[_RHS + j] = r if sg != 0.0 else 0.0
            nslip += 0 if sg == 0.0 or abs(r) <= tol else 1
            nstuck += 0 if sg != 0.0 or abs(df) <= Ff + tol_stick else 1  # padding: unloaded
        if nslip + nstuck == 0:
            ok = True
            break
        if nstuck > 0:
            # Start slipping the stuck nodes beyond threshold: one-node return map as first guess,
            # neighbours held, in node order, each seeing the slip just given to its left neighbour.
            nreleased = 0
            dwl = 0.0
            for j in range(1, n + 1):
                if S[_SG + j] != 0.0:
                    dwl = 0.0
                    continue
                df = S[_A0 + j] + Kr * dwl
                dwl = 0.0
                if abs(df) > Ff + tol_stick:
                    sg = 1.0 if df > 0.0 else -1.0
                    wr = sg * _release(df, S[_KL + j] + Kr, h, Ff, Co, pw)
                    if wr != 0.0:  # else: slip below float range, the node is stuck for all purposes
                        S[_W + j] = wr
                        S[_SG + j] = sg
                        nreleased += 1
                        dwl = wr
            if nreleased > 0:
                continue  # re-evaluate residuals with the released nodes' first guesses
        # Newton: (K + diag ψ') δ = R on slipping nodes, stuck nodes fixed.
        _solve_active(n, m, S, Kr)
        if Co == 0.0:
            # Coulomb ladder: a linear complementarity problem; a node that would reverse, or stop
            # to within the solve's round-off, sticks and is re-checked (and released if it must)
            # at the next pass. (Left slipping at a round-off speed, it would creep.)
            for j in range(1, m + 1):
                w = S[_W + j]
                r = S[_RHS + j] / (w if w != 0.0 else 1.0)
                S[_W + j] = w + S[_RHS + j] if r > -1.0 + 1e-10 else 0.0
                S[_SG + j] = S[_SG + j] if r > -1.0 + 1e-10 else 0.0
            continue
        nfix = 0
        for j in range(1, m + 1):
            w = S[_W + j]
            d = S[_RHS + j]
            r = d / (w if w != 0.0 else 1.0)
            S[_RR + j] = r
            # Growing: Newton's step, or _grow's if large. Shrinking: where the power law dominates
            # the node's stiffness (weight theta), step towards log|w| (w·e^r, here its Padé
            # form), which does not overshoot towards zero as the linear step (w·(1 + r)) does.
            theta = S[_DFL + j] / (S[_KL + j] + Kr + S[_DFL + j])
            wp = w * (1.0 + r * (1.0 - 0.5 * theta)) / (1.0 - 0.5 * theta * r)
            S[_W + j] = (w + d if r < _R_GROW else w) if r >= 0.0 else wp
            nfix += 1 if r >= _R_GROW or r <= -0.9 else 0  # one counter: with two, no vectorising
        if nfix == 0:
            continue
        _grow(n, S, Kr, pw)
        # Newton would reverse these nodes or overshoot towards zero on the concave power law:
        # replace their step by the one-node return map with the neighbours held, which sticks
        # the node, restarts it in the other direction, or gives a slip inside the bracket.
        for j in range(1, n + 1):
            if S[_SG + j] == 0.0 or S[_RR + j] > -0.9:
                continue
            a0 = S[_A0 + j]
            S[_W + j] = 0.0
            S[_SG + j] = 0.0
            if abs(a0) > Ff + tol_stick:
                sg = 1.0 if a0 > 0.0 else -1.0
                wr = sg * _release(a0, S[_KL + j] + Kr, h, Ff, Co, pw)
                if wr != 0.0:
                    S[_W + j] = wr
                    S[_SG + j] = sg
    # the iteration cap reached: the residual of the slips the last pass left (its Newton step unchecked)
    residual = 0.0 if ok else _ladder_residual(n, h, Kr, Ff, Co, pw, tol, tol_stick, S) / (Kpa + 2.0 * Kr)
    # Consistent tangent: du_1/de = Kpa·[A⁻¹]_11 on the final slipping set, with the damper
    # slopes of the converged pass. Only the run of slipping nodes from node 1 couples to the input.
    diss = 0.0
    for j in range(1, m + 1):
        diss += (Ff + S[_PSI + j]) * abs(S[_W + j])  # stuck and padding nodes: w = 0
    for j in range(1, m + 1):
        S[_U + j] += S[_W + j]
    du1 = 0.0
    if S[_SG + 1] != 0.0:
        b = 1
        while b < n and S[_SG + b + 1] != 0.0:
            b += 1
        # [A⁻¹]_11 = (minor of nodes 2..b)/(minor of nodes 1..b), the minors from the bottom up,
        # scaled as in _solve_active.
        _scale_diagonal(m, S, Kr)
        d2, d1 = 0.0, 1.0
        for j in range(b, 0, -1):
            d2, d1 = d1, S[_AP + j] * d1 - (S[_SC + j] * S[_SC + j + 1]) * d2
        du1 = Kpa * d2 / d1 * (S[_SC + 1] / Kr)
    return Kpa * (e - S[_U + 1]), Kpa * (1.0 - du1), diss, residual


@nb.njit(cache=True, fastmath=_FAST)
def _ladder_residual(n, h, Kr, Ff, Co, pw, tol, tol_stick, S):
    """The worst force residual [N or N·m] of a ladder's nodes at the slips S[_W], as the solve's
    passes test them: a slipping node's imbalance beyond its slider and power law (above ``tol``),
    a stuck node's beyond its threshold (above ``tol_stick``); 0 if none, NaN if one is not a number.
    Called only when the solve stops at its iteration cap, so that the loop it mirrors stays lean."""
    worst = 0.0
    for j in range(1, n + 1):
        pos = S[_U + j] + S[_W + j]
        df = S[_KL + j] * ((S[_U + j - 1] + S[_W + j - 1]) - pos) - Kr * (pos - (S[_U + j + 1] + S[_W + j + 1]))
        sg = S[_SG + j]
        if sg != 0.0:
            aw = max(abs(S[_W + j]), _W_FLOOR) if S[_W + j] != 0.0 else h
            r = abs(df - sg * (Ff + (Co * _pow(aw / h, pw) if Co > 0.0 else 0.0)))
            bad = not r <= tol
        else:
            r = abs(df) - Ff
            bad = not r <= tol_stick
        if bad and worst == worst and (r != r or r > worst):   # a NaN, once found, is kept
            worst = r
    return worst


@nb.njit(cache=True, inline="always", fastmath=_FAST)
def _sts_shape(s, Ct, nroot, A, B):
    """First-loading hysteretic force H0(s) = (Ct(s + A))^(1/n) − B for s ≥ 0, and its slope."""
    v = (Ct * (s + A)) ** (1.0 / nroot)
    return v - B, v / (nroot * (s + A))


@nb.njit(cache=True, inline="always", fastmath=_FAST)
def _curve(x, CV, o, n):
    """A tabulated elastic law and its slope at deflection x: the cubic Hermite through the nodes
    ``CV[o:o + n] = (x_i, F_i, dF/dx_i)`` (monotone when the slopes are PCHIP's), straight on with
    the end slopes beyond the first and last node."""
    if x <= CV[o, 0]:
        return CV[o, 1] + CV[o, 2] * (x - CV[o, 0]), CV[o, 2]
    last = o + n - 1
    if x >= CV[last, 0]:
        return CV[last, 1] + CV[last, 2] * (x - CV[last, 0]), CV[last, 2]
    lo, hi = o, last
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if CV[mid, 0] <= x:
            lo = mid
        else:
            hi = mid
    h = CV[hi, 0] - CV[lo, 0]
    t = (x - CV[lo, 0]) / h
    f0, s0, f1, s1 = CV[lo, 1], CV[lo, 2] * h, CV[hi, 1], CV[hi, 2] * h
    f = f0 + t * (s0 + t * (3.0 * (f1 - f0) - 2.0 * s0 - s1 + t * (2.0 * (f0 - f1) + s0 + s1)))
    k = (s0 + t * (6.0 * (f1 - f0) - 4.0 * s0 - 2.0 * s1 + t * (6.0 * (f0 - f1) + 3.0 * s0 + 3.0 * s1))) / h
    return f, k


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
def step_bank(e, h, P, I, MX, CV, L, q, eprev, cs, ck, stack, diss, nfail, worst, F, K):
    """Advance all channels of a bank by one step of h seconds to deflections e (in place).

    ``CV`` holds the nodes of the channels with a tabulated elastic law (:func:`_curve`), ``L`` the
    channels' ladders (:func:`place_ladders`); ``nfail`` counts each channel's steps
    whose solve did not converge, ``worst`` keeps their largest residual [m or rad] (NaN kept).
    """
    M = e.shape[0]
    for c in range(M):
        x = e[c]
        if I[c, I_CV_N] > 0:
            f, k = _curve(x, CV, I[c, I_CV_OFF], I[c, I_CV_N])
        else:
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
                fl, kl, dl, residual = _ladder_step(x, de, h, n, P[c, P_KPA], P[c, P_KR], P[c, P_FF], P[c, P_CO],
                                                    P[c, P_PW], P[c, P_TOL], L[I[c, I_LADDER]:])
                f += fl
                k += kl
                diss[c] += dl
                if residual != 0.0:
                    nfail[c] += 1
                    if worst[c] == worst[c] and (residual != residual or residual > worst[c]):
                        worst[c] = residual
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


# A bank's arrays are views of one float and one int buffer (pack_bank), so that a call from Python
# passes the kernel 4 arguments instead of 15: numba's dispatch unboxes each array argument, and the
# 15 cost about 0.6 µs more per call on the benchmark (25 µs). The int buffer opens with a header
# holding, for each array, its offset in its buffer and its shape (padded with 1s to _HEAD_DIMS).
#: step_bank's arrays in its argument order after (e, h): name, dtype, dimensions.
BANK_ARRAYS = (("P", np.float64, 2), ("I", np.int64, 2), ("MX", np.float64, 2), ("CV", np.float64, 2),
               ("ladder", np.float64, 1),
               ("q", np.float64, 1), ("eprev", np.float64, 1), ("cs", np.float64, 2), ("ck", np.int64, 1),
               ("stack", np.float64, 3), ("diss", np.float64, 1), ("nfail", np.int64, 1),
               ("worst", np.float64, 1), ("force", np.float64, 1), ("tangent", np.float64, 1))
_HEAD_DIMS = 3
_HEAD = len(BANK_ARRAYS) * (1 + _HEAD_DIMS)
_ALIGN = 8  # elements: every array starts a multiple of 64 bytes from its buffer's start


def pack_bank(shapes: dict[str, tuple[int, ...]]) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """Zeroed float and int buffers holding a bank's arrays of the given shapes (one per name of
    BANK_ARRAYS), and the arrays as views of them, for :func:`step_packed`."""
    ends = {np.float64: 0, np.int64: _HEAD}
    head = np.zeros(_HEAD, dtype=np.int64)
    places = {}
    for k, (name, dtype, ndim) in enumerate(BANK_ARRAYS):
        shape = tuple(shapes[name])
        if len(shape) != ndim:
            raise ValueError(f"bank array {name!r} must have {ndim} dimensions, got shape {shape}")
        start = -(-ends[dtype] // _ALIGN) * _ALIGN
        places[name] = (dtype, start, shape)
        ends[dtype] = start + math.prod(shape)
        head[k * (1 + _HEAD_DIMS):(k + 1) * (1 + _HEAD_DIMS)] = (start, *shape, *(1,) * (_HEAD_DIMS - ndim))
    buffers = {dtype: np.zeros(end, dtype=dtype) for dtype, end in ends.items()}
    buffers[np.int64][:_HEAD] = head
    views = {name: buffers[dtype][start:start + math.prod(shape)].reshape(shape)
             for name, (dtype, start, shape) in places.items()}
    return buffers[np.float64], buffers[np.int64], views


@nb.njit(cache=True, inline="always")
def _view1(buf, ib, k):
    o = ib[k * (1 + _HEAD_DIMS)]
    return buf[o:o + ib[k * (1 + _HEAD_DIMS) + 1]]


@nb.njit(cache=True, inline="always")
def _view2(buf, ib, k):
    o, n0, n1 = ib[k * (1 + _HEAD_DIMS)], ib[k * (1 + _HEAD_DIMS) + 1], ib[k * (1 + _HEAD_DIMS) + 2]
    return buf[o:o + n0 * n1].reshape((n0, n1))


@nb.njit(cache=True, inline="always")
def _view3(buf, ib, k):
    o, n0, n1, n2 = ib[k * (1 + _HEAD_DIMS)], ib[k * (1 + _HEAD_DIMS) + 1], ib[k * (1 + _HEAD_DIMS) + 2], \
        ib[k * (1 + _HEAD_DIMS) + 3]
    return buf[o:o + n0 * n1 * n2].reshape((n0, n1, n2))


@nb.njit(cache=True)
def step_packed(e, h, fb, ib):
    """:func:`step_bank` on a bank packed by :func:`pack_bank` (float buffer fb, int buffer ib)."""
    if e.shape[0] != ib[1]:  # P's rows: one per channel
        raise ValueError("deflections e must have one entry per channel of the bank")
    step_bank(e, h, _view2(fb, ib, 0), _view2(ib, ib, 1), _view2(fb, ib, 2), _view2(fb, ib, 3), _view1(fb, ib, 4),
              _view1(fb, ib, 5), _view1(fb, ib, 6), _view2(fb, ib, 7), _view1(ib, ib, 8), _view3(fb, ib, 9),
              _view1(fb, ib, 10), _view1(ib, ib, 11), _view1(fb, ib, 12), _view1(fb, ib, 13), _view1(fb, ib, 14))
