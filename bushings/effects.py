"""Physical extensions of a bushing force law that the thesis's models lack (spec bushings §6).

Two kinds, both switched on per channel and off by default:

* parameter extensions, which stay inside the ladder/Maxwell family and so only change a
  :class:`ChannelParams`: rate-dependent damping on the ladder nodes (:func:`with_viscosity`),
  slider friction on them (:func:`with_friction`), and broad-spectrum relaxation as a Prony series
  fitted to a fractional (power-law) relaxation modulus (:func:`with_broad_relaxation`);
* state extensions (:class:`Effects`), applied around the base law by a compiled wrapper of the
  bank's kernel: preload (operating-point shift), tension/compression asymmetry, Mullins
  softening, self-heating, and a backlash dead band.

:class:`ExtendedBank` steps a bank of channels with their effects, and runs whole deflection
histories in one compiled call (for fitting, where a history is replayed many times).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, fields
from typing import Any, Mapping, Sequence

import numba as nb
import numpy as np
from numba.core import caching

from bushings import kernel as kn
from bushings.bank import DEFAULT_TOLERANCE, BushingBank
from vsim_core.errors import InputError
from bushings.parameters import LENGTH_UNIT_SI, ChannelParams

# Columns of the effect parameter matrix (one row per channel) and of the effect state.
E_PRELOAD, E_ASYM, E_MULLINS, E_HEAT, E_HEAT_TAU, E_BACKLASH, E_TARE = range(7)
N_ECOLS = 7
S_XMAX, S_HEAT, S_DISS = range(3)
N_SCOLS = 3
#: Duration and steps of the quasi-static mounting ramp to the preload deflection.
MOUNT_S, MOUNT_STEPS = 10.0, 200


def kernel_stamped_locator(owner: str) -> type:
    """A numba cache locator for the compiled functions of the file ``owner`` whose stamp also
    covers the bushing kernels (``bushings/kernel.py`` and this file).

    A function that calls the kernel compiles it into itself, but numba checks only the stamp of
    the function's own file: after a kernel change its cache would run the old kernel (on the new
    bank's arrays: wrong bits at best, memory corruption at worst). Register the class with
    ``numba.core.caching.CacheImpl._locator_classes.insert(0, ...)`` before the functions are defined.
    """
    owner_path = os.path.realpath(owner)

    class KernelStampedLocator(caching.InTreeCacheLocator):
        @classmethod
        def from_function(cls, py_func, py_file):
            if os.path.realpath(py_file) != owner_path:
                return None  # other files keep numba's own locators
            return super().from_function(py_func, py_file)

        def get_source_stamp(self):
            stamps = [super().get_source_stamp()]
            for path in (kn.__file__, __file__):
                st = os.stat(path)
                stamps.append(caching._hash_source_file(path, st.st_mtime, st.st_size))
            return tuple(stamps)

    return KernelStampedLocator


caching.CacheImpl._locator_classes.insert(0, kernel_stamped_locator(__file__))


@dataclass(frozen=True)
class Effects:
    """State extensions of one channel's law (SI: m or rad, N or N·m, J, s); zeros switch them off.

    With ``x = e + preload`` (after the backlash dead band) the force is
    ``η_mullins(x)·η_heat(Q)·(F_base(x) + F_asym(x)) − F_tare``.
    """

    preload: float = 0.0          #: operating point of the mounted part on its law [m or rad]
    asymmetry: float = 0.0        #: extra tangent fraction per unit deflection on one side [1/m or 1/rad];
    #: > 0 stiffens compression (x < 0), < 0 tension: F_asym = |a|·K0·x·|x|/2 on that side
    mullins: float = 0.0          #: softening μ below the largest |x| seen: η = 1 − μ(1 − |x|/x_max)
    heating: float = 0.0          #: softening per joule of heat held, κ = β/C_th [1/J]: η = 1/(1 + κQ)
    heating_tau_s: float = 300.0  #: thermal time constant of the heat held Q [s]
    backlash: float = 0.0         #: half-width of a dead band in series with the part [m or rad]

    @property
    def active(self) -> bool:
        """True when any effect is switched on."""
        return any(getattr(self, f.name) != 0.0 for f in fields(self) if f.name != "heating_tau_s")


NO_EFFECTS = Effects()

#: Parameter-set ``effects`` keys -> (Effects field, power of the length unit, unit for translations,
#: unit for rotations, lower bound). Lengths are in mm (or deg), heat in kJ, as in the parameter sets.
EFFECT_KEYS: dict[str, tuple[str, int, str, str, float]] = {
    "preload": ("preload", 1, "mm", "deg", -math.inf),
    "asymmetry": ("asymmetry", -1, "1/mm", "1/deg", -math.inf),
    "mullins": ("mullins", 0, "-", "-", 0.0),
    "heating": ("heating", 0, "1/kJ", "1/kJ", 0.0),
    "heating_tau_s": ("heating_tau_s", 0, "s", "s", 1e-9),
    "backlash": ("backlash", 1, "mm", "deg", 0.0),
}


def effects_to_si(values: Mapping[str, Any], quantity: str = "translation", source: str = "<effects>") -> Effects:
    """Validate a parameter set's ``effects`` mapping (mm or deg, 1/kJ, s) and convert it to SI."""
    length = LENGTH_UNIT_SI[quantity]
    si: dict[str, float] = {}
    for key, raw in values.items():
        if key not in EFFECT_KEYS:
            raise InputError(f"unknown effect {key!r}; expected one of {', '.join(EFFECT_KEYS)}",
                             source=source, key=f"effects.{key}")
        name, power, _, _, lower = EFFECT_KEYS[key]
        if isinstance(raw, bool) or not isinstance(raw, (int, float)) or not math.isfinite(raw) or raw < lower:
            raise InputError(f"expected a finite number >= {lower:g}, got {raw!r}", source=source, key=f"effects.{key}")
        si[name] = float(raw) * length ** power * (1e-3 if key == "heating" else 1.0)
    if si.get("mullins", 0.0) >= 1.0:
        raise InputError(f"expected mullins < 1, got {values['mullins']!r}", source=source, key="effects.mullins")
    return Effects(**si)


def with_viscosity(ch: ChannelParams, Co: float, pw: float) -> ChannelParams:
    """The ladder with power-law dampers Co·|v|^pw [N/(m/s)^pw] at every node (STS → STVS)."""
    return ch.replace(model="stvs" if ch.Ff > 0.0 else "rt", Co=Co, pw=pw)


def with_friction(ch: ChannelParams, Ff: float, co_scale: float = 1.0) -> ChannelParams:
    """The ladder with slider threshold Ff [N] at every node and its dampers scaled (RT → STVS)."""
    return ch.replace(model="stvs" if Ff > 0.0 else ch.model, Ff=Ff, Co=ch.Co * co_scale)


#: Relaxation times of the broad-spectrum Prony series [s]: two per decade from 1 ms to 10⁴ s.
BROAD_TAUS_S = np.logspace(-3, 4, 15)


def broad_relaxation_branches(k1: float, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """Maxwell branches (stiffnesses [N/m], damper rates [N·s/m]) whose relaxation modulus follows
    ``k1·t^−α`` (a fractional element, ``k1`` its stiffness at t = 1 s) within 5 % from 10 ms to 100 s.

    From t^−α = (1/Γ(α))·∫ τ^−α e^{−t/τ} d ln τ, discretised on the log-spaced :data:`BROAD_TAUS_S`;
    the tail beyond the longest time, ∫ τ^−α d ln τ = τ_max^−α/α, is lumped into the longest branch.
    """
    taus = BROAD_TAUS_S
    k = k1 / math.gamma(alpha) * taus ** (-alpha) * math.log(taus[1] / taus[0])
    k[-1] += k1 / math.gamma(alpha) * taus[-1] ** (-alpha) / alpha
    return k, k * taus


def with_broad_relaxation(ch: ChannelParams, k1: float, alpha: float) -> ChannelParams:
    """The law with a parallel fractional element of relaxation stiffness k1 [N/m] at 1 s and order α."""
    k, c = broad_relaxation_branches(k1, alpha)
    return ch.replace(maxwell_k=ch.maxwell_k + tuple(k), maxwell_c=ch.maxwell_c + tuple(c))


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
        a = EP[c, E_ASYM]
        if a != 0.0 and (x < 0.0) == (a > 0.0):
            k0 = P[c, kn.P_K0]
            f += abs(a) * k0 * x * abs(x) * 0.5
            k += abs(a) * k0 * abs(x)
        mu = EP[c, E_MULLINS]
        if mu > 0.0:
            if abs(x) > ES[c, S_XMAX]:
                ES[c, S_XMAX] = abs(x)
            xmax = ES[c, S_XMAX]
            if xmax > 0.0:
                eta = 1.0 - mu * (1.0 - abs(x) / xmax)
                k = eta * k + f * mu * (1.0 if x >= 0.0 else -1.0) / xmax
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
        b = EP[c, E_BACKLASH]
        if b > 0.0 and abs(e[c]) <= b:
            k = 0.0
        Fout[c] = f - EP[c, E_TARE]
        Kout[c] = k


@nb.njit(cache=True)
def step_extended(e, h, EP, ES, X, Fout, Kout, P, I, MX, L, q, eprev, cs, ck, stack, diss, nfail, F, K):
    """One step of every channel to deflections e with its effects; (Fout, Kout) in place.

    The arguments after Kout are the bank's kernel arguments (:meth:`BushingBank.kernel_args`).
    """
    _effects_in(e, EP, X)
    kn.step_bank(X, h, P, I, MX, L, q, eprev, cs, ck, stack, diss, nfail, F, K)
    _effects_out(h, e, X, EP, ES, P, diss, F, K, Fout, Kout)


@nb.njit(cache=True, nogil=True)
def run_extended(E, dts, EP, ES, X, Fhist, Khist, P, I, MX, L, q, eprev, cs, ck, stack, diss, nfail, F, K):
    """Step through deflections E (T, M) with steps dts (T,) [s]; forces and tangents into (T, M)."""
    for t in range(E.shape[0]):
        step_extended(E[t], dts[t], EP, ES, X, Fhist[t], Khist[t], P, I, MX, L, q, eprev, cs, ck, stack, diss,
                      nfail, F, K)


class ExtendedBank:
    """A :class:`BushingBank` whose channels carry :class:`Effects`, stepped by one compiled call.

    A channel with a preload is mounted at :meth:`reset`: a quasi-static ramp from 0 to its
    preload deflection, after which its force is tared to zero (as a bench zeroes its load cell on
    the mounted part, and as a vehicle is assembled at its design position).
    """

    def __init__(self, channels: Sequence[ChannelParams], effects: Sequence[Effects] | None = None,
                 tolerance: float = DEFAULT_TOLERANCE):
        self.bank = BushingBank(channels, tolerance)
        effects = list(effects) if effects is not None else [NO_EFFECTS] * self.bank.size
        if len(effects) != self.bank.size:
            raise ValueError(f"{len(effects)} effects for {self.bank.size} channels")
        self.effects = tuple(effects)
        M = self.bank.size
        self.EP = np.zeros((M, N_ECOLS))
        for c, fx in enumerate(self.effects):
            self.EP[c, :E_TARE] = (fx.preload, fx.asymmetry, fx.mullins, fx.heating, fx.heating_tau_s, fx.backlash)
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
        self.EP[:, E_TARE] = self.force

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
