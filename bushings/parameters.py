"""Bushing channel parameters: the model catalogue and the conversion from the thesis's units to SI.

Parameter values are written in the thesis's units (N, mm, s for translations; N·m, deg, s for
rotations) and converted to SI exactly once, here, when a :class:`ChannelParams` is built.
Everything downstream (kernels, bank, vehicle) is SI: N, m, s or N·m, rad, s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, Mapping

import numpy as np

from elastokin.core import units
from elastokin.core.errors import InputError

#: Number of ladder cells when a set does not say (the thesis's choice for 0.05–2 mm).
DEFAULT_CELLS = 15
#: Most ladder cells a channel may have (the kernel's ladder rows are sized for it).
MAX_CELLS = 200
#: Largest magnitude of any parameter in the thesis units (N, mm, s; N·m, deg): a stiffness of 1e9 N/mm
#: or a force of 1e9 N is a unit or typing error, not a bushing.
MAX_MAGNITUDE = 1e9
#: Smallest power-law exponent: the damper's inverse law v ∝ F^(1/pw) is then already a slider of
#: exponent 33; below it the implicit step fails to converge on ordinary loads (measured at 0.02).
PW_MIN = 0.03

#: Each parameter's dimension: the power of the length unit L in value_SI = value_user · L**power, and
#: its unit with F the force unit (N, or N·m for rotations) and L the length unit (mm, or deg). Co has
#: dimension F/(L/s)**pw, handled in to_si().
_PARAMETERS: dict[str, tuple[int | None, str]] = {
    "K0": (-1, "{F}/{L}"), "C": (-1, "{F}·s/{L}"), "Kpa": (-1, "{F}/{L}"), "Kr": (-1, "{F}/{L}"), "Ff": (0, "{F}"),
    "Co": (None, "{F}/({L}/s)^pw"), "pw": (0, ""), "N": (0, ""),
    "N_sup": (1, "{L}"), "N_inf": (1, "{L}"), "S_sup": (1, "{L}"), "S_inf": (1, "{L}"), "P_sup": (0, "{F}"),
    "P_inf": (0, "{F}"), "Ct": (-1, "{F}^n/{L}"), "n": (0, ""), "maxwell_k": (-1, "{F}/{L}"),
    "maxwell_c": (-1, "{F}·s/{L}"), "curve": (None, "[{L}, {F}] points"),
}

#: The nonlinear elastic law's keys (beside K0).
ELASTIC_KEYS = _ELASTIC_KEYS = ("N_sup", "N_inf", "S_sup", "S_inf", "P_sup", "P_inf")
# Parallel Maxwell branches: the TVS's viscoelastic part, and broad-spectrum relaxation on any law.
_MAXWELL_KEYS = ("maxwell_k", "maxwell_c")

#: model name -> (required keys, optional keys) in the user-facing parameter mapping.
MODELS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "linear": (("K0",), ("C",) + _ELASTIC_KEYS + _MAXWELL_KEYS),
    "elastic": (("K0",) + _ELASTIC_KEYS, ("C",) + _MAXWELL_KEYS),
    "sts": (("K0", "Kpa", "Kr", "Ff"), ("N", "C") + _ELASTIC_KEYS + _MAXWELL_KEYS),
    "sts_continuous": (("K0", "Kpa", "Ct"), ("C",) + _ELASTIC_KEYS + _MAXWELL_KEYS),
    "stsn": (("K0", "Kpa", "Ct", "n"), ("C",) + _ELASTIC_KEYS + _MAXWELL_KEYS),
    "rt": (("K0", "Kpa", "Kr", "Co", "pw"), ("N", "C") + _ELASTIC_KEYS + _MAXWELL_KEYS),
    "stvs": (("K0", "Kpa", "Kr", "Ff", "Co", "pw"), ("N", "C") + _ELASTIC_KEYS + _MAXWELL_KEYS),
    "tvs": (("K0", "Kpa", "Kr", "Ff") + _MAXWELL_KEYS, ("N", "C") + _ELASTIC_KEYS),
    "curve": (("curve",), ("C",) + _MAXWELL_KEYS),
}
#: Most points of a tabulated elastic law (``curve``).
MAX_CURVE_POINTS = 1000
#: The ladder models whose elastic law may be a ``curve`` in place of K0 and the elastic keys.
CURVE_ELASTIC = ("sts", "sts_continuous", "stsn", "rt", "stvs", "tvs")


def model_keys(model: str, values: Mapping[str, Any] | None = None) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The keys of a model's parameters.

    Args:
        model: a key of :data:`MODELS`.
        values: the parameters given, or None.

    Returns:
        (required, optional) keys: :data:`MODELS`'s, with a ladder's K0 and elastic keys replaced
        by ``curve`` when ``values`` give one (``curve`` optional otherwise).
    """
    required, optional = MODELS[model]
    if model in CURVE_ELASTIC and values is not None and "curve" in values:
        return (tuple(k for k in required if k != "K0"),
                tuple(k for k in optional if k not in _ELASTIC_KEYS) + ("curve",))
    return required, optional + (("curve",) if model in CURVE_ELASTIC else ())

#: The models the bench identification fits (all their required parameters, N fixed): a constant
#: here, so that the command line lists them without importing the fit (and scipy).
FITTED_MODELS = ("sts", "rt", "stvs")

#: Length unit of user-facing parameter values, per quantity, in SI.
LENGTH_UNIT_SI = {"translation": units.si("mm"), "rotation": units.si("deg")}
UNIT_LABELS = {"translation": ("N", "mm"), "rotation": ("N·m", "deg")}


def parameter_unit(key: str, quantity: str = "translation") -> str:
    """The unit a parameter is written in (``N/mm`` for K0 of a translation, ``N·m/deg`` of a rotation)."""
    force, length = UNIT_LABELS[quantity]
    return _PARAMETERS[key][1].format(F=force, L=length)


@dataclass(frozen=True)
class ChannelParams:
    """One bushing direction's force law, in SI (N, m, s; or N·m, rad, s for rotations).

    The force is ``F = F_el(e) + C·de/dt + ladder(e) + Σ maxwell_j(e)`` (or the continuous
    STS hysteresis instead of the ladder). ``n_cells = 0`` means no ladder. A ``curve`` law's
    ``F_el`` is its tabulated curve (``curve`` nodes), and ``K0`` the curve's slope at zero.
    """

    model: str
    quantity: str = "translation"
    K0: float = 0.0                 #: linear (large-amplitude) stiffness [N/m]
    C: float = 0.0                  #: parallel linear damping [N·s/m]
    N_sup: float = math.inf         #: end of the linear zone in tension [m]
    N_inf: float = -math.inf        #: end of the linear zone in compression [m] (negative)
    S_sup: float = math.inf         #: saturation (vertical asymptote) in tension [m]
    S_inf: float = -math.inf        #: saturation in compression [m] (negative)
    P_sup: float = 0.0              #: progressivity in tension [N]
    P_inf: float = 0.0              #: progressivity in compression [N]
    n_cells: int = 0                #: ladder cells N
    Kpa: float = 0.0                #: small-amplitude additional stiffness [N/m]
    Kr: float = 0.0                 #: ladder spring stiffness [N/m]
    Ff: float = 0.0                 #: slider threshold [N]
    Co: float = 0.0                 #: power-law damper coefficient [N/(m/s)^pw]
    pw: float = 1.0                 #: power-law exponent, 0 < pw <= 1
    Ct: float = 0.0                 #: continuous STS constant [N^n/m] (n = 2: Ct = 2·Ff·Kr)
    n_root: float = 2.0             #: root of the continuous STS (2 = Coveney; STSn+ otherwise)
    maxwell_k: tuple[float, ...] = field(default_factory=tuple)  #: Maxwell spring stiffnesses [N/m]
    maxwell_c: tuple[float, ...] = field(default_factory=tuple)  #: Maxwell damper rates [N·s/m]
    #: a tabulated elastic law's nodes (deflection [m], force [N], slope [N/m]), deflections increasing
    curve: tuple[tuple[float, float, float], ...] = field(default_factory=tuple)

    @property
    def continuous(self) -> bool:
        """True for the continuous (Coveney) STS family, which uses a turning-point memory."""
        return self.model in ("sts_continuous", "stsn")

    def replace(self, **changes: Any) -> "ChannelParams":
        """A copy with some SI fields changed."""
        return replace(self, **changes)


def _number(value: Any, source: str, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"expected a number, got {value!r}", source=source, key=key)
    if not abs(value) <= MAX_MAGNITUDE:
        raise InputError(f"expected a finite number of at most {MAX_MAGNITUDE:g} in magnitude (N, mm, s: a unit or "
                         f"typing error beyond), got {str(value)[:40]}", source=source, key=key)
    return float(value)


def check_one_elastic_law(model: str, values: Mapping[str, object], source: str | None = None) -> None:
    """Refuse ``values`` of ``model`` that give a ladder model's elastic law twice, as K0 (and the
    elastic keys) and as a curve.

    Raises:
        InputError: naming ``source`` and the key ``curve``.
    """
    if model in CURVE_ELASTIC and "curve" in values and ({"K0", *_ELASTIC_KEYS} & set(values)):
        raise InputError("give the elastic law as K0 (and the elastic keys) or as a curve, not both",
                         source=source, key="curve")


def to_si(model: str, values: Mapping[str, Any], quantity: str = "translation",
          source: str = "<parameters>") -> ChannelParams:
    """Validate a user-facing parameter mapping (thesis units) and convert it to SI.

    ``values`` uses the thesis's names: K0, Kpa, Kr [N/mm], Ff [N], Co [N/(mm/s)^pw], pw, N,
    C [N·s/mm], N_sup/N_inf/S_sup/S_inf [mm], P_sup/P_inf [N], Ct [N^n/mm], n, maxwell_k [N/mm],
    maxwell_c [N·s/mm], curve [[mm, N], ...] (N·m and deg in place of N and mm for ``quantity:
    rotation``).
    """
    if not isinstance(model, str) or model not in MODELS:
        raise InputError(f"unknown model {model!r}; expected one of {', '.join(MODELS)}",
                         source=source, key="model")
    if not isinstance(quantity, str) or quantity not in LENGTH_UNIT_SI:
        raise InputError(f"unknown quantity {quantity!r}; expected translation or rotation",
                         source=source, key="quantity")
    required, optional = model_keys(model, values)
    check_one_elastic_law(model, values, source)
    unknown = sorted(set(values) - set(required) - set(optional))
    if unknown:
        raise InputError(f"unknown parameter(s) {', '.join(unknown)} for model {model!r}; "
                         f"expected {', '.join(required + optional)}", source=source, key=unknown[0])
    missing = [k for k in required if k not in values]
    if missing:
        raise InputError(f"missing parameter(s) {', '.join(missing)} for model {model!r}",
                         source=source, key=missing[0])
    length = LENGTH_UNIT_SI[quantity]
    si: dict[str, Any] = {}
    for key, raw in values.items():
        if key == "curve":
            si["curve"] = curve_nodes(raw, length, source)
            si["K0"] = curve_stiffness(si["curve"])
            continue
        if key in ("maxwell_k", "maxwell_c"):
            if not isinstance(raw, (list, tuple)) or not raw:
                raise InputError(f"expected a non-empty list of numbers, got {raw!r}", source=source, key=key)
            nums = [_number(v, source, key) for v in raw]
            if any(v <= 0 for v in nums):
                raise InputError(f"expected positive values, got {raw!r}", source=source, key=key)
            si[key] = tuple(v / length for v in nums)
            continue
        value = _number(raw, source, key)
        if key == "N":
            if value != int(value) or not 1 <= value <= MAX_CELLS:
                raise InputError(f"expected a whole number of cells in 1..{MAX_CELLS}, got {raw!r}",
                                 source=source, key=key)
            si["n_cells"] = int(value)
            continue
        if key == "pw" and not PW_MIN <= value <= 1.0:
            raise InputError(f"expected {PW_MIN} <= pw <= 1 (a smaller exponent is a slider, Ff), got {raw!r}",
                             source=source, key=key)
        if key == "n" and not value > 1.0:
            raise InputError(f"expected a root n > 1, got {raw!r}", source=source, key=key)
        if key in ("K0", "C", "Kpa", "Kr", "Ff", "Co", "Ct", "P_sup", "P_inf") and value < 0:
            raise InputError(f"expected a non-negative value, got {raw!r}", source=source, key=key)
        if key in ("Kpa", "Kr", "Ct") and value == 0:
            raise InputError(f"expected a positive value, got {raw!r}", source=source, key=key)
        si[key] = value if key == "Co" else value * length ** _PARAMETERS[key][0]
    if "Co" in si:  # force/(length/s)^pw: dividing by length**pw
        si["Co"] = si["Co"] / length ** si.get("pw", 1.0)
    if "n" in si:
        si["n_root"] = si.pop("n")
    if len(si.get("maxwell_k", ())) != len(si.get("maxwell_c", ())):
        raise InputError("maxwell_k and maxwell_c must have the same length", source=source, key="maxwell_c")
    _check_elastic(si, source)
    if model in ("sts", "rt", "stvs", "tvs"):
        si.setdefault("n_cells", DEFAULT_CELLS)
    if model == "rt":
        si["Ff"] = 0.0
    return ChannelParams(model=model, quantity=quantity, **si)


def curve_nodes(points: Any, length_si: float, source: str = "<parameters>", key: str = "curve"
                ) -> tuple[tuple[float, float, float], ...]:
    """The nodes (deflection [m or rad], force [N or N·m], slope) of a tabulated elastic law given as
    ``points`` [[deflection, force], ...] in the length unit ``length_si`` (SI per unit): the
    monotone cubic through the points (PCHIP's slopes, so that it neither overshoots nor wiggles
    between them; the end slopes are the end segments'). InputError naming ``key`` (``key[i]`` for
    point i) unless there are 2 to MAX_CURVE_POINTS points of two finite numbers, deflections
    increasing, the force rising from point to point, and (0, 0) among them: the unloaded bushing,
    whose slope there is the law's stiffness about its design position (a preload is the
    vehicle's; a dead band the ``backlash`` effect)."""
    if not isinstance(points, (list, tuple)) or not 2 <= len(points) <= MAX_CURVE_POINTS:
        raise InputError(f"expected 2 to {MAX_CURVE_POINTS} [deflection, force] points, got {str(points)[:60]}",
                         source=source, key=key)
    rows = []
    for i, p in enumerate(points):
        if not isinstance(p, (list, tuple)) or len(p) != 2:
            raise InputError(f"expected a [deflection, force] pair, got {p!r}", source=source, key=f"{key}[{i}]")
        rows.append([_number(v, source, f"{key}[{i}]") for v in p])
    for i in range(1, len(rows)):
        (x0, f0), (x1, f1) = rows[i - 1], rows[i]
        if not x1 > x0:
            raise InputError(f"deflection {x1:g} does not follow {x0:g}; expected increasing deflections",
                             source=source, key=f"{key}[{i}]")
        if not f1 > f0:
            raise InputError(f"force {'falls' if f1 < f0 else 'stays'} from {f0:g} to {f1:g}; expected a force that "
                             f"rises (a falling or flat stretch has no stiffness: a dead band is the backlash "
                             f"effect)", source=source, key=f"{key}[{i}]")
    zero = [i for i, (x, _) in enumerate(rows) if x == 0.0]
    if not zero or abs(rows[zero[0]][1]) > 1e-9 * max(abs(rows[0][1]), abs(rows[-1][1])):
        got = f"force {rows[zero[0]][1]:g} at zero deflection" if zero else "no point at zero deflection"
        raise InputError(f"{got}; expected the point (0, 0), the unloaded bushing (a preload is set on the "
                         f"vehicle's bushing)", source=source, key=f"{key}[{zero[0]}]" if zero else key)
    from scipy.interpolate import PchipInterpolator   # here: the vehicle's command line needs no scipy

    x, f = np.array(rows).T
    with np.errstate(all="ignore"):
        secants = np.diff(f) / np.diff(x)   # in the points' own units
    steep = np.flatnonzero(~(secants <= MAX_MAGNITUDE))
    if steep.size:
        raise InputError(f"a slope of {secants[steep[0]]:.3g} to this point; expected at most {MAX_MAGNITUDE:g} (N/mm "
                         f"or N·m/deg: points closer than the numbers resolve?)", source=source,
                         key=f"{key}[{steep[0] + 1}]")
    x = x * length_si
    slopes = PchipInterpolator(x, f).derivative()(x)
    slopes[0], slopes[-1] = secants[0] / length_si, secants[-1] / length_si
    return tuple((float(a), float(b), float(c)) for a, b, c in zip(x, f, slopes))


def curve_stiffness(nodes: tuple[tuple[float, float, float], ...]) -> float:
    """A tabulated law's slope at its (0, 0) node: its stiffness about the design position."""
    return next(slope for x, _, slope in nodes if x == 0.0)


def _check_elastic(si: dict[str, Any], source: str) -> None:
    present = [k for k in _ELASTIC_KEYS if k in si]
    if present and len(present) != len(_ELASTIC_KEYS):
        missing = [k for k in _ELASTIC_KEYS if k not in si]
        raise InputError(f"the nonlinear elastic law needs all of {', '.join(_ELASTIC_KEYS)}",
                         source=source, key=missing[0])
    if present and not (si["S_inf"] < si["N_inf"] <= 0.0 <= si["N_sup"] < si["S_sup"]):
        raise InputError("expected S_inf < N_inf <= 0 <= N_sup < S_sup", source=source, key="N_sup")
