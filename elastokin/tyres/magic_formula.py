"""The Magic Formula 6.1 and 5.2 tyres: steady-state forces and moments of one tyre from its ``.tir``
coefficients, compiled so that the vehicle's step loop calls it for the four wheels.

Equations: H. B. Pacejka, *Tire and Vehicle Dynamics*, 3rd ed. (2012), §4.3.2, eqs 4.E1–4.E78
(the numbers are quoted at each line), for a tyre rolling forward (every sgn(V_cx) = 1), without
turn slip (every ζ = 1) and with the friction's speed dependence off (``LMUV`` must be 0). Two choices the book leaves open are the MF-Tyre
solver's: the trail's lateral force ``Fy'`` is the combined force at zero camber (4.E74: camber
thrust acts at the contact centre), and the rolling resistance (4.E70) is written with the nominal
load in front, ``My = −R0·Fz0'·(…)·(Fz/Fz0')^QSY7·(p/p0)^QSY8``.

MF 5.2 (``.tir`` FITTYP 6, 21 or 52; MF-Tyre 5.2 and Adams' PAC2002, the book's 2nd edition) is the
same evaluation with the coefficients 5.2 has not at the values that make 6.1's equations 5.2's
(:data:`NEUTRAL_52`: no pressure terms, PKY4 = 2, PKY5 = PKY6 = PKY7 = PEY5 = RBX3 = RBY4 = QDZ10 =
QDZ11 = QSY5 = QSY6 = 0, QSY7 = 1, a linear vertical stiffness) and, where its equations differ
(the record's ``MF52`` flag): the camber scaled per direction, ``γ_x,y,z = γ*·LGAX, LGAY, LGAZ``
(6.1 scales the camber stiffnesses instead, LKYC and LKZC); the side force's camber shift
``S_Hy = (PHY1 + PHY2·dfz)·LHY + PHY3·γ_y`` (6.1: through K_yγ0, 4.E27); the trail's peak
``1 + QDZ3·γ_z + QDZ4·γ_z²`` (6.1: QDZ3·|γ*|, 4.E43); the trail's lateral force ``G_yκ·Fy0`` at
the tyre's camber (MF-Tyre 5.2: ``Fy − S_Vyκ``); and relaxation lengths from PTX1–3 and PTY1–2
(:func:`mf52_relaxation_lengths`; the low-speed damping, which 5.2 files do not give, MF-Tyre's
default :data:`DAMP_VLOW_52`). The slips are the book's α* = tan α, γ* = sin γ for both versions
(MF-Tyre's own solver takes α and γ). Sources of the differences: the MF-Tyre 5.2 equations as
MFeval (M. Furlan Tassara) evaluates FITTYP 6 and 21, and the 2nd edition's as MFPy (J. Cavalcante)
does.

Axes and signs are the ``.tir`` file's (ISO-W): x along the wheel's heading on the road, z up,
y left; longitudinal slip ``κ = (Ω·Re − Vx)/|Vx|`` (positive driving); slip angle ``α`` with
``tan α = Vsy/|Vx|`` (a positive ``α`` gives a negative ``Fy`` for the usual negative PKY1);
inclination ``γ`` about x (right-hand rule). SI: N, m, rad, s; the operating pressure is the
file's ``INFLPRES``.

A tyre's coefficients are one numpy record (:func:`coefficients`); numba compiles field access on
a record to a fixed offset, so the compiled functions read ``p.PKY1`` as fast as an array element.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from elastokin.tyres.tir_file import FITTYPS, TirFile

#: Keys of the Magic Formula 6.1 read from each section; all must be in the file (the scaling
#: factors, :data:`SCALING`, default to 1).
REQUIRED = {
    "MODEL": ("LONGVL", "VXLOW"),
    "DIMENSION": ("UNLOADED_RADIUS",),
    "OPERATING_CONDITIONS": ("INFLPRES", "NOMPRES"),
    "VERTICAL": ("FNOMIN", "VERTICAL_STIFFNESS", "VERTICAL_DAMPING", "Q_FZ2", "PFZ1", "BREFF", "DREFF", "FREFF"),
    "STRUCTURAL": ("LONGITUDINAL_STIFFNESS", "LATERAL_STIFFNESS", "PCFX1", "PCFX2", "PCFX3", "PCFY1", "PCFY2",
                   "PCFY3", "DAMP_VLOW"),
    "LONGITUDINAL_COEFFICIENTS": ("PCX1", "PDX1", "PDX2", "PDX3", "PEX1", "PEX2", "PEX3", "PEX4", "PKX1", "PKX2",
                                  "PKX3", "PHX1", "PHX2", "PVX1", "PVX2", "PPX1", "PPX2", "PPX3", "PPX4", "RBX1",
                                  "RBX2", "RBX3", "RCX1", "REX1", "REX2", "RHX1"),
    "LATERAL_COEFFICIENTS": ("PCY1", "PDY1", "PDY2", "PDY3", "PEY1", "PEY2", "PEY3", "PEY4", "PEY5", "PKY1", "PKY2",
                             "PKY3", "PKY4", "PKY5", "PKY6", "PKY7", "PHY1", "PHY2", "PVY1", "PVY2", "PVY3", "PVY4",
                             "PPY1", "PPY2", "PPY3", "PPY4", "PPY5", "RBY1", "RBY2", "RBY3", "RBY4", "RCY1", "REY1",
                             "REY2", "RHY1", "RHY2", "RVY1", "RVY2", "RVY3", "RVY4", "RVY5", "RVY6"),
    "ROLLING_COEFFICIENTS": ("QSY1", "QSY2", "QSY3", "QSY4", "QSY5", "QSY6", "QSY7", "QSY8"),
    "ALIGNING_COEFFICIENTS": ("QBZ1", "QBZ2", "QBZ3", "QBZ4", "QBZ5", "QBZ9", "QBZ10", "QCZ1", "QDZ1", "QDZ2", "QDZ3",
                              "QDZ4", "QDZ6", "QDZ7", "QDZ8", "QDZ9", "QDZ10", "QDZ11", "QEZ1", "QEZ2", "QEZ3", "QEZ4",
                              "QEZ5", "QHZ1", "QHZ2", "QHZ3", "QHZ4", "PPZ1", "PPZ2", "SSZ1", "SSZ2", "SSZ3", "SSZ4"),
}
#: Keys of the Magic Formula 5.2 read from each section (FITTYP 6, 21, 52); all must be in the file.
REQUIRED_52 = {
    "MODEL": ("LONGVL", "VXLOW"),
    "DIMENSION": ("UNLOADED_RADIUS",),
    "VERTICAL": ("FNOMIN", "VERTICAL_STIFFNESS", "VERTICAL_DAMPING", "BREFF", "DREFF", "FREFF"),
    "LONGITUDINAL_COEFFICIENTS": ("PCX1", "PDX1", "PDX2", "PDX3", "PEX1", "PEX2", "PEX3", "PEX4", "PKX1", "PKX2",
                                  "PKX3", "PHX1", "PHX2", "PVX1", "PVX2", "RBX1", "RBX2", "RCX1", "REX1", "REX2",
                                  "RHX1", "PTX1", "PTX2", "PTX3"),
    "LATERAL_COEFFICIENTS": ("PCY1", "PDY1", "PDY2", "PDY3", "PEY1", "PEY2", "PEY3", "PEY4", "PKY1", "PKY2", "PKY3",
                             "PHY1", "PHY2", "PHY3", "PVY1", "PVY2", "PVY3", "PVY4", "RBY1", "RBY2", "RBY3", "RCY1",
                             "REY1", "REY2", "RHY1", "RHY2", "RVY1", "RVY2", "RVY3", "RVY4", "RVY5", "RVY6", "PTY1",
                             "PTY2"),
    "ROLLING_COEFFICIENTS": ("QSY1", "QSY2", "QSY3", "QSY4"),
    "ALIGNING_COEFFICIENTS": ("QBZ1", "QBZ2", "QBZ3", "QBZ4", "QBZ5", "QBZ9", "QBZ10", "QCZ1", "QDZ1", "QDZ2", "QDZ3",
                              "QDZ4", "QDZ6", "QDZ7", "QDZ8", "QDZ9", "QEZ1", "QEZ2", "QEZ3", "QEZ4", "QEZ5", "QHZ1",
                              "QHZ2", "QHZ3", "QHZ4", "SSZ1", "SSZ2", "SSZ3", "SSZ4"),
}
#: The 6.1 coefficients an MF 5.2 file has not, where not 0: the values that make 6.1's equations 5.2's
#: (the pressures: any equal pair, dpi = 0).
NEUTRAL_52 = {"PKY4": 2.0, "QSY7": 1.0, "INFLPRES": 1.0, "NOMPRES": 1.0}
#: MF-Tyre's low-speed damping factor, for MF 5.2 files, which have no [STRUCTURAL] DAMP_VLOW.
DAMP_VLOW_52 = 1e-3
#: The scaling factors evaluated (``[SCALING_COEFFICIENTS]``, 1 when absent): both versions', MF 6.1's
#: own (camber stiffnesses; 1 for a 5.2 file) and MF 5.2's own (camber per force, relaxation
#: lengths; 1 for a 6.1 file).
SCALING = ("LFZO", "LCX", "LMUX", "LEX", "LKX", "LHX", "LVX", "LCY", "LMUY", "LEY", "LKY", "LHY", "LVY", "LTR", "LRES",
           "LXAL", "LYKA", "LVYKA", "LS", "LMY")
SCALING_61 = ("LKYC", "LKZC")
SCALING_52 = ("LGAX", "LGAY", "LGAZ", "LSGKP", "LSGAL")
#: The record type of a tyre's coefficients: one float64 field per key of either version, and
#: ``MF52`` (1 for an MF 5.2 file).
DTYPE = np.dtype([(key, np.float64) for key in dict.fromkeys(
    k for table in (REQUIRED, REQUIRED_52) for keys in table.values() for k in keys)]
    + [(key, np.float64) for key in SCALING + SCALING_61 + SCALING_52 + ("MF52",)])
#: The small number ε of 4.E6 that keeps the stiffness factors finite at zero load or friction.
_EPS = 1e-6
#: A_μ of 4.E8: the degressive scaling of friction's vertical shifts.
_A_MU = 10.0


def coefficients(tir: TirFile) -> np.record:
    """The Magic Formula 6.1 or 5.2 coefficients of ``tir`` (its FITTYP says which) as one record of
    :data:`DTYPE`. InputError naming the file, line, section and key for a missing coefficient, a
    non-positive nominal load, radius, pressure, stiffness, relaxation coefficient or low-speed
    limit, or a speed-dependent friction (``LMUV`` ≠ 0)."""
    mf52 = FITTYPS[tir.fittyp] == "MF 5.2"
    record = np.zeros(1, DTYPE)[0]
    for key, value in NEUTRAL_52.items():
        record[key] = value
    for section, keys in (REQUIRED_52 if mf52 else REQUIRED).items():
        for key in keys:
            record[key] = tir.number(section, key)
    own, other = (SCALING_52, SCALING_61) if mf52 else (SCALING_61, SCALING_52)
    for key in SCALING + own:
        record[key] = tir.number("SCALING_COEFFICIENTS", key, default=1.0)
    for key in other:
        record[key] = 1.0
    positive = [("VERTICAL", "FNOMIN"), ("DIMENSION", "UNLOADED_RADIUS"), ("VERTICAL", "VERTICAL_STIFFNESS"),
                ("MODEL", "LONGVL"), ("MODEL", "VXLOW"), ("SCALING_COEFFICIENTS", "LFZO")]
    if mf52:
        record["MF52"] = 1.0
        record["DAMP_VLOW"] = tir.number("STRUCTURAL", "DAMP_VLOW", default=DAMP_VLOW_52)
        positive += [("LONGITUDINAL_COEFFICIENTS", "PTX1"), ("LATERAL_COEFFICIENTS", "PTY1"),
                     ("LATERAL_COEFFICIENTS", "PTY2")]
    else:
        positive += [("OPERATING_CONDITIONS", "INFLPRES"), ("OPERATING_CONDITIONS", "NOMPRES"),
                     ("STRUCTURAL", "LONGITUDINAL_STIFFNESS"), ("STRUCTURAL", "LATERAL_STIFFNESS")]
    for section, key in positive:
        if not record[key] > 0.0:
            raise tir.error(section, key, f"{record[key]:g}: expected a positive number")
    if tir.number("SCALING_COEFFICIENTS", "LMUV", default=0.0) != 0.0:
        raise tir.error("SCALING_COEFFICIENTS", "LMUV", "friction's dependence on slip speed is not evaluated; "
                                                        "expected 0")
    vertical = (record["VERTICAL_STIFFNESS"] * record["UNLOADED_RADIUS"] / record["FNOMIN"]) ** 2
    if vertical <= 4.0 * record["Q_FZ2"]:
        raise tir.error("VERTICAL", "Q_FZ2", f"{record['Q_FZ2']:g} leaves no linear term in the load–deflection "
                                             f"law; expected below (VERTICAL_STIFFNESS·R0/FNOMIN)²/4 = {vertical / 4:g}")
    return record


@nb.njit(cache=True, inline="always")
def _sign(x: float) -> float:
    """sgn(x) with sgn(0) = 0, as the book's."""
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


@nb.njit(cache=True, inline="always")
def _nonzero_sign(x: float) -> float:
    """sgn(x) with sgn(0) = 1: the side a small ε is added on."""
    return -1.0 if x < 0.0 else 1.0


@nb.njit(cache=True, inline="always")
def _magic(b: float, c: float, e: float, x: float) -> float:
    """sin-free core of the Magic Formula: ``C·atan(B·x − E·(B·x − atan(B·x)))``."""
    return c * math.atan(b * x - e * (b * x - math.atan(b * x)))


@nb.njit(cache=True, inline="always")
def _normalised(p, fz: float) -> tuple[float, float, float]:
    """Scaled nominal load Fz0' [N] (4.E1), load and pressure increments dfz, dpi (4.E2)."""
    fz0 = p.FNOMIN * p.LFZO
    return fz0, (fz - fz0) / fz0, (p.INFLPRES - p.NOMPRES) / p.NOMPRES


@nb.njit(cache=True)
def low_speed_ramp(p, vx: float) -> float:
    """MF-Tyre's low-speed weighting: 0 at rest, 1 from ``VXLOW`` up, a half cosine between
    (continuous in value and slope). It scales the shifts S_Hx, S_Vx, S_Hy, S_Vy, so that a tyre
    standing still without slip pushes nowhere (no camber thrust, conicity or ply steer at rest);
    one minus it weights the low-speed damping (:func:`elastokin.tyres.transient.low_speed_damping`)."""
    speed = abs(vx)
    return 1.0 if speed >= p.VXLOW else 0.5 * (1.0 - math.cos(math.pi * speed / p.VXLOW))


@nb.njit(cache=True)
def _lateral_pure(p, fz: float, dfz: float, dpi: float, alpha_star: float, gamma_star: float, shifts: float):
    """Pure side slip (4.E19–4.E30): Fy0, K_yα, μy, B_y, C_y, S_Hy, S_Vy at the side force's camber
    ``gamma_star`` (γ_y); ``shifts`` scales S_Hy, S_Vy."""
    fz0 = p.FNOMIN * p.LFZO                                                                  # 4.E1
    lmuy_prime = _A_MU * p.LMUY / (1.0 + (_A_MU - 1.0) * p.LMUY)                             # 4.E8
    g2 = gamma_star * gamma_star
    kya = (p.PKY1 * fz0 * (1.0 + p.PPY1 * dpi) * (1.0 - p.PKY3 * abs(gamma_star))
           * math.sin(p.PKY4 * math.atan(fz / fz0 / ((p.PKY2 + p.PKY5 * g2) * (1.0 + p.PPY2 * dpi)))) * p.LKY)  # 4.E25
    svyg = fz * (p.PVY3 + p.PVY4 * dfz) * gamma_star * p.LKYC * lmuy_prime                  # 4.E28
    kyg0 = fz * (p.PKY6 + p.PKY7 * dfz) * (1.0 + p.PPY5 * dpi) * p.LKYC                     # 4.E30
    if p.MF52 > 0.0:
        camber_shift = p.PHY3 * gamma_star                                                   # MF 5.2
    else:
        camber_shift = (kyg0 * gamma_star - svyg) / (kya + _EPS * _nonzero_sign(kya))
    shy = ((p.PHY1 + p.PHY2 * dfz) * p.LHY + camber_shift) * shifts                          # 4.E27
    svy = (fz * (p.PVY1 + p.PVY2 * dfz) * p.LVY * lmuy_prime + svyg) * shifts               # 4.E29
    alpha_y = alpha_star + shy                                                               # 4.E20
    cy = p.PCY1 * p.LCY                                                                      # 4.E21
    muy = (p.PDY1 + p.PDY2 * dfz) * (1.0 + p.PPY3 * dpi + p.PPY4 * dpi * dpi) * (1.0 - p.PDY3 * g2) * p.LMUY  # 4.E23
    dy = muy * fz                                                                            # 4.E22
    ey = min((p.PEY1 + p.PEY2 * dfz) * (1.0 + p.PEY5 * g2 - (p.PEY3 + p.PEY4 * gamma_star) * _sign(alpha_y))
             * p.LEY, 1.0)                                                                   # 4.E24
    by = kya / (cy * dy + _EPS * _nonzero_sign(dy))                                          # 4.E26
    fy0 = dy * math.sin(_magic(by, cy, ey, alpha_y)) + svy                                   # 4.E19
    return fy0, kya, muy, by, cy, shy, svy


@nb.njit(cache=True)
def _longitudinal_pure(p, fz: float, dfz: float, dpi: float, kappa: float, gamma_star: float, shifts: float):
    """Pure longitudinal slip (4.E9–4.E18): Fx0 and K_xκ at the longitudinal force's camber
    ``gamma_star`` (γ_x); ``shifts`` scales S_Hx, S_Vx."""
    lmux_prime = _A_MU * p.LMUX / (1.0 + (_A_MU - 1.0) * p.LMUX)                             # 4.E8
    kappa_x = kappa + (p.PHX1 + p.PHX2 * dfz) * p.LHX * shifts                               # 4.E10, 4.E17
    cx = p.PCX1 * p.LCX                                                                      # 4.E11
    mux = ((p.PDX1 + p.PDX2 * dfz) * (1.0 + p.PPX3 * dpi + p.PPX4 * dpi * dpi)
           * (1.0 - p.PDX3 * gamma_star * gamma_star) * p.LMUX)                              # 4.E13
    dx = mux * fz                                                                            # 4.E12
    ex = min((p.PEX1 + p.PEX2 * dfz + p.PEX3 * dfz * dfz) * (1.0 - p.PEX4 * _sign(kappa_x)) * p.LEX, 1.0)  # 4.E14
    kxk = fz * (p.PKX1 + p.PKX2 * dfz) * math.exp(p.PKX3 * dfz) * (1.0 + p.PPX1 * dpi + p.PPX2 * dpi * dpi) * p.LKX  # 4.E15
    bx = kxk / (cx * dx + _EPS * _nonzero_sign(dx))                                          # 4.E16
    svx = fz * (p.PVX1 + p.PVX2 * dfz) * p.LVX * lmux_prime * shifts                         # 4.E18
    return dx * math.sin(_magic(bx, cx, ex, kappa_x)) + svx, kxk


@nb.njit(cache=True, inline="always")
def _weighting(b: float, c: float, e: float, shift: float, x: float) -> float:
    """Combined-slip weighting G (4.E53/4.E63): cos(C·atan(…x…)) over its value at the shift."""
    return math.cos(_magic(b, c, e, x)) / math.cos(_magic(b, c, e, shift))


@nb.njit(cache=True)
def forces(p, fz: float, kappa: float, alpha: float, gamma: float, vx: float):
    """Combined-slip forces and moments of one tyre (4.E50–4.E78): ``(Fx, Fy, Mz, My)`` [N, N·m] at
    vertical load ``fz`` [N], longitudinal slip ``kappa``, slip angle ``alpha`` and inclination
    ``gamma`` [rad], forward speed ``vx`` [m/s]. The tyre rolls forward: the book's sgn(V_cx) factors
    are +1 (a car at rest holds through the transient slips' deflections, not through the sign of a
    vanishing speed). Below ``VXLOW`` the curves' shifts fade out (:func:`low_speed_ramp`) and the
    rolling resistance, which opposes ``vx``, fades linearly to zero, so that a wheel at rest is not
    pushed. A tyre off the ground (``fz ≤ 0``) gives zeros."""
    if fz <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    fz0, dfz, dpi = _normalised(p, fz)
    alpha_star = math.tan(alpha)                                                             # 4.E3
    gamma_star = math.sin(gamma)                                                             # 4.E4
    # MF 5.2 scales the camber of each force (1 for 6.1): γ_x, γ_y, γ_z
    gx, gy, gz = gamma_star * p.LGAX, gamma_star * p.LGAY, gamma_star * p.LGAZ
    cos_alpha = math.cos(alpha)                                                              # 4.E6 (V_cx/V_c)
    shifts = low_speed_ramp(p, vx)
    fx0, kxk = _longitudinal_pure(p, fz, dfz, dpi, kappa, gx, shifts)
    fy0, kya, muy, by, cy, shy, svy = _lateral_pure(p, fz, dfz, dpi, alpha_star, gy, shifts)
    kya_prime = kya + _EPS * _nonzero_sign(kya)                                              # 4.E39

    # Fx in combined slip (4.E50–4.E57)
    bxa = (p.RBX1 + p.RBX3 * gx * gx) * math.cos(math.atan(p.RBX2 * kappa)) * p.LXAL        # 4.E54
    exa = min(p.REX1 + p.REX2 * dfz, 1.0)                                                    # 4.E56
    fx = _weighting(bxa, p.RCX1, exa, p.RHX1, alpha_star + p.RHX1) * fx0                     # 4.E50–4.E53, 4.E57

    # Fy in combined slip (4.E58–4.E67)
    dvyk = muy * fz * (p.RVY1 + p.RVY2 * dfz + p.RVY3 * gy) * math.cos(math.atan(p.RVY4 * alpha_star))  # 4.E67
    svyk = dvyk * math.sin(p.RVY5 * math.atan(p.RVY6 * kappa)) * p.LVYKA                     # 4.E66
    shyk = p.RHY1 + p.RHY2 * dfz                                                             # 4.E65
    byk = (p.RBY1 + p.RBY4 * gy * gy) * math.cos(math.atan(p.RBY2 * (alpha_star - p.RBY3))) * p.LYKA  # 4.E62
    eyk = min(p.REY1 + p.REY2 * dfz, 1.0)                                                    # 4.E64
    gyk = _weighting(byk, p.RCY1, eyk, shyk, kappa + shyk)                                   # 4.E59–4.E61, 4.E63
    fy = gyk * fy0 + svyk                                                                    # 4.E58

    # Mz in combined slip (4.E31–4.E49, 4.E71–4.E78)
    r0 = p.UNLOADED_RADIUS
    sht = p.QHZ1 + p.QHZ2 * dfz + (p.QHZ3 + p.QHZ4 * dfz) * gz                               # 4.E35
    alpha_t = alpha_star + sht                                                               # 4.E34
    alpha_r = alpha_star + shy + svy / kya_prime                                             # 4.E37, 4.E38
    bt = ((p.QBZ1 + p.QBZ2 * dfz + p.QBZ3 * dfz * dfz) * (1.0 + p.QBZ4 * gz + p.QBZ5 * abs(gz))
          * p.LKY / p.LMUY)                                                                  # 4.E40
    ct = p.QCZ1                                                                              # 4.E41
    peak_camber = gz if p.MF52 > 0.0 else abs(gz)                                            # 4.E43; MF 5.2: γ_z
    dt = (fz * (r0 / fz0) * (p.QDZ1 + p.QDZ2 * dfz) * (1.0 - p.PPZ1 * dpi) * p.LTR
          * (1.0 + p.QDZ3 * peak_camber + p.QDZ4 * gz * gz))                                 # 4.E42, 4.E43
    et = min((p.QEZ1 + p.QEZ2 * dfz + p.QEZ3 * dfz * dfz)
             * (1.0 + (p.QEZ4 + p.QEZ5 * gz) * (2.0 / math.pi) * math.atan(bt * ct * alpha_t)), 1.0)  # 4.E44
    br = p.QBZ9 * p.LKY / p.LMUY + p.QBZ10 * by * cy                                         # 4.E45
    dr = (fz * r0 * ((p.QDZ6 + p.QDZ7 * dfz) * p.LRES + ((p.QDZ8 + p.QDZ9 * dfz) * (1.0 + p.PPZ2 * dpi)
                                                          + (p.QDZ10 + p.QDZ11 * dfz) * abs(gz))
                     * gz * p.LKZC) * p.LMUY * cos_alpha)                           # 4.E47
    slip_ratio = (kxk / kya_prime) * kappa
    alpha_t_eq = math.sqrt(alpha_t * alpha_t + slip_ratio * slip_ratio) * _sign(alpha_t)    # 4.E77
    alpha_r_eq = math.sqrt(alpha_r * alpha_r + slip_ratio * slip_ratio) * _sign(alpha_r)    # 4.E78
    trail = dt * math.cos(_magic(bt, ct, et, alpha_t_eq)) * cos_alpha                        # 4.E73
    residual = dr * math.cos(math.atan(br * alpha_r_eq))                                     # 4.E75 (C_r = 1)
    if p.MF52 > 0.0:
        fy_trail = gyk * fy0                                       # MF 5.2: Fy − S_Vyκ, camber thrust included
    else:
        fy_trail = gyk * _lateral_pure(p, fz, dfz, dpi, alpha_star, 0.0, shifts)[0]          # 4.E74
    scrub = r0 * (p.SSZ1 + p.SSZ2 * fy / fz0 + (p.SSZ3 + p.SSZ4 * dfz) * gz) * p.LS          # 4.E76
    mz = -trail * fy_trail + residual + scrub * fx                                           # 4.E71, 4.E72

    # My, rolling resistance (4.E70), fading to zero at rest
    speed = vx / p.LONGVL
    my = (-r0 * fz0 * p.LMY * (p.QSY1 + p.QSY2 * fx / fz0 + p.QSY3 * abs(speed) + p.QSY4 * speed ** 4
                                 + (p.QSY5 + p.QSY6 * fz / fz0) * gamma * gamma)
          * (fz / fz0) ** p.QSY7 * (p.INFLPRES / p.NOMPRES) ** p.QSY8 * max(-1.0, min(1.0, vx / p.VXLOW)))
    return fx, fy, mz, my


@nb.njit(cache=True)
def slip_stiffnesses(p, fz: float, gamma: float) -> tuple[float, float]:
    """Slip stiffnesses at zero slip: ``(K_xκ [N], K_yα [N/rad])`` (4.E15, 4.E25) at load ``fz`` [N]
    and inclination ``gamma`` [rad]."""
    _, dfz, dpi = _normalised(p, fz)
    gamma_star = math.sin(gamma)
    return (_longitudinal_pure(p, fz, dfz, dpi, 0.0, gamma_star * p.LGAX, 1.0)[1],
            _lateral_pure(p, fz, dfz, dpi, 0.0, gamma_star * p.LGAY, 1.0)[1])


@nb.njit(cache=True)
def mf52_relaxation_lengths(p, fz: float, gamma: float) -> tuple[float, float]:
    """MF 5.2's relaxation lengths ``(σκ, σα)`` [m] at load ``fz`` [N] and inclination ``gamma``
    [rad] (MF-Tyre 5.2): ``σκ = Fz·(PTX1 + PTX2·dfz)·exp(−PTX3·dfz)·(R0/Fz0)·LSGKP``, ``σα =
    PTY1·sin(2·atan(Fz/(PTY2·Fz0')))·(1 − PKY3·|γ_y|)·R0·LFZO·LSGAL``."""
    fz0, dfz, _ = _normalised(p, fz)
    r0 = p.UNLOADED_RADIUS
    sigma_k = fz * (p.PTX1 + p.PTX2 * dfz) * math.exp(-p.PTX3 * dfz) * r0 / p.FNOMIN * p.LSGKP
    sigma_a = (p.PTY1 * math.sin(2.0 * math.atan(fz / (p.PTY2 * fz0))) * (1.0 - p.PKY3 * abs(math.sin(gamma) * p.LGAY))
               * r0 * p.LFZO * p.LSGAL)
    return sigma_k, sigma_a


@nb.njit(cache=True)
def carcass_stiffnesses(p, fz: float) -> tuple[float, float]:
    """The carcass's longitudinal and lateral stiffnesses [N/m] at load ``fz`` [N]: MF 6.1's
    [STRUCTURAL] keys with their load and pressure dependence (Besselink et al. 2010); for MF 5.2,
    which gives relaxation lengths instead, the slip stiffnesses over them (σ = K/C either way)."""
    if p.MF52 > 0.0:
        kxk, kya = slip_stiffnesses(p, fz, 0.0)
        sigma_k, sigma_a = mf52_relaxation_lengths(p, fz, 0.0)
        return abs(kxk) / sigma_k if sigma_k > 0.0 else 0.0, abs(kya) / sigma_a if sigma_a > 0.0 else 0.0
    _, dfz, dpi = _normalised(p, fz)
    cx = p.LONGITUDINAL_STIFFNESS * (1.0 + p.PCFX1 * dfz + p.PCFX2 * dfz * dfz) * (1.0 + p.PCFX3 * dpi)
    cy = p.LATERAL_STIFFNESS * (1.0 + p.PCFY1 * dfz + p.PCFY2 * dfz * dfz) * (1.0 + p.PCFY3 * dpi)
    return cx, cy


@nb.njit(cache=True)
def vertical_force(p, deflection: float, deflection_rate: float) -> float:
    """Vertical load [N] of the tyre pressed ``deflection`` [m] into a flat road at ``deflection_rate``
    [m/s] (MF 6.1: ``Fz = Fz0·(1 + PFZ1·dpi)·(q1·ρ/R0 + Q_FZ2·(ρ/R0)²)`` with q1 such that the
    stiffness at the nominal load is ``VERTICAL_STIFFNESS``, plus ``VERTICAL_DAMPING``·ρ̇; MF 5.2,
    without Q_FZ2 and PFZ1: ``VERTICAL_STIFFNESS``·ρ); never negative: the road pushes, it does not pull."""
    if deflection <= 0.0:
        return 0.0
    fz0 = p.FNOMIN
    x = deflection / p.UNLOADED_RADIUS
    q1 = math.sqrt((p.VERTICAL_STIFFNESS * p.UNLOADED_RADIUS / fz0) ** 2 - 4.0 * p.Q_FZ2)
    dpi = (p.INFLPRES - p.NOMPRES) / p.NOMPRES
    return max(0.0, fz0 * (1.0 + p.PFZ1 * dpi) * (q1 * x + p.Q_FZ2 * x * x) + p.VERTICAL_DAMPING * deflection_rate)


@nb.njit(cache=True)
def _evaluate(p, fz, kappa, alpha, gamma, vx, out) -> None:
    for i in range(fz.shape[0]):
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = forces(p, fz[i], kappa[i], alpha[i], gamma[i], vx[i])


def evaluate(p: np.record, fz, kappa=0.0, alpha=0.0, gamma=0.0, vx=None) -> dict[str, np.ndarray]:
    """:func:`forces` over arrays (broadcast together): ``{"Fx", "Fy", "Mz", "My"}`` [N, N·m]; ``vx``
    [m/s] defaults to the file's reference speed ``LONGVL``."""
    vx = p["LONGVL"] if vx is None else vx
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (fz, kappa, alpha, gamma, vx)))
    shape = arrays[0].shape
    fz_, kappa_, alpha_, gamma_, vx_ = (np.ascontiguousarray(a).ravel() for a in arrays)
    out = np.empty((fz_.size, 4))
    _evaluate(p, fz_, kappa_, alpha_, gamma_, vx_, out)
    return {name: out[:, j].reshape(shape) for j, name in enumerate(("Fx", "Fy", "Mz", "My"))}
