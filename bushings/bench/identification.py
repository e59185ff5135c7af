"""Identification of ladder bushing models (STS, RT, STVS) from bench records (thesis ch. 5).

Three steps, each usable on its own:

1. direct STS identification from one slow triangular cycle (eqs 5.5-5.8 as corrected in the
   spec): :func:`measure_cycle` reads Tg1, Tg2, F_max, X_max off the record and
   :func:`sts_from_measures` solves for K0, Kpa, Kr, Ff;
2. the STVS (or RT) starting point from that STS (eq. 5.10): :func:`stvs_initial`, :func:`rt_initial`;
3. a least-squares fit of all parameters to several records at once: :func:`fit`.

Parameter sets are handled in the thesis's units (N, mm, s) as :class:`ParameterSet` values and
converted to SI only by :func:`bushings.to_si`; records and simulations are SI.
"""

from __future__ import annotations

import datetime as dt
import math
import time
from dataclasses import dataclass, field, replace
from typing import Mapping, Sequence

import numpy as np
from scipy.optimize import least_squares

from elastokin.bushings.bench.records import BenchRecord, simulate_record
from elastokin.bushings.parameter_sets import ParameterSet
from elastokin.bushings.parameters import DEFAULT_CELLS, ELASTIC_KEYS, FITTED_MODELS, MODELS, PW_MIN, to_si
from elastokin.core.errors import InputError
from elastokin.core.units import MM

#: Parameters adjusted by :func:`fit`, per model: the model's required ones (N is fixed).
FIT_PARAMETERS: dict[str, tuple[str, ...]] = {model: MODELS[model][0] for model in FITTED_MODELS}
#: Share of a branch, ending at its tip, over which Tg2 is measured (within the STS's last linear
#: segment for the thesis's sets: 0.46 of 4.05 mm for fig5_6).
TG2_SPAN_FRACTION = 0.1
# Forward-difference step of the Jacobian, in log-parameter (relative) or pw units: large enough
# to dominate the implicit solver's 1e-13 tolerance, small enough for a 0.1 % derivative error.
_FD_STEP = 1e-3
LOG_SPAN = 6.0   #: decades a positive parameter may move from its starting value in a fit


# --- 1. Direct STS identification -------------------------------------------------------------

@dataclass(frozen=True)
class CycleMeasures:
    """The four quantities of a large symmetric cycle used by eqs 5.5-5.8 (consistent units)."""

    Tg1: float    #: tangent just after a reversal
    Tg2: float    #: tangent at the end of a branch
    F_max: float  #: force amplitude
    X_max: float  #: deflection amplitude


def sts_from_measures(m: CycleMeasures, n_cells: int) -> dict[str, float]:
    """K0, Kpa, Kr, Ff of the discrete STS from one cycle's measures (eqs 5.5-5.8, corrected).

    Units follow the inputs (N/mm, N, mm gives N/mm and N). Assumes the cycle tip is reached with
    N−1 sliders slipping, so the result reproduces the four measures exactly.
    """
    Tg1, Tg2, F, X, N = m.Tg1, m.Tg2, m.F_max, m.X_max, n_cells
    D = 2.0 * F - (Tg1 + Tg2) * X
    return {
        "K0": (F * (Tg1 + Tg2) - 2.0 * Tg1 * Tg2 * X) / D,
        "Kpa": (Tg1 - Tg2) * (F - Tg1 * X) / D,
        "Kr": (N - 1) * (Tg1 - Tg2) * (Tg1 * X - F) * (F - Tg2 * X) / D ** 2,
        "Ff": 2.0 * (F - Tg1 * X) * (F - Tg2 * X) / (N * D),
    }


def sts_cycle_measures(K0: float, Kpa: float, Kr: float, Ff: float, n_cells: int) -> CycleMeasures:
    """Closed-form measures of the STS cycle whose tip has N−1 sliders slipping (annex C, C.8, 5.2).

    The inverse of :func:`sts_from_measures`.
    """
    N = n_cells
    x_max = Ff * N * (1.0 / Kpa + (N - 1) / (2.0 * Kr))
    return CycleMeasures(Tg1=K0 + Kpa, Tg2=K0 + Kpa * Kr / ((N - 1) * Kpa + Kr),
                         F_max=K0 * x_max + N * Ff, X_max=x_max)


def turning_points(e: np.ndarray, threshold: float) -> np.ndarray:
    """Indices of the reversals of e, ignoring wiggles smaller than ``threshold`` (noise)."""
    turns: list[int] = []
    direction, ext, lo, hi = 0, 0, 0, 0
    for i, x in enumerate(e):
        if direction == 0:  # no direction yet: wait for an excursion larger than the threshold
            hi = i if x > e[hi] else hi
            lo = i if x < e[lo] else lo
            if e[hi] - e[lo] > threshold:
                direction, ext = (1, hi) if hi > lo else (-1, lo)
                first = min(hi, lo)  # a reversal too, unless the record merely starts there
                if abs(e[first] - e[0]) > threshold:
                    turns.append(first)
        elif direction * (x - e[ext]) > 0:
            ext = i
        elif direction * (e[ext] - x) > threshold:
            turns.append(ext)
            direction, ext = -direction, i
    return np.array(turns, dtype=int)


def _slope(x: np.ndarray, y: np.ndarray) -> float:
    """Least-squares slope (a regression, not a two-point secant, to average out force noise)."""
    xc = x - x.mean()
    return float(xc @ (y - y.mean()) / (xc @ xc))


def measure_cycle(record: BenchRecord, tangent_span: float = 1e-4) -> CycleMeasures:
    """Tg1, Tg2, F_max, X_max (SI) of the last full cycle of a triangular record.

    Tg1 is a regression over ``tangent_span`` [m] of deflection just after a reversal (the thesis
    uses about 0.1 mm: the smallest cycle the model should represent); Tg2 one over the last
    :data:`TG2_SPAN_FRACTION` of the branch (at least ``tangent_span``), where the slope hardly
    varies and a longer span averages out force noise. Both are averaged over the last rising and
    the last falling branch.
    """
    e, F = record.e, record.F
    p2p = float(e.max() - e.min())
    turns = list(turning_points(e, 0.25 * p2p))
    # The record may end on a tip: count the last stretch as a branch if it spans the cycle.
    if turns and abs(e[-1] - e[turns[-1]]) > 0.95 * p2p:
        turns.append(len(e) - 1)
    branches = {}
    for a, b in zip(turns[:-1], turns[1:]):
        branches[int(np.sign(e[b] - e[a]))] = (a, b)  # the last branch of each direction wins
    if set(branches) != {-1, 1}:
        raise InputError("expected a triangular cycle with a full rising and a full falling branch",
                         source=record.source)
    tg1, tg2, f_amp, x_amp = [], [], [], []
    for sign, (a, b) in branches.items():
        s = sign * (e[a:b + 1] - e[a])  # distance travelled along the branch
        f = sign * F[a:b + 1]
        head = s <= tangent_span
        tail = s >= s[-1] - max(tangent_span, TG2_SPAN_FRACTION * s[-1])
        if head.sum() < 2 or tail.sum() < 2:
            raise InputError(f"too few samples within {tangent_span / MM:g} mm of a reversal to measure "
                             "the tangents; record the triangle with a finer time step", source=record.source)
        tg1.append(_slope(s[head], f[head]))
        tg2.append(_slope(s[tail], f[tail]))
        f_amp.append(0.5 * (f[-1] - f[0]))
        x_amp.append(0.5 * s[-1])
    return CycleMeasures(float(np.mean(tg1)), float(np.mean(tg2)), float(np.mean(f_amp)), float(np.mean(x_amp)))


def identify_sts(record: BenchRecord, n_cells: int = DEFAULT_CELLS, tangent_span: float = 1e-4) -> ParameterSet:
    """Discrete STS parameter set (N, mm units) identified directly from one slow triangle record."""
    m = measure_cycle(record, tangent_span)
    si = sts_from_measures(m, n_cells)
    bad = [k for k, v in si.items() if not v > 0]
    if bad:
        raise InputError(f"direct STS identification gives non-positive {', '.join(bad)} "
                         f"(Tg1 = {m.Tg1 * MM:.1f}, Tg2 = {m.Tg2 * MM:.1f} N/mm, F_max = {m.F_max:.1f} N, "
                         f"X_max = {m.X_max / MM:.3f} mm): the record is not a large, slow, symmetric "
                         "hysteresis cycle", source=record.source)
    values = {"N": n_cells, "K0": si["K0"] * MM, "Kpa": si["Kpa"] * MM, "Kr": si["Kr"] * MM, "Ff": si["Ff"]}
    return ParameterSet(name=f"sts_{record.source}", model="sts", quantity="translation", values=values,
                        source=f"STS identified directly from {record.source} (eqs 5.5-5.8)")


def k0_nonlinear(sts: Mapping[str, float]) -> float:
    """K0 of the nonlinear elastic law that continues an STS beyond its cycle (eq. 5.9), N/mm."""
    N = sts.get("N", DEFAULT_CELLS)
    return sts["K0"] + sts["Kpa"] * sts["Kr"] / ((N - 1) * sts["Kpa"] + sts["Kr"])


def _feasible(m: CycleMeasures) -> CycleMeasures:
    """The measures with Tg2 moved inside the domain where eqs 5.5-5.8 give positive parameters.

    That domain is Tg1·S/(2·Tg1 − S) < Tg2 < S with S = F_max/X_max the secant stiffness; a noisy
    or saturated cycle can leave it. Tg2 is the least reliable measure, so it is the one moved.
    """
    S = m.F_max / m.X_max
    lo, hi = m.Tg1 * S / (2.0 * m.Tg1 - S), S
    return replace(m, Tg2=float(np.clip(m.Tg2, lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo))))


# --- 2. RT / STVS starting points (eq. 5.10) ----------------------------------------------------

def stvs_initial(sts: ParameterSet, v0_mm_s: float = 0.333, pw: float = 0.2,
                 slider_share: float = 0.8) -> ParameterSet:
    """STVS starting point from an STS set (eq. 5.10): same K0, Kpa, Kr, N; the STS threshold is
    split between the slider (``slider_share``) and the power-law damper's force Fs at the triangle's
    speed V0, with Co = Fs / V0^pw (the thesis takes pw in [0.1, 0.3])."""
    v = sts.values
    fs = (1.0 - slider_share) * v["Ff"]
    values = {"N": v.get("N", DEFAULT_CELLS), "K0": v["K0"], "Kpa": v["Kpa"], "Kr": v["Kr"],
              "Ff": slider_share * v["Ff"], "Co": fs / v0_mm_s ** pw, "pw": pw}
    return ParameterSet(name=sts.name.replace("sts", "stvs", 1), model="stvs", quantity=sts.quantity,
                        values=values, source=f"{sts.source}; STVS initialised by eq. 5.10")


def rt_initial(sts: ParameterSet, v0_mm_s: float = 0.333, pw: float = 0.1) -> ParameterSet:
    """RT starting point from an STS set: the damper gives the STS threshold at V0 (Co = Ff / V0^pw)."""
    v = sts.values
    values = {"N": v.get("N", DEFAULT_CELLS), "K0": v["K0"], "Kpa": v["Kpa"], "Kr": v["Kr"],
              "Co": v["Ff"] / v0_mm_s ** pw, "pw": pw}
    return ParameterSet(name=sts.name.replace("sts", "rt", 1), model="rt", quantity=sts.quantity,
                        values=values, source=f"{sts.source}; RT initialised with Co = Ff/V0^pw")


def starting_set(pset: ParameterSet, model: str) -> ParameterSet:
    """A set to start a fit of ``model`` from: an STS set converted by eq. 5.10 for the STVS, or to an
    RT start (:func:`stvs_initial`, :func:`rt_initial`); any other set as it is."""
    if pset.model == "sts" and model == "stvs":
        return stvs_initial(pset)
    if pset.model == "sts" and model == "rt":
        return rt_initial(pset)
    return pset


def with_elastic_curve(pset: ParameterSet, curve: Sequence[Sequence[float]], where: str) -> ParameterSet:
    """``pset`` with its elastic law (K0 and the elastic keys) replaced by the tabulated ``curve``
    ([[mm, N], ...], from ``where``): a fit from it keeps the curve and fits the ladder."""
    values = {k: v for k, v in pset.values.items() if k not in ("K0", *ELASTIC_KEYS)}
    return replace(pset, values={**values, "curve": [list(p) for p in curve]},
                   source=f"{pset.source}, its elastic law the curve of {where}")


def initial_guesses(records: Sequence[BenchRecord], model: str, n_cells: int = DEFAULT_CELLS) -> list[ParameterSet]:
    """Starting points for :func:`fit`: direct STS identification on the slowest cyclic record,
    then for the STVS eq. 5.10 twice (slider share 0.8 as the thesis's text says, 0.2 as its
    fig. 5.9 set implies), for the RT Co = Ff/V0^pw; V0 is that record's median speed."""
    cyclic = [r for r in records if len(turning_points(r.e, 0.25 * float(np.ptp(r.e)))) >= 2]
    if not cyclic:
        raise InputError("no triangular cycle among the records to start the fit from; add a slow "
                         "triangle record or give a starting parameter set", source=", ".join(r.source for r in records))
    speeds = [float(np.median(np.abs(np.diff(r.e) / np.diff(r.t)))) / MM for r in cyclic]
    slowest = int(np.argmin(speeds))
    record, v0 = cyclic[slowest], speeds[slowest]
    try:
        sts = identify_sts(record, n_cells)
    except InputError:  # e.g. a cycle beyond the ladder's saturation: start from the nearest valid STS
        si = sts_from_measures(_feasible(measure_cycle(record)), n_cells)
        sts = ParameterSet(name=f"sts_{record.source}", model="sts", quantity="translation",
                           values={"N": n_cells, "K0": si["K0"] * MM, "Kpa": si["Kpa"] * MM,
                                   "Kr": si["Kr"] * MM, "Ff": si["Ff"]},
                           source=f"STS from {record.source} (eqs 5.5-5.8, Tg2 moved into their domain)")
    if model == "stvs":
        return [stvs_initial(sts, v0, slider_share=share) for share in (0.8, 0.2)]
    if model == "rt":
        return [rt_initial(sts, v0)]
    return [sts]


# --- 3. Least-squares fit -----------------------------------------------------------------------

@dataclass(frozen=True)
class RecordError:
    """Fit error on one record."""

    source: str
    rms_N: float        #: RMS of simulated − measured force [N]
    range_N: float      #: peak-to-peak measured force [N]

    @property
    def percent(self) -> float:
        """RMS error as a percentage of the force range."""
        return 100.0 * self.rms_N / self.range_N


@dataclass(frozen=True)
class FitResult:
    """Outcome of :func:`fit`; values and standard errors in the thesis's units (N, mm, s)."""

    model: str
    values: dict[str, float]             #: fitted parameter set (with N)
    std_errors: dict[str, float]         #: one standard error per fitted parameter
    errors: list[RecordError]            #: per record, on the full (not subsampled) records
    initial: dict[str, float]            #: starting point
    seconds: float                       #: wall-clock time of the fit
    evaluations: int                     #: channel simulations of all records (all starts)
    message: str = ""                    #: optimiser's termination message
    correlation: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))  #: of the fitted parameters

    def parameter_set(self, name: str, record_paths: Sequence[str]) -> ParameterSet:
        """The fitted parameters as a :class:`ParameterSet` (rounded to 5 significant digits) whose
        source says what was fitted to what, when, and how well."""
        errors = ", ".join(f"{e.source} {e.rms_N:.3g} N ({e.percent:.2f} %)" for e in self.errors)
        source = (f"fitted by vsim bushing fit ({self.model}) on {dt.date.today().isoformat()} to "
                  f"{', '.join(record_paths)}; RMS fit error {errors}")
        params = {k: (int(v) if k == "N" else float(f"{v:.5g}") if isinstance(v, float) else v)
                  for k, v in self.values.items()}
        return ParameterSet(name, self.model, "translation", params, source)


class _Problem:
    """Normalised residuals of a parameter vector over all records, and their Jacobian.

    x holds log(value) for positive parameters and pw itself, in user units (N, mm, s) so that
    Co stays O(Ff) and weakly coupled to pw. Each record's residuals are divided by its force range
    and by √n, so that every record weighs the same whatever its length and load level.
    """

    def __init__(self, model: str, fixed: Mapping[str, float], records: Sequence[BenchRecord]):
        self.model, self.fixed, self.records = model, dict(fixed), list(records)
        # a curve is the elastic law in K0's place: it is held, K0 not fitted
        self.names = tuple(n for n in FIT_PARAMETERS[model]
                           if n not in self.fixed and not (n == "K0" and "curve" in self.fixed))
        self.weights = [1.0 / (float(np.ptp(r.F)) * math.sqrt(len(r))) for r in self.records]
        self.evaluations = 0

    def values(self, x: np.ndarray) -> dict[str, float]:
        return {**self.fixed, **{n: float(v if n == "pw" else math.exp(v)) for n, v in zip(self.names, x)}}

    def encode(self, values: Mapping[str, float]) -> np.ndarray:
        return np.array([values[n] if n == "pw" else math.log(values[n]) for n in self.names])

    def _residuals(self, xs: np.ndarray) -> np.ndarray:
        """Residuals (C, m) of C parameter vectors, simulated together in one bank per record."""
        channels = [to_si(self.model, self.values(x), source="fit") for x in xs]
        self.evaluations += len(xs)
        return np.concatenate([(simulate_record(channels, r.t, r.e) - r.F[:, None]).T * w
                               for r, w in zip(self.records, self.weights)], axis=1)

    def residuals(self, x: np.ndarray) -> np.ndarray:
        return self._residuals(x[None])[0]

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        # Step pw away from whichever bound it may sit on.
        steps = np.where((np.array(self.names) == "pw") & (x > 0.5), -_FD_STEP, _FD_STEP)
        xs = np.vstack([x, x + np.diag(steps)])
        r = self._residuals(xs)
        return ((r[1:] - r[0]) / steps[:, None]).T


def fit(records: Sequence[BenchRecord], model: str = "stvs", initial: Sequence[ParameterSet] | None = None,
        n_cells: int | None = None, max_samples: int = 3000, max_iterations: int = 60,
        hold: Sequence[str] = ()) -> FitResult:
    """Least-squares fit of all ``model`` parameters (N fixed, and those named in ``hold`` at their
    starting values: ``("K0",)`` for a ladder without its parallel spring) to several records at once.

    The fit runs from each starting set (default :func:`initial_guesses`) and keeps the best: with
    noisy data the cost has shallow local minima along the Ff-Co-Kr valley.

    Records longer than ``max_samples`` are subsampled (every k-th sample; the model is then
    stepped at the coarser step). Standard errors come from covariance = s²·(JᵀJ)⁻¹ at the optimum,
    s² being the normalised residual variance; per-record errors are on the full records.
    """
    if model not in FIT_PARAMETERS:
        raise InputError(f"cannot fit model {model!r}; expected one of {', '.join(FIT_PARAMETERS)}", key="model")
    if not records:
        raise InputError("no records to fit")
    unknown = sorted(set(hold) - set(FIT_PARAMETERS[model]))
    if unknown:
        raise InputError(f"cannot hold {', '.join(unknown)}: not a fitted parameter of {model!r} "
                         f"({', '.join(FIT_PARAMETERS[model])})", key="hold")
    starts = list(initial) if initial is not None else initial_guesses(records, model, n_cells or DEFAULT_CELLS)
    tic = time.perf_counter()
    best, evaluations = None, 0
    for start in starts:
        if start.model != model:
            raise InputError(f"starting set is a {start.model!r} set, expected {model!r}", source=start.name, key="model")
        init_values = dict(start.values, **({"N": n_cells} if n_cells is not None else {}))
        fixed = {k: v for k, v in init_values.items() if k not in FIT_PARAMETERS[model] or k in hold}
        problem = _Problem(model, fixed, [r.subsampled(max_samples) for r in records])
        is_pw = np.array(problem.names) == "pw"
        x0 = problem.encode(init_values)
        # a positive parameter stays within LOG_SPAN decades of its start: its log cannot run to −∞ (exp → 0)
        lower = np.where(is_pw, PW_MIN, x0 - LOG_SPAN * math.log(10.0))
        upper = np.where(is_pw, 1.0, x0 + LOG_SPAN * math.log(10.0))
        sol = least_squares(problem.residuals, np.clip(x0, lower, upper),
                            jac=problem.jacobian, bounds=(lower, upper), method="trf", x_scale="jac",
                            max_nfev=max_iterations, xtol=1e-6, ftol=1e-8)
        evaluations += problem.evaluations
        if best is None or sol.cost < best[0].cost:
            best = (sol, problem, init_values)
    sol, problem, init_values = best
    values = problem.values(sol.x)
    std_x, corr = _standard_errors(sol.jac, sol.fun)
    std = {n: float(s if n == "pw" else values[n] * s) for n, s in zip(problem.names, std_x)}
    channel = to_si(model, values, source="fit")
    errors = []
    for r in records:
        res = simulate_record([channel], r.t, r.e)[:, 0] - r.F
        errors.append(RecordError(r.source, float(np.sqrt(np.mean(res ** 2))), float(np.ptp(r.F))))
    return FitResult(model=model, values=values, std_errors=std, errors=errors, initial=init_values,
                     seconds=time.perf_counter() - tic, evaluations=evaluations, message=sol.message,
                     correlation=corr)


def _standard_errors(J: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Standard errors and correlation matrix of x from covariance s²·(JᵀJ)⁻¹."""
    m, p = J.shape
    s2 = float(r @ r) / max(m - p, 1)
    cov = s2 * np.linalg.pinv(J.T @ J)
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(std, std)
    return std, corr
