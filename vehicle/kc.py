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

import mujoco
import numpy as np

from vehicle.builder import BuildOptions
from vehicle.definition import VehicleDefinition
from vehicle.rig import KCRig, RigOutputs

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


def kc_metrics(rig: KCRig) -> dict[str, dict[str, float]]:
    """Run the K&C sequence (:data:`TESTS`) on ``rig``; metrics per axle (keys of :data:`METRICS`)."""
    base = _design_contact_base(rig)
    runs = {t.name: (t, run_triangle(rig, t)) for t in TESTS}
    deg = math.degrees
    out: dict[str, dict[str, float]] = {}
    for axle in AXLES:
        L, R = f"{axle}_left", f"{axle}_right"

        def slope(test: str, x, y) -> float:
            t, (down, up) = runs[test]
            return centre_slope(branches(down, up, x, y), FIT_FRACTION * t.amplitude * _input_scale(test, base[axle]))

        def each(test: str, x, y) -> float:
            """Mean over the axle's two wheels of slope(x(wheel), y(wheel))."""
            return 0.5 * sum(slope(test, lambda o, c=c: x(o.wheels[c]), lambda o, c=c: y(o.wheels[c])) for c in (L, R))

        roll = lambda o: deg((o.wheels[R].pad_height - o.wheels[L].pad_height) / base[axle])
        steer = lambda o: deg(0.5 * (o.wheels[L].steer + o.wheels[R].steer))
        m = {
            "bump_steer_deg_per_m": each("bump", lambda w: w.pad_height, lambda w: deg(w.toe)),
            "bump_camber_deg_per_m": each("bump", lambda w: w.pad_height, lambda w: deg(w.camber)),
            "roll_steer_deg_per_deg": slope("roll", roll, steer),
            # right wheel outer; its camber to the ground gains the roll angle itself
            "roll_camber_deg_per_deg": 1.0 + slope("roll", roll, lambda o: deg(o.wheels[R].camber - o.wheels[L].camber) / 2),
            "lateral_force_compliance_steer_deg_per_kn": 1e3 * slope("lateral", lambda o: o.wheels[L].pad_force[1], steer),
            # +Fy points inboard on the right wheel, outboard on the left
            "lateral_force_compliance_camber_deg_per_kn": 1e3 * slope(
                "lateral", lambda o: o.wheels[L].pad_force[1], lambda o: deg(o.wheels[R].camber - o.wheels[L].camber) / 2),
            "lateral_compliance_mm_per_kn": 1e6 * each("lateral", lambda w: w.pad_force[1], lambda w: w.wheel_centre[1]),
            "longitudinal_compliance_steer_deg_per_kn": -1e3 * each("longitudinal", lambda w: w.pad_force[0],
                                                                     lambda w: deg(w.toe)),
            "aligning_torque_compliance_steer_deg_per_knm": 1e3 * slope("aligning", lambda o: o.wheels[L].pad_torque, steer),
        }
        t, (down, up) = runs["bump"]
        window = FIT_FRACTION * t.amplitude
        for name, angle in (("toe", "toe"), ("camber", "camber")):
            widths = [loop_width(branches(down, up, lambda o, c=c: o.wheels[c].pad_height,
                                           lambda o, c=c: deg(getattr(o.wheels[c], angle))), window) for c in (L, R)]
            m[f"{name}_loop_width_deg"] = float(np.mean([w[0] for w in widths]))
            m[f"{name}_loop_width_max_deg"] = float(np.mean([w[1] for w in widths]))
        out[axle] = m
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

