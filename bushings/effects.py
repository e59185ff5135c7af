"""Physical extensions of a bushing force law that the thesis's models lack (spec bushings §6).

Two kinds, both switched on per channel and off by default:

* parameter extensions, which stay inside the ladder/Maxwell family and so only change a
  :class:`ChannelParams`: rate-dependent damping on the ladder nodes (:func:`with_viscosity`),
  slider friction on them (:func:`with_friction`), and broad-spectrum relaxation as a Prony series
  fitted to a fractional (power-law) relaxation modulus (:func:`with_broad_relaxation`);
* state extensions (:class:`Effects`): preload (operating-point shift), tension/compression
  asymmetry, Mullins softening, self-heating, a slipping interface and a backlash dead band,
  applied around the base law by the compiled wrapper of :mod:`elastokin.bushings.extended_bank`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, Mapping

import numpy as np

from elastokin.bushings.parameters import LENGTH_UNIT_SI, ChannelParams
from elastokin.core.errors import InputError


@dataclass(frozen=True)
class Effects:
    """State extensions of one channel's law (SI: m or rad, N or N·m, J, s); zeros switch them off.

    With ``x = e + preload`` (after the backlash dead band) the force is
    ``η_mullins(x)·η_heat(Q)·(F_base(x) + F_asym(x)) + F_slip − F_tare``, where F_slip is the force of a
    Jenkins element (a spring in series with a Coulomb slider: one element of Iwan's 1966 model, the
    sharp limit of Berg's 1998 smooth friction element) in parallel: an interface of the part that
    slips (a bonded sleeve, a clamped face), clamped unloaded at the mounted position. Its force is
    neither softened by η nor does its dissipation heat the part: it acts at a face, not in the
    rubber. In a backlash dead band the part is held at x = 0, where a hysteretic law and the
    interface keep the force they had there.
    """

    preload: float = 0.0          #: operating point of the mounted part on its law [m or rad]
    asymmetry: float = 0.0        #: extra tangent fraction per unit deflection on one side, at the
    #: parameter sets' unit of deflection r (1 mm or 1 deg) [1/m or 1/rad]; > 0 stiffens compression
    #: (x < 0), < 0 tension: on that side the tangent grows by |a|·K0·r·(|x|/r)^n,
    #: F_asym = |a|·K0·r·(|x|/r)^n·x/(n + 1)
    asymmetry_power: float = 1.0  #: n >= 1, how the progressive part grows (1: the tangent in proportion
    #: to the deflection; 2: as its square, a stop met gradually)
    asymmetry_step: float = 0.0   #: extra tangent fraction from zero deflection on one side [-] (a kink
    #: in the law), signs as ``asymmetry``: F_asym += |s|·K0·x on that side
    asymmetry_step_width: float = 0.0   #: width w over which the step's extra tangent rises linearly,
    #: centred on zero deflection [m or rad] (0: a kink; > 0 a part whose voids close gradually): the
    #: fraction 1/2 + u/w of |s|·K0 for |u| < w/2, u the deflection towards the stiffened side
    mullins: float = 0.0          #: softening μ below the largest |x| seen: η = 1 − μ(1 − (|x|/x_max)^p)
    mullins_shape: float = 1.0    #: p >= 1, the shape of the recovery towards x_max (1: linear; > 1: the
    #: part stays soft further up; < 1 would make the force's slope infinite at x = 0)
    heating: float = 0.0          #: softening per joule of heat held, κ = β/C_th [1/J]: η = 1/(1 + κQ)
    heating_tau_s: float = 300.0  #: thermal time constant of the heat held Q [s]
    slip_force: float = 0.0       #: force at which the parallel interface slips [N or N·m]
    slip_stiffness: float = 1.0   #: the interface's stiffness before it slips, a fraction of K0 [-]
    backlash: float = 0.0         #: half-width of a dead band in series with the part [m or rad]

    @property
    def active(self) -> bool:
        """True when any effect is switched on."""
        return any(getattr(self, f.name) != 0.0 for f in fields(self) if f.name not in _SETTINGS)


#: Fields that shape an effect but switch none on.
_SETTINGS = ("heating_tau_s", "mullins_shape", "asymmetry_power", "asymmetry_step_width", "slip_stiffness")
#: Largest power of an asymmetry's progressive part: a stop's force grows at most as the fourth power
#: of its deflection; beyond, a typing error (and overflow far from the reference deflection).
MAX_ASYMMETRY_POWER = 5.0
NO_EFFECTS = Effects()

#: Parameter-set ``effects`` keys -> (Effects field, power of the length unit, unit for translations,
#: unit for rotations, lower bound). Lengths are in mm (or deg), heat in kJ, as in the parameter sets.
EFFECT_KEYS: dict[str, tuple[str, int, str, str, float]] = {
    "preload": ("preload", 1, "mm", "deg", -math.inf),
    "asymmetry": ("asymmetry", -1, "1/mm", "1/deg", -math.inf),
    "asymmetry_step": ("asymmetry_step", 0, "-", "-", -math.inf),
    "asymmetry_power": ("asymmetry_power", 0, "-", "-", 1.0),
    "asymmetry_step_width": ("asymmetry_step_width", 1, "mm", "deg", 0.0),
    "mullins": ("mullins", 0, "-", "-", 0.0),
    "mullins_shape": ("mullins_shape", 0, "-", "-", 1.0),
    "heating": ("heating", 0, "1/kJ", "1/kJ", 0.0),
    "heating_tau_s": ("heating_tau_s", 0, "s", "s", 1e-9),
    "slip_force": ("slip_force", 0, "N", "N·m", 0.0),
    "slip_stiffness": ("slip_stiffness", 0, "-", "-", 1e-9),
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
    if si.get("asymmetry_power", 1.0) > MAX_ASYMMETRY_POWER:
        raise InputError(f"expected asymmetry_power <= {MAX_ASYMMETRY_POWER:g}, got {values['asymmetry_power']!r}",
                         source=source, key="effects.asymmetry_power")
    return Effects(**si)


def with_viscosity(ch: ChannelParams, Co: float, pw: float) -> ChannelParams:
    """The ladder with power-law dampers Co·|v|^pw [N/(m/s)^pw] at every node (STS → STVS)."""
    return ch.replace(model="stvs" if ch.Ff > 0.0 else "rt", Co=Co, pw=pw)


def with_friction(ch: ChannelParams, Ff: float, co_scale: float = 1.0) -> ChannelParams:
    """The ladder with slider threshold Ff [N] at every node and its dampers scaled (RT → STVS)."""
    return ch.replace(model="stvs" if Ff > 0.0 else ch.model, Ff=Ff, Co=ch.Co * co_scale)


#: Relaxation times of the broad-spectrum Prony series [s]: two per decade from 1 ms to 10⁴ s.
BROAD_TAUS_S = np.logspace(-3, 4, 15)


def broad_relaxation_branches(k1: float, alpha: float, tau_end_s: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
    """Maxwell branches (stiffnesses [N/m], damper rates [N·s/m]) whose relaxation modulus follows
    ``k1·t^−α`` (a fractional element, ``k1`` its stiffness at t = 1 s) within 5 % from 10 ms to 100 s.

    From t^−α = (1/Γ(α))·∫ τ^−α e^{−t/τ} d ln τ, discretised on the log-spaced :data:`BROAD_TAUS_S`;
    the tail beyond the longest time, ∫ τ^−α d ln τ = τ_max^−α/α, is lumped into the longest branch.
    A terminal time ``tau_end_s`` [s] cuts the spectrum off as e^{−τ/τ_end} (the spectrum of
    Baumgaertel, Schausberger and Winter (1990), here with an exponential cut-off): well below τ_end
    the modulus falls at the power law's rate, less the stiffness the cut branches held, and beyond it
    relaxes fully; ∞, none. Branches cut to below 1e−12 of their stiffness are left out (a branch
    without stiffness has no relaxation time).
    """
    taus = BROAD_TAUS_S
    cut = np.exp(-taus / tau_end_s)
    k = k1 / math.gamma(alpha) * taus ** (-alpha) * math.log(taus[1] / taus[0]) * cut
    k[-1] += k1 / math.gamma(alpha) * taus[-1] ** (-alpha) / alpha * cut[-1]
    kept = cut > 1e-12
    return k[kept], (k * taus)[kept]


def with_broad_relaxation(ch: ChannelParams, k1: float, alpha: float, tau_end_s: float = math.inf) -> ChannelParams:
    """The law with a parallel fractional element of relaxation stiffness k1 [N/m] at 1 s and order α,
    its spectrum cut off at the terminal time ``tau_end_s`` [s] (:func:`broad_relaxation_branches`)."""
    k, c = broad_relaxation_branches(k1, alpha, tau_end_s)
    return ch.replace(maxwell_k=ch.maxwell_k + tuple(k), maxwell_c=ch.maxwell_c + tuple(c))
