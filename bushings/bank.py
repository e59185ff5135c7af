"""A bank of bushing channels stepped together: the one object a vehicle calls every time step."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from elastokin.bushings import kernel as kn
from elastokin.bushings.parameters import ChannelParams


@dataclass
class BankState:
    """A copy of a bank's internal state (for trial steps, restarts and reproducibility)."""

    arrays: dict[str, np.ndarray]


#: Default solver tolerance [m or rad]: ladder nodes placed to 10 nm (fig5_9_caption's sliders stretch 3 µm
#: before slipping). On the benchmark's load at h = 1 ms (tools/benchmarks/bushing_speed.py) it moves the force
#: by 0.05 N, a 28th of the time step's own error (1.4 N); 1e-9 m would cost 8 % more time.
DEFAULT_TOLERANCE = 1e-8


class BushingBank:
    """M bushing channels (any mix of models) with their internal state, stepped implicitly.

    ``step(e, dt)`` takes the deflections at the end of the step [m or rad], advances every
    channel by one backward-Euler step (exact stick–slip, unconditionally stable) and returns the
    forces [N or N·m] and tangent stiffnesses dF/de. One compiled call serves the whole bank.
    """

    _STATE = ("ladder", "q", "eprev", "cs", "ck", "stack", "diss", "nfail", "worst")

    def __init__(self, channels: Sequence[ChannelParams], tolerance: float = DEFAULT_TOLERANCE):
        """``tolerance`` [m or rad]: the implicit ladder solve stops when every node's force
        residual is below tolerance·(Kpa + 2·Kr), i.e. nodes are placed to about this distance."""
        self.channels: tuple[ChannelParams, ...] = tuple(channels)
        #: The solve's tolerance [m or rad].
        self.tolerance = tolerance
        M = len(self.channels)
        n_mx = max(sum(len(ch.maxwell_k) for ch in self.channels), 1)
        n_cv = max(sum(len(ch.curve) for ch in self.channels), 1)
        cells = np.array([0 if ch.continuous else ch.n_cells for ch in self.channels], dtype=np.int64)
        ladder_at, ladder_size = kn.place_ladders(cells)
        shapes = {"P": (M, kn.N_PCOLS), "I": (M, kn.N_ICOLS), "MX": (n_mx, 2), "CV": (n_cv, 3), "ladder": (ladder_size,),
                  "q": (n_mx,), "eprev": (M,), "cs": (M, 2), "ck": (M,), "stack": (M, kn.STACK_SIZE, 2),
                  "diss": (M,), "nfail": (M,), "worst": (M,), "force": (M,), "tangent": (M,)}
        self._fbuf, self._ibuf, arrays = kn.pack_bank(shapes)
        for name, array in arrays.items():
            setattr(self, name, array)
        mx = cv = 0
        for c, ch in enumerate(self.channels):
            self.P[c, kn.P_K0] = ch.K0
            self.P[c, kn.P_C] = ch.C
            self.P[c, kn.P_NSUP:kn.P_PINF + 1] = (ch.N_sup, ch.N_inf, ch.S_sup, ch.S_inf, ch.P_sup, ch.P_inf)
            self.P[c, kn.P_KPA] = ch.Kpa
            self.P[c, kn.P_KR] = ch.Kr
            self.P[c, kn.P_FF] = ch.Ff
            self.P[c, kn.P_CO] = ch.Co
            self.P[c, kn.P_PW] = ch.pw
            self.P[c, kn.P_CT] = ch.Ct
            self.P[c, kn.P_NROOT] = ch.n_root
            self.P[c, kn.P_TOL] = tolerance
            if ch.continuous:
                self.I[c, kn.I_KIND] = kn.KIND_CONTINUOUS
                # Micro-reversal filter: 1e-3 of the length over which the branch slope halves.
                self.P[c, kn.P_EPS] = 1e-3 * _hysteresis_length(ch)
            self.I[c, kn.I_NCELL] = cells[c]
            self.I[c, kn.I_LADDER] = ladder_at[c]
            self.I[c, kn.I_MX_N] = len(ch.maxwell_k)
            self.I[c, kn.I_MX_OFF] = mx
            for k, cc in zip(ch.maxwell_k, ch.maxwell_c):
                self.MX[mx] = (k, cc)
                mx += 1
            self.I[c, kn.I_CV_N] = len(ch.curve)
            self.I[c, kn.I_CV_OFF] = cv
            for node in ch.curve:
                self.CV[cv] = node
                cv += 1
        self.reset()

    @property
    def size(self) -> int:
        """Number of channels M."""
        return len(self.channels)

    @property
    def dissipated(self) -> np.ndarray:
        """Energy dissipated in each channel's damping and friction elements since reset [J]."""
        return self.diss

    @property
    def failed_steps(self) -> np.ndarray:
        """Per channel, the number of steps since reset whose implicit solve hit its iteration cap
        with a residual left (should be 0)."""
        return self.nfail

    @property
    def tolerances(self) -> np.ndarray:
        """Per channel, the tolerance its solve is held to [m or rad]: ``tolerance``, or round-off
        for a Coulomb ladder (no power-law dampers), solved exactly."""
        return np.array([self.tolerance if ch.Co > 0.0 else kn.STICK_TOLERANCE for ch in self.channels])

    @property
    def worst_residual(self) -> np.ndarray:
        """Per channel, the largest residual those steps left [m or rad]: the nodes' worst force
        residual over Kpa + 2·Kr, the distance to which they are placed, to set beside the
        :attr:`tolerances` (0 where every step converged; NaN for a residual that was not a number)."""
        return self.worst

    def reset(self) -> None:
        """Return every channel to its virgin, unloaded state at zero deflection."""
        # In place: compiled callers keep the arrays of kernel_args() (the vehicle's coupling does).
        for name in self._STATE + ("force", "tangent"):
            getattr(self, name)[...] = 0
        kn.reset_ladders(self.ladder, self.P, self.I)

    def snapshot(self) -> BankState:
        """A copy of the internal state."""
        return BankState({name: getattr(self, name).copy() for name in self._STATE})

    def restore(self, state: BankState) -> None:
        """Restore a state taken by :meth:`snapshot` of this bank."""
        for name in self._STATE:
            getattr(self, name)[...] = state.arrays[name]

    def step(self, e: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Advance all channels by dt [s] to deflections e (M,) [m or rad].

        Returns (force, tangent), arrays of shape (M,) owned by the bank and overwritten by the
        next call.
        """
        if not dt > 0.0:
            raise ValueError(f"time step must be positive, got {dt!r}")
        kn.step_packed(np.ascontiguousarray(e, dtype=float), float(dt), self._fbuf, self._ibuf)
        return self.force, self.tangent

    def kernel_args(self) -> tuple[np.ndarray, ...]:
        """The arrays :func:`elastokin.bushings.kernel.step_bank` takes after (e, h), in its order, for
        compiled callers (e.g. a vehicle step loop) that call the kernel themselves."""
        return tuple(getattr(self, name) for name, _, _ in kn.BANK_ARRAYS)

    def run(self, e: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Step through a deflection history e (T, M) or (T,) for one channel; returns forces and
        tangents of the same shape (row t is the state after imposing e[t])."""
        hist = np.asarray(e, dtype=float)
        flat = hist.ndim == 1
        hist = hist.reshape(len(hist), -1)
        forces = np.empty_like(hist)
        tangents = np.empty_like(hist)
        for t in range(len(hist)):
            f, k = self.step(hist[t], dt)
            forces[t] = f
            tangents[t] = k
        if flat:
            return forces[:, 0], tangents[:, 0]
        return forces, tangents


def _hysteresis_length(ch: ChannelParams) -> float:
    """Length over which the continuous-STS first-loading slope halves from Kpa [m]."""
    n = ch.n_root
    A = (n * ch.Kpa / ch.Ct ** (1.0 / n)) ** (n / (1.0 - n))
    # slope ∝ (s + A)^(1/n − 1): halves at s = A·(2^(n/(n−1)) − 1)
    return A * (2.0 ** (n / (n - 1.0)) - 1.0) if math.isfinite(A) else 1e-6
