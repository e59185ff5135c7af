"""The standard K&C metrics (spec vehicle.md §4) from the down and up legs of a triangle: the centre
line is the mean of the two branches; a compliance or gradient is its least-squares slope over ±80 %
of the amplitude around design (±20 mm in bump); a loop width is the difference between the
branches at design (and its maximum over that range). Rig samples and recorded runs both provide
the legs (:data:`Leg`), so that `vsim kc`, the run summary and the comparison share one definition.

Sign conventions (ISO 8855; see :data:`METRICS` for each metric): toe-in positive, camber
positive with the wheel top leaning outward, steer angle positive to the left (axle steer = mean
of the two wheels), bump positive, roll positive with the left side of the body up (right wheels
in bump, as in a left turn); roll camber is the outer (right) wheel's camber relative to the
ground (pad plane) per degree of body roll; lateral compliance camber is the camber of a wheel
whose contact-point force points inboard (an outer wheel in cornering).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from elastokin.vehicle.scenarios.kc_tests import TEST, TESTS
from elastokin.analysis.loops import Branches, centre_slope, loop_width

FIT_FRACTION = 0.8       #: slopes and loop widths over ±80 % of the amplitude

#: JSON key, unit, and sign convention of each metric.
METRICS = (
    ("bump_steer_deg_per_m", "deg/m", "toe-in per metre of bump (mean of left and right)"),
    ("bump_camber_deg_per_m", "deg/m", "camber (top out +) per metre of bump"),
    ("roll_steer_deg_per_deg", "deg/deg", "axle steer (left +) per degree of roll (left side up +)"),
    ("roll_camber_deg_per_deg", "deg/deg", "outer-wheel camber to ground per degree of roll"),
    ("lateral_force_compliance_steer_deg_per_kn", "deg/kN", "axle steer (left +) per kN of Fy (left +) per wheel"),
    ("lateral_force_compliance_camber_deg_per_kn", "deg/kN", "camber (top out +) per kN of inboard Fy"),
    ("lateral_compliance_mm_per_kn", "mm/kN", "wheel-centre lateral displacement per kN of Fy, along it"),
    ("longitudinal_compliance_steer_deg_per_kn", "deg/kN", "toe-in per kN of braking force (−x) at the contact point"),
    ("aligning_torque_compliance_steer_deg_per_knm", "deg/kN·m", "axle steer (left +) per kN·m of Mz (left +) per wheel"),
    ("toe_loop_width_deg", "deg", "toe loop width at design height in the bump test"),
    ("camber_loop_width_deg", "deg", "camber loop width at design height in the bump test"),
    ("toe_loop_width_max_deg", "deg", "largest toe loop width over ±20 mm of bump"),
    ("camber_loop_width_max_deg", "deg", "largest camber loop width over ±20 mm of bump"),
    ("wheel_rate_n_per_mm", "N/mm", "pad Fz per mm of wheel-centre travel in bump (wheel-centre rate; rigid rig wheels)"),
    ("ride_rate_n_per_mm", "N/mm", "the wheel rate in series with the tyre's vertical stiffness at its nominal load "
                                  "(VERTICAL_STIFFNESS of its .tir)"),
    ("half_track_change_mm_per_m", "mm/m", "wheel-centre half-track (outward +) per metre of wheel-centre travel in bump"),
    ("wheel_recession_mm_per_m", "mm/m", "wheel-centre rearward (−x) travel per metre of wheel-centre travel in bump"),
    ("roll_stiffness_nm_per_deg", "N·m/deg", "axle's roll moment (right minus left pad Fz × half the contact base) "
                                           "per degree of roll"),
    ("roll_stiffness_share_pct", "%", "axle's share of the car's roll stiffness (front + rear)"),
    ("roll_centre_height_kinematic_mm", "mm", "above the pads at design: the contact points' common lateral "
                                              "motion per radian of roll (instant centres; roll test, Fy = 0)"),
    ("roll_centre_height_force_mm", "mm", "above the pads at design: where the resultant of the ground forces "
                                          "crosses the centre plane under Fy (lateral test, pad heights held)"),
    ("braking_pad_fz_ratio", "N/N", "pad Fz per N of braking force (−x) at the contact point, pad heights held "
                                    "(side-view tan θ; + pushes the wheel down)"),
    ("rack_gain_deg_per_mm", "deg/mm", "mean road-wheel steer (left +) per mm of rack (left +), steering sweep"),
    ("steering_ratio", "-", "steering-wheel angle (the rack's travel per revolution) per road-wheel angle, "
                            "at straight ahead"),
    ("ackermann_pct", "%", "inner minus outer wheel's steer over that of Ackermann geometry (cot δo − cot δi = "
                           "contact base / wheelbase) at the sweep's ±80 % rack"),
    ("caster_deg", "deg", "steering axis (lower ball joint to top mount), its top rearward +, at design"),
    ("kingpin_inclination_deg", "deg", "steering axis, its top inboard +, at design"),
    ("scrub_radius_mm", "mm", "contact point's lateral offset outboard of where the axis meets the ground, at design"),
    ("mechanical_trail_mm", "mm", "where the axis meets the ground ahead of the contact point, at design"),
    ("braking_anti_pitch_pct", "%", "front: anti-dive, rear: anti-lift (SAE J670), the share of the braking "
                                    "load transfer h/L the linkage carries, this axle braking alone at the contact "
                                    "point (outboard brakes)"),
    ("drive_pad_fz_ratio", "N/N", "pad Fz per N of drive force (+x) at the wheel centre, pad heights held "
                                  "(side-view tan θ of the wheel centre's path; + pushes the wheel down)"),
    ("drive_anti_pitch_pct", "%", "front: anti-lift, rear: anti-squat (SAE J670), the share of the load transfer "
                                  "h/L under drive the linkage carries, this axle driving alone at its wheel centres "
                                  "(inboard drive shafts)"),
)

#: The front axle's metrics of the steering sweep and of its steering axis at design (none for the rear).
STEERING_METRICS = ("rack_gain_deg_per_mm", "steering_ratio", "ackermann_pct", "caster_deg", "kingpin_inclination_deg",
                    "scrub_radius_mm", "mechanical_trail_mm")

#: The metrics (keys of :data:`METRICS`) each test gives for an axle, the bump test's loop widths included.
TEST_METRICS = {
    "bump": ("bump_steer_deg_per_m", "bump_camber_deg_per_m", "wheel_rate_n_per_mm", "half_track_change_mm_per_m",
             "wheel_recession_mm_per_m", "toe_loop_width_deg", "toe_loop_width_max_deg", "camber_loop_width_deg",
             "camber_loop_width_max_deg"),
    "roll": ("roll_steer_deg_per_deg", "roll_camber_deg_per_deg", "roll_stiffness_nm_per_deg",
             "roll_centre_height_kinematic_mm"),
    "lateral": ("lateral_force_compliance_steer_deg_per_kn", "lateral_force_compliance_camber_deg_per_kn",
                "lateral_compliance_mm_per_kn", "roll_centre_height_force_mm"),
    "longitudinal": ("longitudinal_compliance_steer_deg_per_kn", "braking_pad_fz_ratio"),
    "drive": ("drive_pad_fz_ratio",),
    "aligning": ("aligning_torque_compliance_steer_deg_per_knm",),
}


#: One leg of a triangle: ``leg(quantity, corner)`` is that quantity's samples on the leg (SI;
#: quantities of :data:`elastokin.analysis.kc_test.WHEEL_QUANTITIES` and the tests' inputs ``rack``
#: and ``centre_fx``, :func:`elastokin.analysis.kc_test.rig_leg`; corners of
#: ``elastokin.vehicle.model.definition.CORNERS``). Rig samples and recorded runs both provide legs, so that
#: both use the definitions below.
Leg = Callable[[str, str], np.ndarray]


def contact_y(centre_y, toe, camber, sign: float, radius: float):
    """Lateral position [m] of a wheel's contact point, its centre less the radius along the wheel
    plane's up direction (``elastokin.vehicle.model.geometry.contact_point``'s y), from the centre's
    ``centre_y`` [m], toe-in and camber [rad] (scalars or arrays) on side ``sign`` (+1 left)."""
    return centre_y - sign * radius * np.cos(toe) * np.sin(camber)


def fit_window(test: str, amplitude: float, base: float) -> float:
    """Half-width of the fits of ``test`` [its fitted input's unit: m, N, N·m; roll: deg of roll]
    for an input of ``amplitude`` [m, N or N·m] and an axle's contact-point base ``base`` [m]."""
    return FIT_FRACTION * amplitude * _input_scale(test, base)


def triangle_metrics(test: str, axle: str, down: Leg, up: Leg, window: float, base: float,
                     radius: float = math.nan) -> dict[str, float]:
    """The gradients, compliances and rates of :data:`TEST_METRICS` that ``test`` (a :data:`TESTS`
    name) gives for ``axle``, fitted over ±``window`` (:func:`fit_window`); ``base`` [m] is the
    axle's contact-point base at design (roll and lateral), ``radius`` [m] the tyre's (roll's
    kinematic roll centre, left out when NaN)."""
    L, R = f"{axle}_left", f"{axle}_right"
    deg = np.degrees

    def slope(x: Callable[[Leg], np.ndarray], y: Callable[[Leg], np.ndarray]) -> float:
        return centre_slope(Branches(x(down), y(down), x(up), y(up)), window)

    def each(x: str, y: str, scale: Callable[[np.ndarray], np.ndarray] = deg) -> float:
        """Mean over the axle's two wheels of the slope of scale(quantity y) against quantity x."""
        return 0.5 * sum(slope(lambda g, c=c: g(x, c), lambda g, c=c: scale(g(y, c))) for c in (L, R))

    steer = lambda g: deg(0.5 * (g("steer", L) + g("steer", R)))
    # right minus left: the right wheel is the outer one in roll, and +Fy points inboard on it
    camber = lambda g: deg(g("camber", R) - g("camber", L)) / 2
    same = lambda v: v
    # the roll moment the axle's pads take about its centre line [N·m]
    roll_moment = lambda g: (g("pad_fz", R) - g("pad_fz", L)) * base / 2
    if test == "bump":
        return {"bump_steer_deg_per_m": each("pad_height", "toe"), "bump_camber_deg_per_m": each("pad_height", "camber"),
                "wheel_rate_n_per_mm": 1e-3 * each("wheel_travel", "pad_fz", same),
                "half_track_change_mm_per_m": 1e3 * each("wheel_travel", "half_track", same),
                "wheel_recession_mm_per_m": -1e3 * each("wheel_travel", "wheel_centre_x", same)}
    if test == "roll":
        roll = lambda g: deg((g("pad_height", R) - g("pad_height", L)) / base)
        # the outer wheel's camber to the ground gains the roll angle itself
        m = {"roll_steer_deg_per_deg": slope(roll, steer), "roll_camber_deg_per_deg": 1.0 + slope(roll, camber),
             "roll_stiffness_nm_per_deg": slope(roll, roll_moment)}
        if not math.isnan(radius):
            # the ground turns by −φ about the roll centre relative to the clamped body: the contact
            # points (centre − r × the wheel's up direction) move by −h·φ together
            mean_y = lambda g: 0.5 * sum(contact_y(g("wheel_centre_y", c), g("toe", c), g("camber", c), sign, radius)
                                         for c, sign in ((L, 1.0), (R, -1.0)))
            m["roll_centre_height_kinematic_mm"] = -1e3 * math.degrees(slope(roll, mean_y))
        return m
    if test == "lateral":
        fy = lambda g: g("pad_fy", L)
        # the ground forces' moment about (0, h) vanishes: h·ΣFy + (Fz_L − Fz_R)·base/2 = 0
        return {"lateral_force_compliance_steer_deg_per_kn": 1e3 * slope(fy, steer),
                "lateral_force_compliance_camber_deg_per_kn": 1e3 * slope(fy, camber),
                "lateral_compliance_mm_per_kn": 1e6 * each("pad_fy", "wheel_centre_y", same),
                "roll_centre_height_force_mm": 0.5e3 * slope(lambda g: 0.5 * (g("pad_fy", L) + g("pad_fy", R)),
                                                             roll_moment)}
    if test == "longitudinal":
        return {"longitudinal_compliance_steer_deg_per_kn": -1e3 * each("pad_fx", "toe"),
                "braking_pad_fz_ratio": -each("pad_fx", "pad_fz", same)}
    if test == "drive":
        return {"drive_pad_fz_ratio": each("centre_fx", "pad_fz", same)}
    if test == "aligning":
        return {"aligning_torque_compliance_steer_deg_per_knm": 1e3 * slope(lambda g: g("pad_mz", L), steer)}
    raise ValueError(f"unknown K&C test {test!r}; expected one of {', '.join(t.name for t in TESTS)}")


@dataclass(frozen=True)
class CarFigures:
    """What the car-level metrics of :func:`car_metrics` read of the vehicle."""

    wheelbase_m: float
    cg_height_m: float                       #: the whole car's centre of mass above the ground at design
    tyre_vertical_stiffness_n_per_m: float | None   #: None without a tyre property file
    rack_travel_per_rev_m: float             #: rack travel per steering-wheel revolution


def car_metrics(axles: dict[str, dict[str, float]], car: CarFigures) -> dict[str, dict[str, float]]:
    """``axles`` (each axle's :func:`triangle_metrics` of every test) with the metrics that need
    both axles or the car (:data:`METRICS`): each axle's share of the roll stiffness, its ride
    rate (left out without a tyre stiffness), its anti-dive (front) or anti-lift (rear) under
    braking and its anti-lift (front) or anti-squat (rear) under drive."""
    total_roll = sum(m["roll_stiffness_nm_per_deg"] for m in axles.values())
    out = {}
    for axle, m in axles.items():
        extra = {"roll_stiffness_share_pct": 100.0 * m["roll_stiffness_nm_per_deg"] / total_roll,
                 # a linkage pushing its wheel down under braking (pad Fz up) pushes the body up:
                 # anti-dive at the front, pro-lift at the rear
                 "braking_anti_pitch_pct": (1.0 if axle == "front" else -1.0) * 100.0 * m["braking_pad_fz_ratio"]
                                           * car.wheelbase_m / car.cg_height_m,
                 # under drive the load moves the other way: pushing the wheel down is anti-squat at the
                 # rear, pro-lift at the front
                 "drive_anti_pitch_pct": (-1.0 if axle == "front" else 1.0) * 100.0 * m["drive_pad_fz_ratio"]
                                         * car.wheelbase_m / car.cg_height_m}
        if car.tyre_vertical_stiffness_n_per_m is not None:
            tyre = 1e-3 * car.tyre_vertical_stiffness_n_per_m
            extra["ride_rate_n_per_mm"] = 1.0 / (1.0 / m["wheel_rate_n_per_mm"] + 1.0 / tyre)
        out[axle] = m | extra
    return out


def steering_metrics(down: Leg, up: Leg, window: float, base: float, car: CarFigures) -> dict[str, float]:
    """The front axle's rack gain, steering ratio and Ackermann (:data:`METRICS`) from the steering
    sweep's legs (their ``rack`` quantity: the rack displacement [m], any corner), fitted over
    ±``window`` [m of rack]; ``base`` [m] is the front contact base."""
    L, R = "front_left", "front_right"
    branches = lambda y: Branches(down("rack", L), y(down), up("rack", L), y(up))
    gain = centre_slope(branches(lambda g: np.degrees(0.5 * (g("steer", L) + g("steer", R)))), window)  # deg/m
    ends = np.array([-window, window])
    left, right = (np.mean(branches(lambda g, c=c: g("steer", c)).on(ends), axis=0) for c in (L, R))
    ratios = []
    for i in range(2):   # each end: the inner wheel is on the side the car turns to
        inner, outer = (left[i], right[i]) if left[i] + right[i] > 0 else (-right[i], -left[i])
        ackermann_outer = math.atan(1.0 / (1.0 / math.tan(inner) + base / car.wheelbase_m))
        ratios.append((inner - outer) / (inner - ackermann_outer))
    return {"rack_gain_deg_per_mm": 1e-3 * gain,
            "steering_ratio": 360.0 / car.rack_travel_per_rev_m / gain,
            "ackermann_pct": 100.0 * float(np.mean(ratios))}


def bump_loop_widths(axle: str, down: Leg, up: Leg, window: float) -> dict[str, float]:
    """Toe and camber loop widths [deg] of the bump test (keys of :data:`METRICS`), mean of the
    axle's two wheels, against the pad height over ±``window`` [m]."""
    m = {}
    for angle in ("toe", "camber"):
        widths = [loop_width(Branches(down("pad_height", c), np.degrees(down(angle, c)),
                                      up("pad_height", c), np.degrees(up(angle, c))), window)
                  for c in (f"{axle}_left", f"{axle}_right")]
        m[f"{angle}_loop_width_deg"] = float(np.mean([w[0] for w in widths]))
        m[f"{angle}_loop_width_max_deg"] = float(np.mean([w[1] for w in widths]))
    return m


def _input_scale(test: str, base: float) -> float:
    """Factor from a test's amplitude to the unit of its fitted input (roll: pad m → body deg)."""
    return math.degrees(2.0 / base) if test == "roll" else 1.0


#: Gradients against wheel travel or pad height over at most ±20 mm around design (spec §4), the
#: window of `vsim kc`'s bump test [m].
BUMP_WINDOW_M = fit_window("bump", TEST["bump"].amplitude, math.nan)
