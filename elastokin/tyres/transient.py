"""First-order transient slip of the Magic Formula tyre: the slips the formula sees lag the
kinematic ones over a relaxation length (Pacejka, *Tire and Vehicle Dynamics*, 3rd ed., §7.2.2;
the relaxation lengths of MF 6.1 are the slip stiffnesses over the carcass stiffnesses, MF 5.2's
its own laws of PTX and PTY).

Written in the contact-deflection form, which holds down to standstill: with ``q`` the lagged slip
(κ', or tan α') and ``v`` the contact point's slip velocity that drives it (``Ω·Re − Vx`` for κ,
the lateral sliding velocity ``V_sy`` for tan α),

    σ·dq/dt + |Vx|·q = v,

so that rolling at constant slip ``q → v/|Vx|`` (the kinematic slip) with the length constant σ,
and at rest ``q = ∫v dt/σ``: the tyre holds like a spring of the carcass stiffness, and a car
parked on a slope does not creep. Below ``VXLOW`` a damping of the sliding velocity, ``DAMP_VLOW``
times the carcass stiffness, fades in (MF-Tyre's low-speed damping), since a spring alone would
ring at standstill.
"""

from __future__ import annotations

import math

import numba as nb

from elastokin.core.compiled_cache import follow
from elastokin.tyres import magic_formula
from elastokin.tyres.magic_formula import carcass_stiffnesses, low_speed_ramp, mf52_relaxation_lengths, slip_stiffnesses

follow(__file__, magic_formula.__file__)

#: Least relaxation length [m]: a tyre unloaded to zero has σ → 0; its slips then follow the
#: kinematic ones within a step instead of dividing by zero.
SIGMA_MIN = 1e-4


@nb.njit(cache=True)
def relaxation_lengths(p, fz: float, gamma: float) -> tuple[float, float]:
    """``(σκ, σα)`` [m] at load ``fz`` [N] and inclination ``gamma`` [rad]: slip stiffness over
    carcass stiffness (MF 5.2: :func:`~elastokin.tyres.magic_formula.mf52_relaxation_lengths`), each at
    least :data:`SIGMA_MIN`."""
    if p.MF52 > 0.0:
        sigma_k, sigma_a = mf52_relaxation_lengths(p, max(fz, 0.0), gamma)
        return max(sigma_k, SIGMA_MIN), max(sigma_a, SIGMA_MIN)
    kxk, kya = slip_stiffnesses(p, max(fz, 0.0), gamma)
    cx, cy = carcass_stiffnesses(p, max(fz, 0.0))
    return (max(abs(kxk) / cx, SIGMA_MIN) if cx > 0.0 else SIGMA_MIN,
            max(abs(kya) / cy, SIGMA_MIN) if cy > 0.0 else SIGMA_MIN)


@nb.njit(cache=True)
def lag(q: float, slip_velocity: float, vx: float, sigma: float, h: float) -> float:
    """The lagged slip after a step of ``h`` [s] from ``q``, with the slip velocity [m/s], forward
    speed [m/s] and relaxation length [m] held over the step: the exact solution of
    ``σ·dq/dt + |Vx|·q = v``, so the result does not depend on how a time is cut into steps."""
    decay = abs(vx) * h / sigma
    # (1 − e^(−λ))/λ, 1 at λ = 0 (standstill: q integrates v/σ)
    gain = -math.expm1(-decay) / decay if decay > 1e-12 else 1.0
    return q * math.exp(-decay) + slip_velocity * h / sigma * gain


@nb.njit(cache=True)
def low_speed_damping(p, fz: float, vx: float) -> tuple[float, float]:
    """Damping coefficients [N·s/m] of the longitudinal and lateral sliding velocities at forward
    speed ``vx`` [m/s]: ``DAMP_VLOW`` times the carcass stiffnesses at rest, fading to zero at
    ``VXLOW`` as one minus the shifts' low-speed ramp."""
    weight = 1.0 - low_speed_ramp(p, vx)
    if weight == 0.0:
        return 0.0, 0.0
    cx, cy = carcass_stiffnesses(p, max(fz, 0.0))
    return weight * p.DAMP_VLOW * cx, weight * p.DAMP_VLOW * cy
