"""Frequency characterisation (spec §4): first-harmonic dynamic stiffness and loss angle.

Two estimates of K* = F1/E1 under e = A·sin(2πft), for many (A, f) pairs at once:

* :func:`first_harmonic`, the reference: time simulation of the stabilised response.
* :func:`equivalent_damping`, the fast approximation of eqs 5.16/5.17: every dissipative element
  becomes the linear damper dissipating the same energy per cycle at its own amplitude, and the
  ladder is solved as a complex linear system whose node amplitudes are iterated to consistency.

All quantities are SI: amplitudes in m, stiffness in N/m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from elastokin.bushings.bank import BushingBank
from elastokin.bushings.parameters import ChannelParams
from elastokin.core.errors import InputError


@dataclass(frozen=True)
class DynamicStiffness:
    """First-harmonic complex stiffness K* = F1/E1 per (amplitude, frequency) pair."""

    amplitude_m: np.ndarray        #: sine amplitude A [m]
    frequency_hz: np.ndarray       #: sine frequency f [Hz]
    k_complex_n_per_m: np.ndarray  #: F1/E1 [N/m] (complex)

    @property
    def k_dyn_n_per_m(self) -> np.ndarray:
        """Dynamic stiffness |K*| [N/m]."""
        return np.abs(self.k_complex_n_per_m)

    @property
    def tan_delta(self) -> np.ndarray:
        """Loss factor tan δ = Im K* / Re K*."""
        return self.k_complex_n_per_m.imag / self.k_complex_n_per_m.real


def harmonic_ratio(e: np.ndarray, force: np.ndarray, samples_per_cycle: int) -> np.ndarray:
    """F1/E1 of the last ``samples_per_cycle`` rows of e and force, shape (T,) or (T, M).

    The rectangle rule over exactly one period is exact for the first harmonic of a sampled
    periodic signal, so no window is needed.
    """
    phase = np.exp(-2j * math.pi * np.arange(samples_per_cycle) / samples_per_cycle)
    e1 = np.tensordot(phase, e[-samples_per_cycle:], axes=(0, 0))
    f1 = np.tensordot(phase, force[-samples_per_cycle:], axes=(0, 0))
    return f1 / e1


def rate_scaled(channel: ChannelParams, factor: float) -> ChannelParams:
    """The channel seen in a time scaled by ``factor`` (τ = factor·t): every rate-dependent
    coefficient takes the factor (C, Maxwell dampers: factor; power-law Co: factor**pw), so that
    stepping the copy in τ is the same backward-Euler scheme as stepping the original in t."""
    return channel.replace(C=channel.C * factor, Co=channel.Co * factor ** channel.pw,
                           maxwell_c=tuple(c * factor for c in channel.maxwell_c))


def first_harmonic(channel: ChannelParams, amplitudes_m: np.ndarray, frequencies_hz: np.ndarray, *,
                   cycles: int = 5, points_per_cycle: int = 400, max_dt_s: float | None = None) -> DynamicStiffness:
    """Dynamic stiffness of the last of ``cycles`` sine cycles from rest, by time simulation.

    ``amplitudes_m`` [m] and ``frequencies_hz`` [Hz] broadcast together; the result has their
    common shape. Every pair is one channel of a single bank, stepped in time normalised by its
    own period (see :func:`rate_scaled`), so all pairs share one grid of n samples per cycle with
    n ≥ ``points_per_cycle`` (and a real step ≤ ``max_dt_s`` at the lowest frequency if given).
    The ladder laws have no time scale of their own, so n alone sets the accuracy: for ``fig5_9_caption``
    n = 400 and n = 2000 agree to 0.05 % in |K*| and 0.5 % in tan δ. Backward Euler's phase
    error makes tan δ of a linear damper low by about (π/n)·tan δ relative.
    """
    a, f = np.broadcast_arrays(np.asarray(amplitudes_m, dtype=float), np.asarray(frequencies_hz, dtype=float))
    n = points_per_cycle if max_dt_s is None else max(points_per_cycle, math.ceil(1.0 / (f.min() * max_dt_s) - 1e-9))
    bank = BushingBank([rate_scaled(channel, fi) for fi in f.ravel()])
    phase = 2.0 * math.pi * np.arange(1, cycles * n + 1) / n
    e = np.sin(phase)[:, None] * a.ravel()[None, :]
    force, _ = bank.run(e, 1.0 / n)
    return DynamicStiffness(a, f, harmonic_ratio(e, force, n).reshape(a.shape))


def lossier(channel: ChannelParams, amplitude_m: float, frequency_hz: float, factor: float = 2.0) -> ChannelParams:
    """``channel`` with its ladder's stiffness Kpa × ``factor`` and its linear spring K0 set so that
    its dynamic stiffness |K*| at (``amplitude_m``, ``frequency_hz``) stays its own: more loss (a
    factor above 1) at the same stiffness there, as a lossier compound in a part of the same rate.

    With the deflection imposed K0 only adds K0 to K*: with c the rest's K* (the ladder stiffened),
    K0 = −Re c + √(|K*|² − (Im c)²). ValueError for a law whose elastic part is not linear (K0 is then
    no parallel spring) or when no K0 ≥ 0 gives |K*| (the stiffened ladder alone is already stiffer).
    """
    if (any(math.isfinite(x) for x in (channel.N_sup, channel.N_inf, channel.S_sup, channel.S_inf))
            or channel.P_sup or channel.P_inf):
        raise ValueError(f"a {channel.model} law with a nonlinear elastic part: its K0 is not a parallel spring")
    at = (np.array([amplitude_m]), np.array([frequency_hz]))
    target = abs(first_harmonic(channel, *at).k_complex_n_per_m[0])
    stiffened = channel.replace(Kpa=channel.Kpa * factor)
    rest = first_harmonic(stiffened, *at).k_complex_n_per_m[0] - channel.K0
    k0 = -rest.real + math.sqrt(target ** 2 - rest.imag ** 2) if target >= abs(rest.imag) else -1.0
    if k0 < 0.0:
        raise ValueError(f"Kpa × {factor:g} alone makes |K*| above the law's {target:.4g} N/m: no K0 keeps it")
    return stiffened.replace(K0=k0)


def with_loss(channel: ChannelParams, tan_delta: float, amplitude_m: float, frequency_hz: float,
              max_factor: float = 50.0) -> ChannelParams:
    """``channel`` made lossier (:func:`lossier`) until its tan δ at (``amplitude_m``,
    ``frequency_hz``) is ``tan_delta``, its |K*| there kept: a part of the same rate in a compound of
    the stated loss (PSA specifies tan δ at 15 Hz, 1 mm: Bourgeteau 2009, §2.1.1).

    Args:
        channel: a ladder law (SI) whose elastic part is linear.
        tan_delta: the loss wanted, at least the law's own.
        amplitude_m: sine amplitude [m]; frequency_hz: its frequency [Hz].
        max_factor: the stiffest ladder tried, × the law's own Kpa.

    Returns:
        The law with Kpa × f and K0 lowered (SI), f found to a relative 1e-6.

    Raises:
        ValueError: when ``tan_delta`` is below the law's own loss, or beyond what a ladder
            ``max_factor`` times as stiff gives (or than a K0 ≥ 0 allows).
    """
    at = (np.array([amplitude_m]), np.array([frequency_hz]))

    def loss(factor: float) -> float:
        k = first_harmonic(lossier(channel, amplitude_m, frequency_hz, factor), *at).k_complex_n_per_m[0]
        return float(k.imag / k.real) - tan_delta

    own = loss(1.0) + tan_delta
    if tan_delta < own:
        raise ValueError(f"tan δ {tan_delta:g} is below the law's own {own:.4g}: a lossier law cannot give it")
    where = f"at {amplitude_m * 1e3:g} mm, {frequency_hz:g} Hz"
    try:
        most = loss(max_factor) + tan_delta
    except ValueError as exc:   # the ladder that stiff leaves no K0 ≥ 0: try a smaller max_factor
        raise ValueError(f"tan δ {tan_delta:g} {where}: a ladder {max_factor:g} × as stiff is refused ({exc})") from None
    if tan_delta > most:
        raise ValueError(f"tan δ {tan_delta:g} is beyond a ladder {max_factor:g} × as stiff (it gives {most:.4g}) {where}")
    return lossier(channel, amplitude_m, frequency_hz, brentq(loss, 1.0, max_factor, xtol=1e-9, rtol=1e-6))


def equivalent_damping(channel: ChannelParams, amplitudes_m: np.ndarray, frequencies_hz: np.ndarray, *,
                       eps_m: float = 1e-10, tol: float = 1e-6, max_iter: int = 2000) -> DynamicStiffness:
    """Dynamic stiffness by the equivalent-damping approximation (spec eqs 5.16/5.17).

    At node amplitude X each ladder element is replaced by the damper dissipating the same energy
    per cycle: C_eq = 2·Co·(ωX)^(pw−1)·Γ(1+pw/2)/(√π·Γ((3+pw)/2)) + 4·Ff/(π·ω·X). The node
    amplitudes are iterated (plain fixed point) until they reproduce themselves to
    ``tol`` relative to A; |X| is regularised as √(X² + eps_m²) (1e-7 mm by default, so that stuck
    sliders keep a finite damper). The elastic law is taken as linear (K0); the continuous STS
    has no ladder and is refused.
    """
    if channel.continuous:
        raise InputError(f"the equivalent-damping approximation needs a ladder model, not {channel.model!r}",
                         key="model")
    a, f = np.broadcast_arrays(np.asarray(amplitudes_m, dtype=float), np.asarray(frequencies_hz, dtype=float))
    w = 2.0 * math.pi * f.ravel()
    k = channel.K0 + 1j * w * channel.C
    for km, cm in zip(channel.maxwell_k, channel.maxwell_c):
        k = k + km * 1j * w * cm / (km + 1j * w * cm)
    if channel.n_cells:
        u1 = _ladder_first_node(channel, a.ravel(), w, eps_m, tol, max_iter)
        k = k + channel.Kpa * (1.0 - u1 / a.ravel())
    return DynamicStiffness(a, f, np.broadcast_to(k, a.size).reshape(a.shape))


def _ladder_first_node(ch: ChannelParams, a: np.ndarray, w: np.ndarray, eps_m: float, tol: float,
                       max_iter: int) -> np.ndarray:
    """Complex amplitude of node 1 of the linearised ladder, per pair (P,)."""
    n = ch.n_cells
    k_left = np.full(n, ch.Kr)
    k_left[0] = ch.Kpa
    stiffness = np.diag(k_left + ch.Kr) - ch.Kr * (np.eye(n, k=1) + np.eye(n, k=-1))
    rhs = np.zeros((len(a), n), dtype=complex)
    rhs[:, 0] = ch.Kpa * a
    # math.gamma, not scipy.special's: that import alone cost every run 0.14 s
    viscous = 2.0 * ch.Co * math.gamma(1.0 + ch.pw / 2.0) / (math.sqrt(math.pi) * math.gamma((3.0 + ch.pw) / 2.0))

    def regularised_amplitudes(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        wx = w[:, None] * x
        c_eq = viscous * wx ** (ch.pw - 1.0) + 4.0 * ch.Ff / (math.pi * wx)
        u = np.linalg.solve(stiffness + (1j * w[:, None] * c_eq)[:, :, None] * np.eye(n), rhs[:, :, None])[:, :, 0]
        return np.sqrt(np.abs(u) ** 2 + eps_m ** 2), u[:, 0]

    # Start from infinite node amplitudes, where sliders and power-law dampers vanish.
    x, _ = regularised_amplitudes(np.full((len(a), n), np.inf))
    for _ in range(max_iter):
        x_new, u1 = regularised_amplitudes(x)
        if np.max(np.abs(x_new - x) / a[:, None]) < tol:
            return u1
        x = x_new
    raise RuntimeError(f"equivalent-damping node amplitudes did not converge in {max_iter} iterations")
