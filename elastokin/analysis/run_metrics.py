"""Metrics of a recorded run (:class:`elastokin.recordings.run_format.Run`, simulated or measured), shared
by the run summary (`vsim run`), `vsim compare` and the diagnosis.

Signals stay in their recorded units (mm, deg, N, N·m; time in s) unless a name says SI. Loops are
read on a case's last cycle, split into an unloading (down) and a loading (up) branch at the
extremes of the input driving them, with the definitions of :mod:`elastokin.analysis.loops`: the centre
line is the mean of the branches, the gradient its least-squares slope around design (zero input),
the loop width the difference between the branches at design and its largest value over the fit
window.

The named K&C metrics (:data:`elastokin.analysis.kc_metrics.METRICS`) of a case come from
:func:`elastokin.analysis.kc_metrics.triangle_metrics` fed with the recorded signals, so a run and
`vsim kc` share one definition; they differ only in the history the run gives the bushings
(settling, earlier cycles) and in the fit window, which here follows the case's amplitude (±80 %,
and at most ±20 mm in bump).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from elastokin.vehicle.scenarios.channels import CORNER_TAGS
from elastokin.vehicle.scenarios.road_scenario import ROAD_TYPES
from elastokin.vehicle.scenarios.scenario import SIGNAL_TYPES
from elastokin.vehicle.scenarios.schedule import PHASES, ROAD_PHASES
from elastokin.analysis.kc_metrics import (BUMP_WINDOW_M, FIT_FRACTION, Leg, bump_loop_widths, contact_y, fit_window,
                                          triangle_metrics)
from elastokin.analysis.loops import (Branches, centre_slope, common_range, dynamic_stiffness, loop_area, loop_width,
                                 relaxation_amplitude)
from elastokin.core import units
from elastokin.core.documents import Document
from elastokin.core.errors import InputError
from elastokin.recordings.run_format import Run

#: The `vsim kc` test that each scenario type (or bi-sine input) plays.
KC_TESTS = {"pumping": "bump", "roll": "roll", "lateral_force": "lateral", "longitudinal_force": "longitudinal",
            "aligning_torque": "aligning"}
#: (force, displacement) of a wheel whose first-harmonic ratio is its dynamic stiffness, per driven
#: input quantity: the pad's reaction to an imposed height, the wheel centre's yield to a force.
STIFFNESS_PAIRS = {"pad_z": ("pad_fz", "pad_height"), "pad_fy": ("pad_fy", "wheel_centre_y"),
                   "pad_fx": ("pad_fx", "wheel_centre_x"), "pad_mz": ("pad_mz", "steer")}
#: A thousand of each x unit, for gradients: per m of travel, per kN, per kN·m.
_THOUSAND = {"mm": "m", "N": "kN", "N·m": "kN·m"}
_EPS_S = 1e-9   #: times closer than this are the same instant (the recording's 1 ns stamps)


def gradient_unit(y_unit: str, x_unit: str) -> tuple[float, str]:
    """(factor, unit) that turn a slope in y unit per x unit (mm, N, N·m) into per m, kN or kN·m."""
    return 1e3, f"{y_unit}/{_THOUSAND[x_unit]}"


# -- cases of a run --------------------------------------------------------------------------------
def cases(run: Run) -> list[dict[str, Any]]:
    """The run's cases (metadata ``extra.cases``: number, label, parameters, cycles, times)."""
    return list(run.metadata.extra["cases"])


def input_kind(run: Run) -> str:
    """What the run's input does: its scenario type, or the input a bi-sine drives."""
    extra = run.metadata.extra
    if extra["type"] == "bisine":
        return cases(run)[0]["parameters"]["input"]
    return extra["type"]


def is_road(run: Run) -> bool:
    """Whether ``run`` is a run of a road scenario."""
    return run.metadata.extra.get("type") in ROAD_TYPES


def input_phase(run: Run) -> int:
    """The value of the ``phase`` signal during the inputs (the last of the run's phases)."""
    return len(ROAD_PHASES if is_road(run) else PHASES) - 1


def case_mask(run: Run, case: Mapping[str, Any], last_cycle: bool = False) -> np.ndarray:
    """Samples of ``case``'s input phase, or of its last cycle."""
    start, end = case["input_start_s"], case["end_s"]
    if last_cycle:
        start += (end - start) * (case["cycles"] - 1) / case["cycles"]
    return ((run.signals["case"] == case["case"]) & (run.signals["phase"] == input_phase(run))
            & (run.t_s >= start - _EPS_S))


def loop_axes(run: Run, tag: str) -> tuple[str, str] | None:
    """(x signal, driving input) of the loops of wheel ``tag``, None for time-only runs: wheel
    travel driven by the pad height, or the pad force or torque that drives itself."""
    x_quantity = run.metadata.extra["x_quantity"]
    if x_quantity is None:
        return None
    return f"{x_quantity}_{tag}", f"{'pad_z' if x_quantity == 'wheel_travel' else x_quantity}_{tag}"


def _legs(run: Run, case: Mapping[str, Any], driver: str) -> tuple[np.ndarray, np.ndarray] | None:
    """(down, up) sample masks of ``case``'s last cycle: from the maximum of signal ``driver`` to
    its minimum (`vsim kc`'s +A → −A leg), and the rest of the cycle; splitting at the extremes
    rather than by the sign of each step keeps a noisy measured input's branches apart. None
    without two samples on each."""
    mask = case_mask(run, case, last_cycle=True)
    index = np.flatnonzero(mask)
    if index.size < 4:
        return None
    drive = run.signals[driver][index]
    top, bottom = int(np.argmax(drive)), int(np.argmin(drive))
    between = np.zeros_like(mask)
    between[index[min(top, bottom) + 1 : max(top, bottom) + 1]] = True
    down, up = (between, mask & ~between) if top < bottom else (mask & ~between, between)
    return (down, up) if down.sum() >= 2 and up.sum() >= 2 else None


def case_branches(run: Run, case: Mapping[str, Any], x: str, y: str, driver: str) -> Branches | None:
    """Branches of signal ``y`` against signal ``x`` on ``case``'s last cycle, split at the
    extremes of signal ``driver``; None without both branches."""
    legs = _legs(run, case, driver)
    if legs is None:
        return None
    (down, up), xs, ys = legs, run.signals[x], run.signals[y]
    return Branches(xs[down], ys[down], xs[up], ys[up])


@dataclass(frozen=True)
class Loop:
    """An output's loop against the x signal on a case's last cycle, in the recorded units."""

    gradient: float     #: centre-line slope at design [y unit / x unit]
    width: float        #: loop width at design [y unit]
    width_max: float    #: largest loop width over the fit window [y unit]
    area: float         #: ∮ y dx over the last cycle (:func:`loop_area`) [y unit · x unit]
    window: float       #: half-width of the gradient's fit [x unit]


def case_loop(run: Run, case: Mapping[str, Any], x: str, y: str, driver: str) -> Loop | None:
    """The :class:`Loop` of ``y`` against ``x`` (branches split by ``driver``) on ``case``'s last
    cycle, None when the run did not record both branches. Widths are read over ±80 % of the
    range both branches cover; the gradient over the same, at most ±20 mm of wheel travel."""
    b = case_branches(run, case, x, y, driver)
    reach = common_range(b) if b is not None else 0.0
    if not reach > 0:
        return None
    window = FIT_FRACTION * reach
    cap = BUMP_WINDOW_M / units.si(run.units[x]) if x.startswith("wheel_travel") else math.inf
    last = case_mask(run, case, last_cycle=True)
    return Loop(centre_slope(b, min(window, cap)), *loop_width(b, window),
                loop_area(run.signals[x][last], run.signals[y][last]), min(window, cap))


def case_relaxation(run: Run, case: Mapping[str, Any], name: str) -> float | None:
    """:func:`relaxation_amplitude` of signal ``name`` over ``case``'s final hold [its unit]; None
    for a case without a final hold or without samples in it."""
    hold = case.get("hold_from_s")
    mask = case_mask(run, case)
    if hold is None or not np.any(mask & (run.t_s >= hold - _EPS_S)):
        return None
    return relaxation_amplitude(run.t_s[mask], run.signals[name][mask], hold)


def _crossing_s(t_s: np.ndarray, y: np.ndarray, share: float) -> float:
    y = (y - y[0]) / (y[-1] - y[0])
    i = int(np.flatnonzero(y >= share)[0])
    return float(t_s[i - 1] + (share - y[i - 1]) / (y[i] - y[i - 1]) * (t_s[i] - t_s[i - 1]))


def case_lag_s(run: Run, case: Mapping[str, Any], follower: str, leader: str, share: float,
               after_hold_s: float) -> float:
    """How long after signal ``leader`` the ``follower`` first reaches ``share`` (0–1) of its change
    [s], from the last sample at rest before the case's input to ``after_hold_s`` into its hold,
    each linear between samples: a response's lag behind its input (the toe behind a rack step,
    thesis fig. 4.35)."""
    window = slice(int(np.searchsorted(run.t_s, case["input_start_s"])),
                   int(np.searchsorted(run.t_s, case["hold_from_s"] + after_hold_s)))
    t = run.t_s[window]
    return _crossing_s(t, run.signals[follower][window], share) - _crossing_s(t, run.signals[leader][window], share)


def sine_frequency_hz(run: Run, case: Mapping[str, Any]) -> float | None:
    """Frequency of ``case``'s input as played [Hz] if it is a single sine, else None."""
    parameters = case["parameters"]
    if parameters.get("shape") != "sine":
        return None
    return parameters["frequency_hz"] / run.metadata.extra["duration_scale"]


def case_dynamic_stiffness(run: Run, case: Mapping[str, Any], force: str, displacement: str) -> complex | None:
    """:func:`dynamic_stiffness` of signal ``force`` over signal ``displacement`` on the last period
    of ``case``'s sine input [their units, e.g. N/mm]; None if the input is not a sine."""
    frequency = sine_frequency_hz(run, case)
    if frequency is None:
        return None
    mask = case_mask(run, case) & (run.signals["input_time"] <= case["cycles"] / frequency + _EPS_S)
    return dynamic_stiffness(run.t_s[mask], run.signals[force][mask], run.signals[displacement][mask], frequency)


# -- the named K&C metrics -------------------------------------------------------------------------
def contact_base_m(run: Run, radius_m: float | None = None) -> dict[str, float]:
    """Lateral distance between the left and right contact points of each axle at design [m]
    (`vsim kc`'s roll base), from the first sample's wheel centres and cambers (the runner records
    the design pose first) and the tyre radius ``radius_m`` (default: that of the run's vehicle):
    contact = centre − r × the wheel plane's up direction. InputError for a run without a vehicle
    (a rig recording) and no radius given."""
    radius = tyre_radius_m(run) if radius_m is None else float(radius_m)
    if radius is None:
        raise InputError("roll metrics need the design contact-point base, from the tyre radius of the measured "
                         "vehicle, and a rig recording holds no vehicle: give the vehicle (Run.metrics(vehicle=...))",
                         source=str(run.path))
    def first(quantity: str, tag: str) -> float:   # the design pose, in SI
        return float(run.signals[f"{quantity}_{tag}"][0]) * units.si(run.units[f"{quantity}_{tag}"])

    out = {}
    for axle in ("front", "rear"):
        left, right = (contact_y(first("wheel_centre_y", t), first("toe", t), first("camber", t), sign, radius)
                       for t, sign in ((CORNER_TAGS[f"{axle}_left"], 1.0), (CORNER_TAGS[f"{axle}_right"], -1.0)))
        out[axle] = float(left - right)
    return out


def tyre_radius_m(run: Run) -> float | None:
    """The tyre radius [m] of the vehicle the run recorded, None for a run without one (a rig
    recording). InputError naming the recording and the key for a vehicle without a numeric one."""
    if not run.metadata.vehicle_yaml:
        return None
    try:
        return float(Document(run.metadata.vehicle_yaml, str(run.path)).data["tyre"]["radius"])
    except (TypeError, KeyError, ValueError) as exc:  # an InputError (not YAML) is a ValueError
        raise InputError(f"the recorded vehicle has no tyre radius to read ({exc}); expected a number in metres",
                         source=str(run.path), key="vehicle.tyre.radius") from None


def _leg(run: Run, mask: np.ndarray) -> Leg:
    """The :data:`elastokin.analysis.kc_metrics.Leg` of the recorded samples ``mask``, in SI."""
    def signal(quantity: str, corner: str) -> np.ndarray:
        name = f"{quantity}_{CORNER_TAGS[corner]}"
        return run.signals[name][mask] * units.si(run.units[name])
    return signal


def case_metrics(run: Run, case: Mapping[str, Any], contact_base: Mapping[str, float] | None = None,
                 radius_m: float | None = None) -> dict[str, dict[str, float]]:
    """The named K&C metrics (keys, units and signs of :data:`elastokin.analysis.kc_metrics.METRICS`) that ``case``
    gives per axle of the run (:data:`elastokin.analysis.kc_metrics.TEST_METRICS`): pumping → bump
    steer and camber, wheel rate, half-track change, recession and the toe and camber loop widths;
    roll → roll steer, camber and stiffness per degree of body roll and the kinematic roll centre;
    lateral force → its three compliances and the force roll centre; longitudinal force → its
    compliance steer and the braking pad-force ratio; aligning torque → its compliance steer; a
    metric the run cannot give (a roll centre without the tyre radius) left out. Empty for inputs
    without K&C metrics (rack steps, CSV) or a case without both branches recorded.

    ``contact_base`` [m] per axle defines the roll angle (default: :func:`contact_base_m`);
    ``radius_m``, the tyre radius, the contact points of roll's kinematic roll centre (default:
    the run's vehicle's; without either, that metric is left out).
    """
    if radius_m is None:
        radius_m = tyre_radius_m(run)
    test = KC_TESTS.get(input_kind(run))
    out: dict[str, dict[str, float]] = {}
    if test is None:
        return out
    quantity = SIGNAL_TYPES[input_kind(run)]
    for axle in run.metadata.extra["axles"]:
        driver = f"{quantity}_{CORNER_TAGS[f'{axle}_left']}"
        legs = _legs(run, case, driver)
        if legs is None:
            continue
        if contact_base is None and (test == "roll" or (test == "lateral" and radius_m is not None)):
            contact_base = contact_base_m(run, radius_m)   # roll's angle; lateral's force roll centre
        down, up = (_leg(run, m) for m in legs)
        base = contact_base[axle] if contact_base is not None and test in ("roll", "lateral") else math.nan
        amplitude = float(np.abs(run.signals[driver][legs[0] | legs[1]]).max()) * units.si(run.units[driver])
        window = fit_window(test, amplitude, base)
        if test == "bump":
            window = min(window, BUMP_WINDOW_M)
        try:
            m = triangle_metrics(test, axle, down, up, window, base, math.nan if radius_m is None else radius_m)
            if test == "bump":
                m |= bump_loop_widths(axle, down, up, window)
        except KeyError:  # a rig recording may lack this axle's wheels
            continue
        out[axle] = {k: v for k, v in m.items() if not math.isnan(v)}   # those the run cannot give left out
    return out


def run_metrics(run: Run, contact_base: Mapping[str, float] | None = None,
                radius_m: float | None = None) -> dict[int, dict[str, dict[str, float]]]:
    """:func:`case_metrics` of every case, by case number (1-based)."""
    radius_m = tyre_radius_m(run) if radius_m is None else radius_m   # the recorded vehicle's, read once
    return {case["case"]: case_metrics(run, case, contact_base, radius_m) for case in cases(run)}
