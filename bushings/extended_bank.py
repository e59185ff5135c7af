"""A bank of bushing channels with their state extensions (:class:`elastokin.bushings.effects.Effects`), stepped
by one compiled call around the base kernel; and whole deflection histories run in one compiled call
(for fitting, where a history is replayed many times)."""

from __future__ import annotations

from typing import Sequence

import numba as nb
import numpy as np

from elastokin.bushings import kernel as kn
from elastokin.bushings.bank import DEFAULT_TOLERANCE, BushingBank
from elastokin.bushings.effects import NO_EFFECTS, Effects
from elastokin.bushings.parameters import LENGTH_UNIT_SI, ChannelParams
from elastokin.core.compiled_cache import follow

# Columns of the effect parameter matrix (one row per channel) and of the effect state.
(E_PRELOAD, E_ASYM, E_ASYM_POWER, E_ASYM_STEP, E_ASYM_STEP_WIDTH, E_MULLINS, E_MULLINS_SHAPE, E_HEAT, E_HEAT_TAU,
 E_SLIP, E_SLIP_K, E_BACKLASH, E_TARE) = range(13)
N_ECOLS = 13
S_XMAX, S_HEAT, S_DISS, S_SLIP_F, S_SLIP_X = range(5)
N_SCOLS = 5
#: Duration and steps of the quasi-static mounting ramp to the preload deflection.
MOUNT_S, MOUNT_STEPS = 10.0, 200


#: The files a function that steps the bank compiles into itself (see elastokin.core.compiled_cache).
KERNEL_FILES = (kn.__file__, __file__)
follow(__file__, *KERNEL_FILES)


@nb.njit(cache=True)
def _effects_in(e, EP, X):
    """Deflection seen by each base law: backlash dead band, then the preload shift."""
    for c in range(e.shape[0]):
        x = e[c]
        b = EP[c, E_BACKLASH]
        if b > 0.0:
            x = x - b if x > b else (x + b if x < -b else 0.0)
        X[c] = x + EP[c, E_PRELOAD]


@nb.njit(cache=True)
def _effects_out(h, e, X, EP, ES, P, diss, F, K, Fout, Kout):
    """Force and tangent of each channel with its effects, from the base law's (F, K) at X."""
    for c in range(X.shape[0]):
        x, f, k = X[c], F[c], K[c]
        a = EP[c, E_ASYM]   # per unit deflection to the power n (see ExtendedBank)
        if a != 0.0 and (x < 0.0) == (a > 0.0):
            n = EP[c, E_ASYM_POWER]
            extra = abs(a) * P[c, kn.P_K0] * abs(x) ** n
            f += extra * x / (n + 1.0)
            k += extra
        s = EP[c, E_ASYM_STEP]
        w = EP[c, E_ASYM_STEP_WIDTH]
        if s != 0.0 and w > 0.0:
            # the step's tangent rising linearly over w, centred on zero deflection: r = 1/2 + v/w
            # along u (towards the stiff side), F_asym = −s·K0·∫_0^u r (u − w/8 beyond, −w/8 before)
            u = -x if s > 0.0 else x
            v = min(max(u, -0.5 * w), 0.5 * w)
            k0 = P[c, kn.P_K0]
            f -= s * k0 * (0.5 * v + v * v / (2.0 * w) + max(u - 0.5 * w, 0.0))
            k += abs(s) * k0 * (0.5 + v / w)
        elif s != 0.0 and (x < 0.0) == (s > 0.0):
            k0 = P[c, kn.P_K0]
            f += abs(s) * k0 * x
            k += abs(s) * k0
        mu = EP[c, E_MULLINS]
        if mu > 0.0:
            virgin = abs(x) >= ES[c, S_XMAX]   # on the virgin curve x_max moves with x: η stays 1
            if virgin:
                ES[c, S_XMAX] = abs(x)
            xmax = ES[c, S_XMAX]
            if xmax > 0.0:
                p = EP[c, E_MULLINS_SHAPE]   # >= 1: the recovery's slope stays finite at x = 0
                r = abs(x) / xmax
                eta = 1.0 - mu * (1.0 - r ** p)
                slope = 0.0 if virgin else mu * p * r ** (p - 1.0) / xmax
                k = eta * k + f * slope * (1.0 if x >= 0.0 else -1.0)
                f *= eta
        kappa = EP[c, E_HEAT]
        if kappa > 0.0:
            # Heat held Q [J]: fed by the power dissipated in the step, lost with time constant tau.
            power = (diss[c] - ES[c, S_DISS]) / h
            ES[c, S_HEAT] = (ES[c, S_HEAT] + h * power) / (1.0 + h / EP[c, E_HEAT_TAU])
            eta = 1.0 / (1.0 + kappa * ES[c, S_HEAT])
            f *= eta
            k *= eta
        ES[c, S_DISS] = diss[c]
        fs = EP[c, E_SLIP]
        if fs > 0.0:
            # Jenkins element: its spring follows x until its force reaches ±fs, then it slips.
            ks = EP[c, E_SLIP_K] * P[c, kn.P_K0]
            trial = ES[c, S_SLIP_F] + ks * (x - ES[c, S_SLIP_X])
            ES[c, S_SLIP_X] = x
            ES[c, S_SLIP_F] = min(max(trial, -fs), fs)
            f += ES[c, S_SLIP_F]
            k += ks if abs(trial) <= fs else 0.0   # at the limit unloading sticks: the larger tangent
        b = EP[c, E_BACKLASH]
        if b > 0.0 and abs(e[c]) <= b:
            k = 0.0
        Fout[c] = f - EP[c, E_TARE]
        Kout[c] = k


@nb.njit(cache=True)
def step_extended(e, h, EP, ES, X, Fout, Kout, P, I, MX, CV, L, q, eprev, cs, ck, stack, diss, nfail, worst, F, K):
    """One step of every channel to deflections e with its effects; (Fout, Kout) in place.

    The arguments after Kout are the bank's kernel arguments (:meth:`BushingBank.kernel_args`).
    """
    _effects_in(e, EP, X)
    kn.step_bank(X, h, P, I, MX, CV, L, q, eprev, cs, ck, stack, diss, nfail, worst, F, K)
    _effects_out(h, e, X, EP, ES, P, diss, F, K, Fout, Kout)


@nb.njit(cache=True, nogil=True)
def run_extended(E, dts, EP, ES, X, Fhist, Khist, P, I, MX, CV, L, q, eprev, cs, ck, stack, diss, nfail, worst, F, K):
    """Step through deflections E (T, M) with steps dts (T,) [s]; forces and tangents into (T, M)."""
    for t in range(E.shape[0]):
        step_extended(E[t], dts[t], EP, ES, X, Fhist[t], Khist[t], P, I, MX, CV, L, q, eprev, cs, ck, stack, diss,
                      nfail, worst, F, K)


class ExtendedBank:
    """A :class:`BushingBank` whose channels carry :class:`Effects`, stepped by one compiled call.

    A channel with a preload is mounted at :meth:`reset`: a quasi-static ramp from 0 to its
    preload deflection, after which its force is tared to zero (as a bench zeroes its load cell on
    the mounted part, and as a vehicle is assembled at its design position).
    """

    def __init__(self, channels: Sequence[ChannelParams], effects: Sequence[Effects] | None = None,
                 tolerance: float = DEFAULT_TOLERANCE):
        channels = list(channels)
        self.bank = BushingBank(channels, tolerance)
        effects = list(effects) if effects is not None else [NO_EFFECTS] * self.bank.size
        if len(effects) != self.bank.size:
            raise ValueError(f"{len(effects)} effects for {self.bank.size} channels")
        self.effects = tuple(effects)
        M = self.bank.size
        self.EP = np.zeros((M, N_ECOLS))
        for c, (ch, fx) in enumerate(zip(channels, self.effects)):
            # the asymmetry's rate is given at the parameter sets' unit of deflection r: a·r^(1−n) per (m or rad)^n
            rate = fx.asymmetry * LENGTH_UNIT_SI[ch.quantity] ** (1.0 - fx.asymmetry_power)
            self.EP[c, :E_TARE] = (fx.preload, rate, fx.asymmetry_power, fx.asymmetry_step, fx.asymmetry_step_width,
                                   fx.mullins, fx.mullins_shape, fx.heating, fx.heating_tau_s, fx.slip_force,
                                   fx.slip_stiffness, fx.backlash)
        self.ES = np.zeros((M, N_SCOLS))
        self._X = np.zeros(M)
        self.force = np.zeros(M)
        self.tangent = np.zeros(M)
        self.reset()

    @property
    def size(self) -> int:
        """Number of channels M."""
        return self.bank.size

    def reset(self) -> None:
        """Virgin, unloaded channels, then mounted at their preload (if any) and tared."""
        self.bank.reset()
        self.ES[:] = 0.0
        self.EP[:, E_TARE] = 0.0
        preload = self.EP[:, E_PRELOAD].copy()
        if not preload.any():
            return
        zero = np.zeros(self.size)
        for i in range(1, MOUNT_STEPS + 1):
            self.EP[:, E_PRELOAD] = preload * i / MOUNT_STEPS
            self.step(zero, MOUNT_S / MOUNT_STEPS)
        # a slipping interface is clamped at the mounted position: unloaded there, whatever the ramp did
        slip = self.ES[:, S_SLIP_F].copy()
        self.ES[:, S_SLIP_F], self.ES[:, S_SLIP_X] = 0.0, self._X
        self.EP[:, E_TARE] = self.force - slip

    def kernel_args(self) -> tuple[np.ndarray, ...]:
        """Arguments of :func:`step_extended` after (e, h): the effect arrays, ``force`` and
        ``tangent`` (4th and 5th), then the base bank's; for a compiled caller (the vehicle's loop)."""
        return (self.EP, self.ES, self._X, self.force, self.tangent) + self.bank.kernel_args()

    def step(self, e: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Advance all channels by dt [s] to deflections e (M,); returns (force, tangent) owned by the bank."""
        if not dt > 0.0:
            raise ValueError(f"time step must be positive, got {dt!r}")
        step_extended(np.ascontiguousarray(e, dtype=float), float(dt), self.EP, self.ES, self._X, self.force,
                      self.tangent, *self.bank.kernel_args())
        return self.force, self.tangent

    def run(self, e: np.ndarray, dts: np.ndarray | float) -> np.ndarray:
        """Forces (T, M) along deflections e (T, M), or (T,) applied to every channel, with steps
        dts (T,) or one step [s]; continues from the current state. Releases the GIL, so that
        banks can run in parallel threads."""
        hist = np.asarray(e, dtype=float)
        if hist.ndim == 1:
            hist = np.repeat(hist[:, None], self.size, axis=1)
        hist = np.ascontiguousarray(hist)
        steps = np.broadcast_to(np.asarray(dts, dtype=float), (len(hist),)).copy()
        if not (steps > 0.0).all():
            raise ValueError("time steps must be positive")
        forces = np.empty_like(hist)
        tangents = np.empty_like(hist)
        run_extended(hist, steps, self.EP, self.ES, self._X, forces, tangents, *self.bank.kernel_args())
        self.force[:] = forces[-1]
        self.tangent[:] = tangents[-1]
        return forces
