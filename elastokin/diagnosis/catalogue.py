"""The catalogue of causes (spec measured-data §2): each a physical extension of a bushing law with
few parameters, that the virtual rig can switch on in a truth model and the diagnosis can fit.

An extension acts on a parameter set as written in its YAML file (thesis units: N, mm, s; N·m and
deg for rotations), so that an extended model is written back as an ordinary parameter set usable
by ``vsim bushing run`` and by a vehicle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping

import numpy as np

from elastokin.bushings.effects import BROAD_TAUS_S, NO_EFFECTS, broad_relaxation_branches
from elastokin.bushings.parameter_sets import ParameterSet


@dataclass(frozen=True)
class Parameter:
    """One parameter of a cause, in the parameter sets' units."""

    name: str
    unit: str
    bounds: tuple[float, float]        #: fit bounds
    draw: tuple[float, float]          #: realistic magnitude range the virtual rig draws from
    signed: bool = False               #: the virtual rig draws either sign
    sided: bool = False                #: a signed parameter whose sign picks another effect, not the
    #: opposite one (asymmetry: which side stiffens): a linear fit cannot cross zero
    even_part: bool = False            #: a signed parameter whose effect has a part even in it (a cross
    #: stiffness softens both directions it couples, whatever its sign): a fit scaled from one sign's run
    #: misses the other's
    log: bool = False                  #: fitted on a log scale (positive, spans decades)
    factor: bool = False               #: a factor on a design value (1: no effect), whose effect grows
    #: with its logarithm (a log parameter otherwise has no effect at 0 and an effect growing with it)
    either_side: bool = False          #: a factor drawn above or below 1 alike (its draw range above 1)
    description: str = ""
    default: float | None = None       #: a family's shape parameter: its value in the family's first
    #: form, taken when a truth file leaves it out

    def __post_init__(self) -> None:
        if (self.sided or self.even_part) and not self.signed:
            raise ValueError(f"parameter {self.name}: sided or even_part needs signed (a fit on one sign's run "
                             f"must be free to take the other)")
        if self.either_side and not (self.factor and self.draw[0] > 1.0):
            raise ValueError(f"parameter {self.name}: either_side needs a factor drawn above 1")

    @property
    def signs(self) -> tuple[float, ...]:
        """The signs a hypothesis must be tried with: both for a sided parameter or one with an even
        part in its effect, else +1."""
        return (1.0, -1.0) if self.sided or self.even_part else (1.0,)

    def effect(self, value: float) -> float:
        """The coordinate the parameter's effect is taken proportional to: its logarithm for a factor,
        else the value itself."""
        return math.log(value) if self.factor else value

    def from_effect(self, x: float) -> float:
        """The value at effect coordinate ``x`` (the inverse of :meth:`effect`)."""
        return math.exp(x) if self.factor else x


@dataclass(frozen=True)
class Entry:
    """What the catalogue says of any cause: its physics, its signature in the data, its parameters."""

    id: str
    physics: str
    signature: str
    parameters: tuple[Parameter, ...]


@dataclass(frozen=True)
class Cause(Entry):
    """A cause in a bushing's law: which baselines it applies to, and how it extends them."""

    applies: Callable[[ParameterSet], bool]
    #: (params, effects, fitted values) -> extended (params, effects), all in parameter-set units
    extend: Callable[[dict[str, Any], dict[str, Any], Mapping[str, float]], tuple[dict[str, Any], dict[str, Any]]]
    #: a family's other forms alone: each the values that switch its first form off (and leave its shape
    #: parameters at rest), a start of the fits over the corners of the parameters it leaves
    #: (:func:`elastokin.diagnosis.fit_starts.corner_starts`): a fit from the first form's corners does not
    #: reach a form that needs them off
    other_forms: tuple[Mapping[str, float], ...] = ()

    def apply(self, base: ParameterSet, values: Mapping[str, float], source: str = "") -> ParameterSet:
        """The baseline set extended by this cause with ``values``."""
        params, effects = self.extend(dict(base.values), dict(base.effects), values)
        model = base.model
        if _ladder(base) and params.get("Co", 0.0) > 0.0:
            model = "stvs" if params.get("Ff", 0.0) > 0.0 else "rt"
        if model == "rt":
            params.pop("Ff", None)
        return ParameterSet(name=f"{base.name}+{self.id}", model=model, quantity=base.quantity, values=params,
                            source=source or f"{base.source}; extended by {self.id}", effects=effects)


def _ladder(base: ParameterSet) -> bool:
    return base.model in ("sts", "rt", "stvs")


def _elastic_law(base: ParameterSet) -> bool:
    return "N_sup" in base.values


def _add(mapping: dict[str, Any], key: str, value: float) -> dict[str, Any]:
    mapping[key] = mapping.get(key, 0.0) + value
    return mapping


def _viscosity(params: dict, effects: dict, v: Mapping[str, float]) -> tuple[dict, dict]:
    return {**params, "Co": v["Co"], "pw": v["pw"], "C": params.get("C", 0.0) + v.get("C", 0.0)}, effects


def _friction(params: dict, effects: dict, v: Mapping[str, float]) -> tuple[dict, dict]:
    # the interface only where the values give it a force (a K&C hypothesis fits the first two only)
    slip = {k: v[k] for k in ("slip_force", "slip_stiffness") if k in v} if v.get("slip_force", 0.0) > 0.0 else {}
    return {**params, "Ff": v["Ff"], "Co": params["Co"] * v["co_scale"]}, {**effects, **slip}


def _broad(params: dict, effects: dict, v: Mapping[str, float]) -> tuple[dict, dict]:
    k, c = broad_relaxation_branches(v["k1"], v["alpha"], v.get("broad_tau_end_s", math.inf))
    return {**params, "maxwell_k": [*params.get("maxwell_k", ()), *map(float, k)],
            "maxwell_c": [*params.get("maxwell_c", ()), *map(float, c)]}, effects


def _effect(key: str, parameter: str) -> Callable[[dict, dict, Mapping[str, float]], tuple[dict, dict]]:
    def extend(params: dict, effects: dict, v: Mapping[str, float]) -> tuple[dict, dict]:
        return params, _add(dict(effects), key, v[parameter])
    return extend


# A family's shape parameter left out (a hypothesis written before the family had it) is its first form.
def _asymmetry(params: dict, effects: dict, v: Mapping[str, float]) -> tuple[dict, dict]:
    step = v.get("asymmetry_step", NO_EFFECTS.asymmetry_step)
    power = v.get("asymmetry_power", NO_EFFECTS.asymmetry_power)
    width = {"asymmetry_step_width": v["asymmetry_step_width"]} if v.get("asymmetry_step_width") else {}
    return params, {**_add(_add(dict(effects), "asymmetry", v["asymmetry"]), "asymmetry_step", step),
                    "asymmetry_power": power, **width}


def _mullins(params: dict, effects: dict, v: Mapping[str, float]) -> tuple[dict, dict]:
    shape = v.get("mullins_shape", NO_EFFECTS.mullins_shape)
    return params, {**_add(dict(effects), "mullins", v["mullins"]), "mullins_shape": shape}


#: The keys of a law whose values are forces, or forces per deflection, speed or deflection's power:
#: what a harder or softer rubber scales alike (a curve's forces too; its deflections stay).
FORCE_KEYS = ("K0", "Kpa", "Kr", "Ff", "Co", "C", "P_sup", "P_inf", "maxwell_k", "maxwell_c")


def _stiffness(params: dict, effects: dict, v: Mapping[str, float]) -> tuple[dict, dict]:
    s = v["stiffness_scale"]
    out = {k: ([s * x for x in value] if isinstance(value, (list, tuple)) else s * value) if k in FORCE_KEYS else value
           for k, value in params.items()}
    if "curve" in params:
        out["curve"] = [[x, s * f] for x, f in params["curve"]]
    return out, {**effects, **({"slip_force": s * effects["slip_force"]} if "slip_force" in effects else {})}


def _heating(params: dict, effects: dict, v: Mapping[str, float]) -> tuple[dict, dict]:
    return params, {**_add(dict(effects), "heating", v["heating"]), "heating_tau_s": v["heating_tau_s"]}


CAUSES: dict[str, Cause] = {c.id: c for c in (
    # a family (issue 29): the rubber's rate dependence coupled to its hysteresis (the thesis's
    # dampers in the ladder) and a linear dashpot in parallel with the whole law (the Kelvin-Voigt
    # element, the damping C of the curve-based bushings of Adams/Car and Chrono::Vehicle)
    Cause("viscoelasticity_missing",
          "rate-dependent damping coupled to hysteresis: a power-law damper Co·|v|^pw at every ladder node "
          "(STS -> STVS), and a linear dashpot C in parallel with the law",
          "loop width and slope grow with loading speed; force relaxes after a step",
          (Parameter("Co", "N/(mm/s)^pw", (0.1, 300.0), (15.0, 40.0), log=True,
                     description="damper coefficient at every ladder node"),
           Parameter("pw", "-", (0.03, 1.0), (0.1, 0.3), description="damper exponent"),
           Parameter("C", "N·s/mm", (0.0, 10.0), (0.0, 1.0), default=0.0,
                     description="linear dashpot in parallel with the whole law")),
          lambda b: _ladder(b) and b.values.get("Co", 0.0) == 0.0, _viscosity,
          ({"Co": 0.1, "pw": 0.1},)),     # the dashpot alone: the ladder's dampers at their least
    # a family (issue 29): friction inside the rubber (the ladder's sliders, the thesis's STVS) and at
    # an interface of the part that slips as a whole (a Jenkins element, spring and Coulomb slider, in
    # parallel: Iwan 1966's element, the sharp limit of Berg 1998's), whose stiffness before slip sets
    # how round the loop's corners are (Dahl's and Bouc-Wen's smooth friction lie between its stiff
    # and soft ends)
    Cause("viscoelasticity_excess",
          "the part is less viscous and more hysteretic than an RT-like law: slider threshold Ff added at every "
          "ladder node, dampers scaled, and an interface that slips in parallel with the law",
          "simulated loops too round; measured hysteresis persists at low speed",
          (Parameter("Ff", "N", (0.0, 200.0), (5.0, 15.0), description="slider threshold added at every node"),
           Parameter("co_scale", "-", (0.02, 3.0), (0.4, 0.8), log=True, factor=True,
                     description="factor on the damper Co"),
           Parameter("slip_force", "N", (0.0, 200.0), (2.0, 10.0), default=0.0,
                     description="force at which an interface in parallel with the law slips"),
           Parameter("slip_stiffness", "-", (0.01, 5.0), (0.2, 0.5), log=True, default=1.0,
                     description="the interface's stiffness before it slips, a fraction of K0")),
          lambda b: _ladder(b) and b.values.get("Co", 0.0) > 0.0, _friction,
          ({"Ff": 0.0, "co_scale": 1.0},)),     # the slipping interface alone
    Cause("preload",
          "static load shifts the part's operating point along its nonlinear elastic law and leaves its "
          "hysteresis on a loading branch",
          "stiffness error that depends on static load, not on speed; loops not centred",
          (Parameter("preload", "mm", (-5.0, 5.0), (1.5, 3.0), signed=True, sided=True,
                     description="deflection of the mounted part at the rig's zero (2-4 kN of static load)"),),
          _elastic_law, _effect("preload", "preload")),
    # a family (issue 29): an elastomer stiffens progressively as it is compressed, a part with a stop
    # met gradually as a power of its deflection (bump stops' force laws grow as its square to its
    # fourth power), and a part with a void or a rate-limiting sleeve takes its extra stiffness at
    # once from zero deflection (a kink in its law; e.g. voided bushings, Kadlowec et al. 2003), or
    # over the fraction of a millimetre in which its void's faces come into contact (the kink's width)
    Cause("asymmetry",
          "tension/compression asymmetry beyond the elastic law: one side stiffer, from zero deflection "
          "(a kink, or a step spread over a width) and progressively, as a power of the deflection",
          "loops not point-symmetric about their centre",
          (Parameter("asymmetry", "1/mm", (-1.0, 1.0), (0.05, 0.15), signed=True, sided=True,
                     description="extra tangent fraction of K0 per mm at 1 mm; > 0 stiffens compression"),
           Parameter("asymmetry_step", "-", (-1.0, 1.0), (0.03, 0.10), signed=True, sided=True, default=0.0,
                     description="extra tangent fraction of K0 from zero deflection; > 0 stiffens compression"),
           Parameter("asymmetry_power", "-", (1.0, 3.0), (1.0, 2.0), default=1.0,
                     description="power n of the progressive part: the extra tangent grows as |x|^n"),
           Parameter("asymmetry_step_width", "mm", (0.0, 3.0), (0.2, 1.0), default=0.0,
                     description="width over which the step's extra tangent rises, centred on zero (0: a kink)")),
          lambda b: b.values.get("K0", 0.0) > 0.0, _asymmetry,
          ({"asymmetry": 0.0, "asymmetry_power": 1.0},)),     # the kink alone
    # the recovery's shape (issue 29): a power of |x|/x_max, 1 the linear recovery, as the families of
    # Ogden & Roxburgh (1999) and Dorfmann & Ogden (2004) bend it with the past maximum's energy
    Cause("mullins",
          "Mullins softening: the virgin part softens below the largest deflection it has seen, recovering "
          "towards it as a power of the deflection",
          "first cycle stiffer than the next; softening only below the previous maximum",
          (Parameter("mullins", "-", (0.0, 0.8), (0.08, 0.25), description="softening fraction at zero deflection"),
           Parameter("mullins_shape", "-", (1.0, 5.0), (1.0, 2.0), log=True, default=1.0,
                     description="power p of the recovery: softening mu*(1 - (|x|/x_max)^p)")),
          lambda b: True, _mullins),
    # the commonest deviation of a real part (issue 53): rubber hardness varies by a few Shore points
    # from batch to batch, its shear modulus and so every force of the part by ±10-25 %; a modulus
    # factor scales the whole law alike (a ladder's node speeds are then unchanged: the loop's shape
    # and its rate dependence stay), unlike an asymmetry (one side) or a Mullins softening (below the
    # largest deflection)
    Cause("stiffness",
          "the part's rubber harder or softer than the law's (a few Shore points from batch to batch): every "
          "force of the law scaled by one factor at the same deflection history (its stiffnesses, slider "
          "thresholds, dampers and elastic law alike)",
          "gradient, loop width and loop area off together by one factor, on both sides; the loops' shape and "
          "their speed dependence unchanged",
          (Parameter("stiffness_scale", "-", (0.3, 3.0), (1.1, 1.25), log=True, factor=True, either_side=True,
                     description="factor on every force of the law (drawn above or below 1)"),),
          lambda b: b.model not in ("sts_continuous", "stsn") and (b.values.get("K0", 0.0) > 0.0 or "curve" in b.values),
          _stiffness),
    Cause("self_heating",
          "dissipated energy heats the part; stiffness and viscous parameters fall with temperature",
          "slow drift of loops over many cycles, growing with amplitude x frequency",
          (Parameter("heating", "1/kJ", (1e-3, 5.0), (0.08, 0.2), log=True,
                     description="softening per kJ of heat held (beta / thermal capacity)"),
           Parameter("heating_tau_s", "s", (10.0, 5000.0), (100.0, 400.0), log=True,
                     description="thermal time constant")),
          lambda b: _ladder(b) or b.model == "tvs", _heating),
    Cause("broad_relaxation",
          f"relaxation over decades: a fractional element k1·t^-alpha in parallel (Prony series, "
          f"{len(BROAD_TAUS_S)} branches from {BROAD_TAUS_S[0]:g} to {BROAD_TAUS_S[-1]:g} s), its spectrum "
          f"cut off at a terminal time (Baumgaertel-Schausberger-Winter)",
          "log-time relaxation slope that a finite ladder cannot follow; stiffness rising with frequency",
          (Parameter("k1", "N/mm", (0.5, 2000.0), (30.0, 100.0), log=True, description="relaxation stiffness at 1 s"),
           Parameter("alpha", "-", (0.02, 0.9), (0.1, 0.25), description="order of the fractional element"),
           Parameter("broad_tau_end_s", "s", (1.0, 1e7), (1e5, 1e7), log=True, default=math.inf,
                     description="terminal relaxation time: the spectrum cut off beyond it")),
          lambda b: True, _broad,
          ({"broad_tau_end_s": 60.0},)),     # a spectrum that ends within the minute of a bench test
)}


#: Every parameter name belongs to one cause, so that two causes' values can share one mapping.
assert len({p.name for c in CAUSES.values() for p in c.parameters}) == sum(len(c.parameters) for c in CAUSES.values())
#: Joins the ids of two causes found together (ids use only letters and underscores).
PAIR_SEPARATOR = "+"


def combined(first: Cause, second: Cause) -> Cause:
    """Two causes at once, as one cause: the baseline extended by ``first``, then by ``second``, with
    both causes' parameters (id ``first+second``; :func:`parts` splits it back)."""
    def extend(params: dict, effects: dict, v: Mapping[str, float]) -> tuple[dict, dict]:
        return second.extend(*first.extend(params, effects, v), v)

    return Cause(f"{first.id}{PAIR_SEPARATOR}{second.id}", f"{first.physics}; and {second.physics}",
                 f"{first.signature}; and {second.signature}", first.parameters + second.parameters,
                 lambda b: first.applies(b) and second.applies(b), extend)


def parts(cause_id: str) -> list[Cause]:
    """The catalogue causes a (possibly combined, :func:`combined`) cause id names, in order."""
    return [CAUSES[i] for i in cause_id.split(PAIR_SEPARATOR)]


def applicable(base: ParameterSet) -> list[Cause]:
    """The causes that can extend this baseline (e.g. missing viscoelasticity only on an STS)."""
    return [c for c in CAUSES.values() if c.applies(base)]


def draw(cause: Cause, rng: np.random.Generator) -> dict[str, float]:
    """Values of a cause's parameters drawn in their realistic range (see :func:`draw_parameters`)."""
    return draw_parameters(cause.parameters, rng)


def draw_parameters(parameters: tuple[Parameter, ...], rng: np.random.Generator) -> dict[str, float]:
    """Parameter values drawn uniformly (log-uniformly for log parameters) in the realistic range;
    either sign for a signed parameter, one side for all the sided parameters of a family, above or
    below 1 for a factor drawn on either side."""
    out: dict[str, float] = {}
    side = None
    for p in parameters:
        lo, hi = p.draw
        value = float(np.exp(rng.uniform(np.log(lo), np.log(hi)))) if p.log else float(rng.uniform(lo, hi))
        if p.either_side and rng.random() < 0.5:
            value = 1.0 / value
        sign = 1.0
        if p.signed:
            sign = side if p.sided and side is not None else float(rng.choice([-1.0, 1.0]))
            side = sign if p.sided else side
        out[p.name] = value * sign
    return out
