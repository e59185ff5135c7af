"""Tyres on a flat road (z = 0), compiled: from each wheel's pose and velocity, the contact point in
the wheel's plane, the slips, the transient Magic Formula forces, and the wrench on the wheel body.

Per wheel, with ``a`` its spin axis (unit, pointing to the vehicle's left for every wheel) and
``z`` the road's normal:

* contact frame (ISO-W): ``x_c = a × z / |a × z|`` the heading on the road, ``y_c = z × x_c``;
  inclination ``γ = asin(a·z)`` (positive when the wheel's top leans to −y_c);
* contact point: where the wheel's plane meets the road below the centre ``c``, along the plane's
  downward direction: loaded radius ``R_l = c_z/|a × z|``, deflection ``ρ = R0 − R_l``;
* velocities: of the contact point carried by the knuckle (the wheel's angular velocity without
  its spin), ``V_x``, the lateral sliding ``V_sy``; the longitudinal slip's drive ``Ω·R_e − V_x``
  with ``Ω`` the spin rate and ``R_e`` MF-Tyre's effective rolling radius;
* forces: ``Fz`` from the vertical law, the lagged slips (:mod:`elastokin.tyres.transient`), ``Fx, Fy,
  Mz, My`` from the formula, the low-speed damping of the sliding velocities; applied at the
  contact point (``Mz`` about z, ``My`` about y_c).

A tyre mounted on the side opposite to its file's ``TYRESIDE`` is the mirror image of the measured
one: its lateral slip and inclination are mirrored into the formula and ``Fy``, ``Mz`` out of it,
so that the car's left and right behave as mirror images.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from elastokin.core.compiled_cache import follow
from elastokin.tyres import magic_formula, transient
from elastokin.tyres.magic_formula import forces, vertical_force
from elastokin.tyres.transient import lag, low_speed_damping, relaxation_lengths

#: The files a function that computes the tyres compiles into itself (see elastokin.core.compiled_cache).
TYRE_FILES = (magic_formula.__file__, transient.__file__, __file__)
follow(__file__, *TYRE_FILES)

#: Columns of a wheel's row of signals (``signals[w]``), SI.
SIGNALS = ("Fz_N", "Fx_N", "Fy_N", "Mz_Nm", "My_Nm", "kappa", "alpha_rad", "gamma_rad", "vx_mps", "deflection_m")
N_SIGNALS = len(SIGNALS)
#: Columns of a wheel's transient state: lagged longitudinal slip κ', lagged tan α'.
N_STATE = 2


@nb.njit(cache=True, inline="always")
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@nb.njit(cache=True)
def effective_rolling_radius(p, deflection: float) -> float:
    """MF-Tyre's effective rolling radius [m] at ``deflection`` [m]:
    ``R_e = R0 − ρ_Fz0·(DREFF·atan(BREFF·ρ/ρ_Fz0) + FREFF·ρ/ρ_Fz0)``, ρ_Fz0 = FNOMIN/VERTICAL_STIFFNESS."""
    rho0 = p.FNOMIN / p.VERTICAL_STIFFNESS
    x = max(deflection, 0.0) / rho0
    return p.UNLOADED_RADIUS - rho0 * (p.DREFF * math.atan(p.BREFF * x) + p.FREFF * x)


@nb.njit(cache=True)
def tyre_wrenches(tyres, mirrored, h, wheel_body, xipos, xmat, cvel, subtree_com, root_body, state, xfrc,
                  signals) -> None:
    """Write into ``xfrc[wheel_body[w]]`` the road's force and torque on each wheel ``w`` [N, N·m,
    world axes, at the wheel's centre of mass], advancing the transient slips ``state[w]`` over the
    step ``h`` [s] and writing ``signals[w]`` (:data:`SIGNALS`). ``tyres[w]`` are the Magic Formula
    records, ``mirrored[w]`` the wheels on the side opposite to their file's; positions and
    velocities are MuJoCo's (``mj_step1`` fresh)."""
    for w in range(wheel_body.shape[0]):
        p = tyres[w]
        s = -1.0 if mirrored[w] else 1.0
        b = wheel_body[w]
        cx, cy, cz = xipos[b, 0], xipos[b, 1], xipos[b, 2]
        ax, ay, az = xmat[b, 1], xmat[b, 4], xmat[b, 7]            # the body's y axis: the spin axis
        hx, hy, _ = _cross(ax, ay, az, 0.0, 0.0, 1.0)               # a × z (horizontal)
        n = math.sqrt(hx * hx + hy * hy)
        hx, hy = hx / n, hy / n                                     # x_c; y_c = z × x_c = (−hy, hx, 0)
        loaded = cz / n
        rho = p.UNLOADED_RADIUS - loaded
        # contact point: c + R_l·d, d = −(z − (a·z)a)/n
        dx, dy, dz = az * ax / n, az * ay / n, (az * az - 1.0) / n
        px, py, pz = cx + loaded * dx, cy + loaded * dy, cz + loaded * dz
        # velocities: cvel = (ω, v at the subtree's centre of mass), world axes
        r = root_body[b]
        wx, wy, wz = cvel[b, 0], cvel[b, 1], cvel[b, 2]
        ox, oy, oz = _cross(wx, wy, wz, cx - subtree_com[r, 0], cy - subtree_com[r, 1], cz - subtree_com[r, 2])
        vcx, vcy, vcz = cvel[b, 3] + ox, cvel[b, 4] + oy, cvel[b, 5] + oz
        spin = wx * ax + wy * ay + wz * az
        kx, ky, kz = wx - spin * ax, wy - spin * ay, wz - spin * az  # the knuckle's rotation
        ox, oy, oz = _cross(kx, ky, kz, px - cx, py - cy, pz - cz)
        vpx, vpy, vpz = vcx + ox, vcy + oy, vcz + oz
        vx = vpx * hx + vpy * hy
        vsy = -vpx * hy + vpy * hx
        gamma = math.asin(max(-1.0, min(1.0, az)))
        fz = vertical_force(p, rho, -vpz)
        drive = spin * effective_rolling_radius(p, rho) - vx
        sigma_k, sigma_a = relaxation_lengths(p, fz, s * gamma)
        state[w, 0] = lag(state[w, 0], drive, vx, sigma_k, h)
        state[w, 1] = lag(state[w, 1], s * vsy, vx, sigma_a, h)
        alpha = math.atan(state[w, 1])
        fx, fy, mz, my = forces(p, fz, state[w, 0], alpha, s * gamma, vx)
        fy, mz = s * fy, s * mz
        if fz > 0.0:
            damp_x, damp_y = low_speed_damping(p, fz, vx)
            fx += damp_x * drive
            fy -= damp_y * vsy
        # force at the contact point, world axes; torque about the wheel's centre of mass
        fwx, fwy, fwz = fx * hx - fy * hy, fx * hy + fy * hx, fz
        tx, ty, tz = _cross(px - cx, py - cy, pz - cz, fwx, fwy, fwz)
        xfrc[b, 0], xfrc[b, 1], xfrc[b, 2] = fwx, fwy, fwz
        xfrc[b, 3], xfrc[b, 4], xfrc[b, 5] = tx - my * hy, ty + my * hx, tz + mz
        out = signals[w]
        out[0], out[1], out[2], out[3], out[4] = fz, fx, fy, mz, my
        out[5], out[6], out[7], out[8], out[9] = state[w, 0], s * alpha, gamma, vx, rho


def mirrored_wheels(tyreside: str, sides: tuple[str, ...]) -> np.ndarray:
    """Which wheels (``sides``, each "left" or "right") carry their file's tyre mirrored: those on the
    side opposite to ``TYRESIDE`` (MF-Tyre's default "LEFT" when the file says nothing)."""
    return np.array([side.upper() != tyreside.upper() for side in sides])
