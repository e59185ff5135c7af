"""Standard K&C metrics (spec vehicle.md §4) from quasi-static triangles on the virtual rig.

Both axles are tested at once (the body is clamped, so the axles do not interact). Each test
starts from the design pose with virgin bushings, rests :data:`SETTLE` s, then runs the triangle
0 → +A → −A → +A at a constant rate; the +A → −A leg gives the unloading (down) branch, the
−A → +A leg the loading (up) branch. The centre line is the mean of the two branches; a
compliance or gradient is its least-squares slope over ±80 % of A around design (±20 mm in bump);
a loop width is the difference between the branches at design (and its maximum over that range).

========  ======================================  ============  ======================  =========
test      input (every wheel of both axles)        A             rate                    duration
========  ======================================  ============  ======================  =========
bump      pad heights in phase (bump +)            25 mm         25 mm/s (≈ thesis       5 s
                                                                 60 mm at 0.1 Hz)
roll      pads in opposite phase, right up         25 mm         25 mm/s                 5 s
lateral   Fy at the contact points, +y (left)      2 kN/wheel    2 kN/s                  5 s
longit.   Fx at the contact points, −x (braking)   1.5 kN/wheel  2 kN/s                  3.75 s
aligning  Mz about the vertical, +z (to the left)  150 N·m       200 N·m/s               3.75 s
========  ======================================  ============  ======================  =========

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

import mujoco
import numpy as np

from vehicle.model.builder import BuildOptions
from vehicle.model.definition import VehicleDefinition
from vehicle.simulation.rig import KCRig, RigOutputs, WheelOutputs

SETTLE = 0.5             #: rest before each test [s]
FIT_FRACTION = 0.8       #: slopes and loop widths over ±80 % of the amplitude
SAMPLES_PER_LEG = 200   #: samples on each of the down and up legs
AXLES = ("front", "rear")


@dataclass(frozen=True)
class Triangle:
    """One quasi-static triangle applied to all four wheels."""

    name: str
    input: str               #: ``pads``, ``fx``, ``fy`` or ``mz`` (see :meth:`KCRig.ramp`)
    pattern: tuple[float, float, float, float]   #: per corner (order of CORNERS), times the amplitude
    amplitude: float         #: [m, N or N·m]
    rate: float              #: [m/s, N/s or N·m/s]


TESTS = (
    Triangle("bump", "pads", (1, 1, 1, 1), 0.025, 0.025),
    Triangle("roll", "pads", (-1, 1, -1, 1), 0.025, 0.025),
    Triangle("lateral", "fy", (1, 1, 1, 1), 2000.0, 2000.0),
    Triangle("longitudinal", "fx", (-1, -1, -1, -1), 1500.0, 2000.0),
    Triangle("aligning", "mz", (1, 1, 1, 1), 150.0, 200.0),
)
TEST = {t.name: t for t in TESTS}   #: the tests by name

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
)


@dataclass(frozen=True)
class Branches:
    """A measured output against its input on the unloading (down) and loading (up) legs."""

    x_down: np.ndarray
    y_down: np.ndarray
    x_up: np.ndarray
    y_up: np.ndarray

    def on(self, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(down, up) values interpolated at ``grid`` (increasing)."""
        d, u = np.argsort(self.x_down), np.argsort(self.x_up)
        return np.interp(grid, self.x_down[d], self.y_down[d]), np.interp(grid, self.x_up[u], self.y_up[u])


def centre_slope(b: Branches, window: float) -> float:
    """Least-squares slope of the centre line (mean of the branches) over ±``window``."""
    grid = np.linspace(-window, window, 41)
    down, up = b.on(grid)
    return float(np.polyfit(grid, 0.5 * (down + up), 1)[0])


def loop_width(b: Branches, window: float) -> tuple[float, float]:
    """(width at design, largest width over ±``window``) of a loop."""
    grid = np.linspace(-window, window, 41)
    down, up = b.on(grid)
    width = np.abs(down - up)
    return float(np.interp(0.0, grid, width)), float(width.max())


def run_triangle(rig: KCRig, test: Triangle) -> tuple[list[RigOutputs], list[RigOutputs]]:
    """Run ``test`` from design with virgin bushings; returns the (down, up) legs' samples."""
    rig.reset()
    rig.settle(SETTLE)
    peak = test.amplitude * np.asarray(test.pattern, float)
    zero = np.zeros(4)
    leg = test.amplitude / test.rate
    rig.ramp(leg, 0, **{test.input: (zero, peak)})
    down = rig.ramp(2 * leg, SAMPLES_PER_LEG, **{test.input: (peak, -peak)})
    up = rig.ramp(2 * leg, SAMPLES_PER_LEG, **{test.input: (-peak, peak)})
    return down, up


def branches(down: list[RigOutputs], up: list[RigOutputs], x, y) -> Branches:
    """Branches of ``y(sample)`` against ``x(sample)`` from the samples of :func:`run_triangle`."""
    return Branches(np.array([x(o) for o in down]), np.array([y(o) for o in down]),
                    np.array([x(o) for o in up]), np.array([y(o) for o in up]))


def _design_contact_base(rig: KCRig) -> dict[str, float]:
    """Lateral distance between the left and right contact points of each axle at design [m]."""
    rig.reset()
    mujoco.mj_forward(rig.model, rig.data)
    site = lambda c: mujoco.mj_name2id(rig.model, mujoco.mjtObj.mjOBJ_SITE, rig.car.corners[c]["contact_site"])
    return {a: float(rig.data.site_xpos[site(f"{a}_left"), 1] - rig.data.site_xpos[site(f"{a}_right"), 1])
            for a in AXLES}


#: Per-wheel quantities the metric definitions read, from one rig sample's wheel (SI).
WHEEL_QUANTITIES: dict[str, Callable[[WheelOutputs], float]] = {
    "pad_height": lambda w: w.pad_height, "toe": lambda w: w.toe, "camber": lambda w: w.camber,
    "steer": lambda w: w.steer, "wheel_centre_y": lambda w: w.wheel_centre[1],
    "pad_fx": lambda w: w.pad_force[0], "pad_fy": lambda w: w.pad_force[1], "pad_mz": lambda w: w.pad_torque,
}

#: One leg of a triangle: ``leg(quantity, corner)`` is that quantity's samples on the leg (SI;
#: quantities of :data:`WHEEL_QUANTITIES`, corners of ``vehicle.model.builder.CORNERS``). Rig samples and
#: recorded runs both provide legs, so that both use the definitions below.
Leg = Callable[[str, str], np.ndarray]


def rig_leg(samples: list[RigOutputs]) -> Leg:
    """The :data:`Leg` of samples measured on the rig."""
    return lambda quantity, corner: np.array([WHEEL_QUANTITIES[quantity](o.wheels[corner]) for o in samples])


def fit_window(test: str, amplitude: float, base: float) -> float:
    """Half-width of the fits of ``test`` [its fitted input's unit: m, N, N·m; roll: deg of roll]
    for an input of ``amplitude`` [m, N or N·m] and an axle's contact-point base ``base`` [m]."""
    return FIT_FRACTION * amplitude * _input_scale(test, base)


def triangle_metrics(test: str, axle: str, down: Leg, up: Leg, window: float, base: float) -> dict[str, float]:
    """The gradients and compliances of :data:`METRICS` that ``test`` (a :data:`TESTS` name) gives
    for ``axle``, fitted over ±``window`` (:func:`fit_window`); ``base`` [m] is the axle's
    contact-point base at design (used by roll only)."""
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
    if test == "bump":
        return {"bump_steer_deg_per_m": each("pad_height", "toe"), "bump_camber_deg_per_m": each("pad_height", "camber")}
    if test == "roll":
        roll = lambda g: deg((g("pad_height", R) - g("pad_height", L)) / base)
        # the outer wheel's camber to the ground gains the roll angle itself
        return {"roll_steer_deg_per_deg": slope(roll, steer), "roll_camber_deg_per_deg": 1.0 + slope(roll, camber)}
    if test == "lateral":
        fy = lambda g: g("pad_fy", L)
        return {"lateral_force_compliance_steer_deg_per_kn": 1e3 * slope(fy, steer),
                "lateral_force_compliance_camber_deg_per_kn": 1e3 * slope(fy, camber),
                "lateral_compliance_mm_per_kn": 1e6 * each("pad_fy", "wheel_centre_y", lambda v: v)}
    if test == "longitudinal":
        return {"longitudinal_compliance_steer_deg_per_kn": -1e3 * each("pad_fx", "toe")}
    if test == "aligning":
        return {"aligning_torque_compliance_steer_deg_per_knm": 1e3 * slope(lambda g: g("pad_mz", L), steer)}
    raise ValueError(f"unknown K&C test {test!r}; expected one of {', '.join(t.name for t in TESTS)}")


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


def kc_metrics(rig: KCRig) -> dict[str, dict[str, float]]:
    """Run the K&C sequence (:data:`TESTS`) on ``rig``; metrics per axle (keys of :data:`METRICS`)."""
    base = _design_contact_base(rig)
    legs = {t.name: [rig_leg(samples) for samples in run_triangle(rig, t)] for t in TESTS}
    out: dict[str, dict[str, float]] = {}
    for axle in AXLES:
        m = {}
        for t in TESTS:
            m |= triangle_metrics(t.name, axle, *legs[t.name], fit_window(t.name, t.amplitude, base[axle]), base[axle])
        out[axle] = m | bump_loop_widths(axle, *legs["bump"], fit_window("bump", TEST["bump"].amplitude, base[axle]))
    rig.reset()
    return out


def _input_scale(test: str, base: float) -> float:
    """Factor from a test's amplitude to the unit of its fitted input (roll: pad m → body deg)."""
    return math.degrees(2.0 / base) if test == "roll" else 1.0


def vehicle_kc(vehicle: VehicleDefinition, options: BuildOptions = BuildOptions()) -> dict[str, dict[str, float]]:
    """K&C metrics of ``vehicle`` built with ``options`` (on a fresh rig)."""
    return kc_metrics(KCRig(vehicle, options))


def format_table(metrics: dict[str, dict[str, float]]) -> str:
    """The metrics as an aligned text table with units and sign conventions."""
    rows = [f"{'metric':<46} {'unit':<9} {'front':>9} {'rear':>9}  convention"]
    for key, unit, convention in METRICS:
        rows.append(f"{key:<46} {unit:<9} {metrics['front'][key]:>9.4f} {metrics['rear'][key]:>9.4f}  {convention}")
    return "\n".join(rows)

