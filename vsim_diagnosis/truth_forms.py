"""Other forms of catalogued effects, that the virtual bench can hide (issue 29): each written here
apart from the catalogue's families (``bushings.extended_bank``), as a change of the measured part's
force along its deflection history, so that a test of "another form" cannot pass by fitting the
very formula that made the data. Two of them the diagnosis's families can write (written apart all
the same): ``asymmetry_cubic``, the asymmetry family's power 2, and ``viscous_parallel``, the
viscous family's dashpot (the family keeps a little ladder damping, Co ≥ 0.1).

* ``asymmetry_cubic``: one side stiffens as the square of the deflection (a bushing whose rubber
  reaches a stop gradually), F += |c|·K0·x³/3 on that side;
* ``asymmetry_exponential``: one side stiffens exponentially (a hyperelastic law of Fung's kind),
  tangent += |s|·K0·(exp(|x|/w) − 1) on that side;
* ``asymmetry_smooth_kink``: one side stiffer from about zero deflection, the step in tangent
  smoothed over a width w (a voided bushing closing its voids), tangent += |s|·K0·σ(∓x/w);
* ``mullins_ogden``: Ogden–Roxburgh (1999) softening, η = 1 − erf((W_max − W)/(β·W_max))/r with
  the elastic energy W ∝ x² and its largest value so far W_max;
* ``viscous_parallel``: a linear dashpot in parallel with the whole law (the Kelvin–Voigt element,
  the simplest viscoelastic solid), F += c·dx/dt.

Signs as the catalogue's: a positive c or s stiffens compression (x < 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np
from scipy.special import erf

from vsim_core.units import MM, MM_PER_M
from vsim_diagnosis.catalogue import Parameter


@dataclass(frozen=True)
class Form:
    """Another form of the catalogue cause ``family``: its parameters (parameter-set units) and the
    measured force it makes of the law's force along a deflection history."""

    id: str
    family: str
    physics: str
    parameters: tuple[Parameter, ...]
    #: (deflections [m] every dt_s, law's forces [N], K0 [N/m], values, state kept from test to test,
    #: dt_s [s]) -> forces [N]
    change: Callable[[np.ndarray, np.ndarray, float, Mapping[str, float], dict, float], np.ndarray]


def _stiff_side(x: np.ndarray, sign: float) -> np.ndarray:
    """Deflections as seen from the side a positive parameter stiffens (compression, x < 0)."""
    return -x if sign > 0.0 else x


def _cubic(x, force, k0, v, state, dt_s):
    c = v["asymmetry_cubic"] / MM ** 2
    side = _stiff_side(x, c)
    return force - c * k0 * np.where(side > 0.0, side, 0.0) ** 3 / 3.0   # c > 0: more compressive force


def _exponential(x, force, k0, v, state, dt_s):
    s, w = v["asymmetry_exp"], v["exp_length_mm"] * MM
    u = np.maximum(_stiff_side(x, s), 0.0)
    return force - s * k0 * w * (np.expm1(u / w) - u / w)


def _smooth_kink(x, force, k0, v, state, dt_s):
    s, w = v["asymmetry_kink"], v["kink_width_mm"] * MM
    side = _stiff_side(x, s)
    # ∫ σ(u/w) du from 0 to side: w·(softplus(side/w) − ln 2), taken stably for large |side|/w
    grown = w * (np.logaddexp(0.0, side / w) - math.log(2.0))
    return force - s * k0 * grown


def _ogden(x, force, k0, v, state, dt_s):
    r, beta = v["ogden_r"], v["ogden_beta"]
    energy = x ** 2
    peak = np.maximum.accumulate(np.maximum(energy, state.get("peak", 0.0)))
    state["peak"] = float(peak[-1]) if len(peak) else state.get("peak", 0.0)
    eta = 1.0 - erf(np.divide(peak - energy, beta * peak, out=np.zeros_like(energy), where=peak > 0.0)) / r
    return force * eta


def _viscous(x, force, k0, v, state, dt_s):
    return force + v["dashpot"] * MM_PER_M * np.gradient(x, dt_s) if len(x) > 1 else force


FORMS: dict[str, Form] = {f.id: f for f in (
    Form("asymmetry_cubic", "asymmetry", "one side stiffens as the square of the deflection",
         (Parameter("asymmetry_cubic", "1/mm^2", (-1.0, 1.0), (0.02, 0.06), signed=True, sided=True,
                    description="extra tangent fraction of K0 per mm²; > 0 stiffens compression"),),
         _cubic),
    Form("asymmetry_exponential", "asymmetry", "one side stiffens exponentially with the deflection",
         (Parameter("asymmetry_exp", "-", (-1.0, 1.0), (0.01, 0.04), signed=True, sided=True,
                    description="scale of the extra tangent, a fraction of K0; > 0 stiffens compression"),
          Parameter("exp_length_mm", "mm", (0.2, 10.0), (1.0, 2.0), description="deflection of an e-fold growth")),
         _exponential),
    Form("asymmetry_smooth_kink", "asymmetry", "one side stiffer from about zero deflection, smoothed over a width",
         (Parameter("asymmetry_kink", "-", (-1.0, 1.0), (0.08, 0.2), signed=True, sided=True,
                    description="extra tangent fraction of K0 well inside the stiff side"),
          Parameter("kink_width_mm", "mm", (0.01, 1.0), (0.05, 0.2), description="width of the smoothed step")),
         _smooth_kink),
    Form("mullins_ogden", "mullins", "Ogden-Roxburgh softening below the largest elastic energy so far",
         (Parameter("ogden_r", "-", (1.0, 100.0), (3.0, 8.0), description="1/r: the largest softening fraction"),
          Parameter("ogden_beta", "-", (0.05, 10.0), (0.5, 1.5), description="width of the recovery, in W_max")),
         _ogden),
    Form("viscous_parallel", "viscoelasticity_missing", "a linear dashpot in parallel with the whole law",
         (Parameter("dashpot", "N·s/mm", (0.01, 10.0), (0.3, 1.0), log=True, description="damping coefficient"),),
         _viscous),
)}
