"""Other forms of catalogued effects, that the virtual bench can hide (issue 29): each written here
apart from the catalogue's families (``elastokin.bushings.extended_bank``), as a change of the measured part's
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
  the simplest viscoelastic solid), F += c·dx/dt;
* ``dahl_parallel``: Dahl's friction element in parallel with the whole law (rate-independent
  hysteresis of one slipping interface, not the ladder's sliders), dF_d/dx = σ·(1 − F_d/F_c·sgn ẋ);
* ``heating_two_node``: the heat the law dissipates (before its softening, as the catalogue's
  self-heating takes it) feeds a core that passes it to a shell that loses it to the air (a
  two-node thermal network, two time constants where the family has one), and the force softens
  exponentially with the core's heat, η = exp(−κ·Q_core);
* ``relaxation_box``: relaxation with a box spectrum, moduli spread evenly over log τ from 10 ms to
  τ_max (Tobolsky's box: a force falling linearly with log t, where the family's is a power of t cut off
  exponentially at its terminal time).

Signs as the catalogue's: a positive c or s stiffens compression (x < 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numba as nb
import numpy as np
from scipy.linalg import expm
from scipy.signal import lfilter
from scipy.special import erf

from elastokin.core.units import MM, MM_PER_M
from elastokin.diagnosis.catalogue import Parameter

#: The box spectrum's shortest relaxation time [s] and its branches per decade (relaxation_box).
BOX_TAU_MIN_S = 0.01
BOX_PER_DECADE = 3


@dataclass(frozen=True)
class Form:
    """Another form of the catalogue cause ``family``: its parameters (parameter-set units) and the
    measured force it makes of the law's force along a deflection history."""

    id: str
    family: str
    physics: str
    parameters: tuple[Parameter, ...]
    #: (deflections [m] every dt_s, law's forces [N], K0 [N/m], values, state kept from test to test,
    #: dt_s [s], rest at zero deflection before the test [s]) -> forces [N]
    change: Callable[[np.ndarray, np.ndarray, float, Mapping[str, float], dict, float, float], np.ndarray]


def _stiff_side(x: np.ndarray, sign: float) -> np.ndarray:
    """Deflections as seen from the side a positive parameter stiffens (compression, x < 0)."""
    return -x if sign > 0.0 else x


def _cubic(x, force, k0, v, state, dt_s, rest_s):
    c = v["asymmetry_cubic"] / MM ** 2
    side = _stiff_side(x, c)
    return force - c * k0 * np.where(side > 0.0, side, 0.0) ** 3 / 3.0   # c > 0: more compressive force


def _exponential(x, force, k0, v, state, dt_s, rest_s):
    s, w = v["asymmetry_exp"], v["exp_length_mm"] * MM
    u = np.maximum(_stiff_side(x, s), 0.0)
    return force - s * k0 * w * (np.expm1(u / w) - u / w)


def _smooth_kink(x, force, k0, v, state, dt_s, rest_s):
    s, w = v["asymmetry_kink"], v["kink_width_mm"] * MM
    side = _stiff_side(x, s)
    # ∫ σ(u/w) du from 0 to side: w·(softplus(side/w) − ln 2), taken stably for large |side|/w
    grown = w * (np.logaddexp(0.0, side / w) - math.log(2.0))
    return force - s * k0 * grown


def _ogden(x, force, k0, v, state, dt_s, rest_s):
    r, beta = v["ogden_r"], v["ogden_beta"]
    energy = x ** 2
    peak = np.maximum.accumulate(np.maximum(energy, state.get("peak", 0.0)))
    state["peak"] = float(peak[-1]) if len(peak) else state.get("peak", 0.0)
    eta = 1.0 - erf(np.divide(peak - energy, beta * peak, out=np.zeros_like(energy), where=peak > 0.0)) / r
    return force * eta


def _viscous(x, force, k0, v, state, dt_s, rest_s):
    return force + v["dashpot"] * MM_PER_M * np.gradient(x, dt_s) if len(x) > 1 else force


@nb.njit(cache=True)
def _dahl_run(dx: np.ndarray, f0: float, sigma: float, fc: float) -> np.ndarray:
    """Dahl's friction force after each deflection increment dx [m], from f0 [N]: the exact solution
    of dF/dx = σ·(1 − F/F_c·sgn dx) over each increment."""
    out = np.empty(len(dx))
    f = f0
    for i in range(len(dx)):
        if dx[i] != 0.0:
            target = fc if dx[i] > 0.0 else -fc
            f = target - (target - f) * math.exp(-sigma * abs(dx[i]) / fc)
        out[i] = f
    return out


def _dahl(x, force, k0, v, state, dt_s, rest_s):
    fc, sigma = v["dahl_force"], v["dahl_stiffness"] * k0
    if fc <= 0.0:   # no friction force: no element
        return force
    x_last, f = state.get("x", 0.0), state.get("f", 0.0)
    if rest_s > 0.0:   # held at zero deflection before the test: the element followed it there
        f = _dahl_run(np.array([-x_last]), f, sigma, fc)[0]
        x_last = 0.0
    friction = _dahl_run(np.diff(x, prepend=x_last), f, sigma, fc)
    if len(x):
        state["x"], state["f"] = float(x[-1]), float(friction[-1])
    return force + friction


def _network(core_tau_s: float, shell_tau_s: float) -> np.ndarray:
    """Rates of the two-node network on (core, shell) heat [1/s]: core to shell with core_tau_s,
    shell to the air with shell_tau_s."""
    return np.array([[-1.0 / core_tau_s, 1.0 / core_tau_s],
                     [1.0 / core_tau_s, -1.0 / core_tau_s - 1.0 / shell_tau_s]])


@nb.njit(cache=True)
def _network_run(heat_in: np.ndarray, held: np.ndarray, step: np.ndarray, feed: np.ndarray) -> np.ndarray:
    """Core heat [J] after each sample: held ← step·held + feed·heat_in (the exact discrete network)."""
    out = np.empty(len(heat_in))
    q = held.copy()
    for i in range(len(heat_in)):
        q = step @ q + feed * heat_in[i]
        out[i] = q[0]
    held[:] = q
    return out


def _two_node(x, force, k0, v, state, dt_s, rest_s):
    rates = _network(v["core_tau_s"], v["shell_tau_s"])
    held = expm(rates * rest_s) @ state.get("held", np.zeros(2))
    # Heat dissipated [J] by the law before softening: the work done less the energy held
    # elastically, taken as the secant's ½·F·x (exact for a spring; bounded, not accumulating, for
    # the hysteretic law).
    work = np.concatenate([[0.0], np.cumsum(0.5 * (force[1:] + force[:-1]) * np.diff(x))])
    dissipated = work - 0.5 * force * x
    heat_in = np.diff(dissipated, prepend=dissipated[:1])
    step = expm(rates * dt_s)
    feed = np.linalg.solve(rates, step - np.eye(2))[:, 0] / dt_s   # a constant power over the sample
    core = _network_run(heat_in, held, step, feed)
    state["held"] = held
    return force * np.exp(-v["heating_exp"] * 1e-3 * np.maximum(core, 0.0))


def box_taus(tau_max_s: float) -> np.ndarray:
    """Relaxation times [s] of the box spectrum's branches up to ``tau_max_s``: BOX_PER_DECADE a
    decade from BOX_TAU_MIN_S, at the middle of each slice of log τ."""
    taus = BOX_TAU_MIN_S * 10.0 ** ((np.arange(BOX_PER_DECADE * 12) + 0.5) / BOX_PER_DECADE)
    return taus[taus < tau_max_s]


def _box(x, force, k0, v, state, dt_s, rest_s):
    taus = box_taus(v["box_tau_max_s"])
    k = v["box_k"] * MM_PER_M / len(taus)   # N/m each branch
    branch = state.get("branch", np.zeros(len(taus)))
    x_last = state.get("x", 0.0)
    if rest_s > 0.0:   # back to zero deflection, then relaxing at rest
        branch = (branch - k * x_last) * np.exp(-rest_s / taus)
        x_last = 0.0
    dx = np.diff(x, prepend=x_last)
    out = np.empty((len(taus), len(x)))
    for i, tau in enumerate(taus):
        a = math.exp(-dt_s / tau)
        # dF/dt = k·dx/dt − F/τ with dx/dt constant over the sample: the exact update
        out[i] = lfilter([k * tau / dt_s * (1.0 - a)], [1.0, -a], dx, zi=[a * branch[i]])[0]
    if len(x):
        state["branch"], state["x"] = out[:, -1].copy(), float(x[-1])
    return force + out.sum(axis=0)


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
    Form("dahl_parallel", "viscoelasticity_excess", "Dahl's friction element in parallel with the whole law",
         (Parameter("dahl_force", "N", (0.0, 200.0), (5.0, 15.0), description="friction force F_c at full slip"),
          Parameter("dahl_stiffness", "-", (0.01, 5.0), (0.2, 0.5), log=True,
                    description="the element's stiffness before slip σ, a fraction of K0")),
         _dahl),
    Form("heating_two_node", "self_heating", "heat through a core and a shell, exponential softening",
         (Parameter("heating_exp", "1/kJ", (1e-3, 5.0), (0.08, 0.2), log=True,
                    description="softening exponent per kJ held in the core"),
          Parameter("core_tau_s", "s", (1.0, 1000.0), (20.0, 60.0), log=True, description="core to shell"),
          Parameter("shell_tau_s", "s", (10.0, 10000.0), (300.0, 1000.0), log=True, description="shell to the air")),
         _two_node),
    Form("relaxation_box", "broad_relaxation", "a box relaxation spectrum, even over log τ from 10 ms to τ_max",
         (Parameter("box_k", "N/mm", (1.0, 2000.0), (40.0, 150.0), log=True,
                    description="stiffness spread over the spectrum"),
          Parameter("box_tau_max_s", "s", (0.1, 1e4), (30.0, 300.0), log=True, description="longest relaxation time")),
         _box),
)}
