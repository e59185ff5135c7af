"""The K&C report's rates, roll centres and anti-pitch against closed forms and independent
computations on the default car (spec vehicle.md §4; the definitions in
elastokin.analysis.kc_metrics.METRICS): the springs and the bar enter the wheel rate and the roll
stiffness through their motion ratio squared, the roll centre found by the lateral-force test is the
one the roll test's kinematics give, and the trailing arm's recession and anti-lift follow from its
pivot's place."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from elastokin.analysis.kc_metrics import CarFigures, fit_window, steering_metrics, triangle_metrics
from elastokin.analysis.kc_test import car_figures, rig_leg, vehicle_kc
from elastokin.analysis.loops import Branches, centre_slope
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.tyres.magic_formula import coefficients
from elastokin.tyres.tir_file import read_tir
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.geometry import contact_point
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.kc_tests import STEERING, TEST, triangle_input
from elastokin.vehicle.simulation.kc_triangles import design_contact_base, run_triangle
from elastokin.vehicle.simulation.rig import KCRig

SEED = int(os.environ.get("VSIM_TEST_SEED", "0"))
SPRINGS = {"front": ("front_left_spring", "front_right_spring"), "rear": ("rear_spring_left", "rear_spring_right")}


def vehicle_with(tmp_path, name: str, replacements: dict[str, str]):
    """The default car with its file's text replaced (each old text must be there once)."""
    text = DEFAULT_VEHICLE.read_text()
    for old, new in replacements.items():
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    return load_vehicle(path)


def metrics_of(rig: KCRig, test: str) -> tuple[dict[str, dict[str, float]], tuple]:
    """(per axle, ``test``'s metrics; its (down, up) samples) on ``rig``."""
    down, up = run_triangle(rig, TEST[test])
    base = design_contact_base(rig)
    return ({axle: triangle_metrics(test, axle, rig_leg(down, TEST[test]), rig_leg(up, TEST[test]),
                                    fit_window(test, TEST[test].amplitude, base[axle]), base[axle],
                                    rig.vehicle.tyre.radius) for axle in base}, (down, up))


def spring_ratio(samples: tuple, spring: str, x, rate: float, window: float) -> float:
    """A spring's compression per unit of ``x(sample)``, from its force [N] and rate [N/m]."""
    down, up = samples
    b = Branches(np.array([x(o) for o in down]), np.array([o.spring_force[spring] for o in down]) / rate,
                 np.array([x(o) for o in up]), np.array([o.spring_force[spring] for o in up]) / rate)
    return centre_slope(b, window)


@pytest.fixture(scope="module")
def default_rig():
    return KCRig(load_vehicle(DEFAULT_VEHICLE))


def test_springs_and_bar_enter_wheel_rate_and_roll_stiffness_by_their_motion_ratio_squared(tmp_path, default_rig):
    """Springs ×1.5 and the bar ×2: the wheel rate gains Δk·MR², the roll stiffness Δk·MR²·t²/2
    from the springs plus Δk_bar·MR²·t² from the bar (a tendon of left-minus-right strut length),
    with MR each spring's compression per metre of wheel travel (bump) or of pad height (roll)
    read from its own force, t the contact base; the bar leaves the wheel rate alone."""
    v = default_rig.vehicle
    stiffer = KCRig(vehicle_with(tmp_path, "stiffer", {"rate: 28000.0": "rate: 42000.0",
                                                        "rate: 36000.0": "rate: 54000.0",
                                                        "rate: 10000.0": "rate: 20000.0"}))
    base = design_contact_base(default_rig)
    bump0, bump_samples = metrics_of(default_rig, "bump")
    roll0, roll_samples = metrics_of(default_rig, "roll")
    bump1, _ = metrics_of(stiffer, "bump")
    roll1, _ = metrics_of(stiffer, "roll")
    window = fit_window("bump", TEST["bump"].amplitude, math.nan)
    for axle, k in (("front", v.front.spring.rate), ("rear", v.rear.spring.rate)):
        left, right = SPRINGS[axle]
        mr = spring_ratio(bump_samples, left, lambda o: o.wheels[f"{axle}_left"].travel, k, window)
        assert 0.5 < mr < 1.2, mr   # a strut or a spring on the arm
        gain = 1e-3 * 0.5 * k * mr ** 2   # Δk = k/2 [N/mm]
        assert bump1[axle]["wheel_rate_n_per_mm"] - bump0[axle]["wheel_rate_n_per_mm"] == pytest.approx(gain, rel=0.01)
        # roll: right pads up; each spring's compression per metre of its own pad
        mr_roll = 0.5 * (spring_ratio(roll_samples, right, lambda o: o.wheels[f"{axle}_right"].pad_height, k, window)
                         + spring_ratio(roll_samples, left, lambda o: o.wheels[f"{axle}_left"].pad_height, k, window))
        per_rad = 0.5 * k * mr_roll ** 2 * base[axle] ** 2 / 2
        if axle == "front":   # the bar acts on the strut's length, the spring's axis
            per_rad += v.front.anti_roll_rate * mr_roll ** 2 * base[axle] ** 2
        assert (roll1[axle]["roll_stiffness_nm_per_deg"] - roll0[axle]["roll_stiffness_nm_per_deg"]
                == pytest.approx(math.radians(per_rad), rel=0.01)), axle
    # the bar alone: the wheel rate in bump as without it
    bar_only = KCRig(vehicle_with(tmp_path, "bar", {"rate: 10000.0": "rate: 20000.0"}))
    bump2, _ = metrics_of(bar_only, "bump")
    assert bump2["front"]["wheel_rate_n_per_mm"] == pytest.approx(bump0["front"]["wheel_rate_n_per_mm"], rel=1e-3)


def test_the_force_and_kinematic_roll_centres_agree(default_rig):
    """The lateral-force test's roll centre (where the ground forces' resultant crosses the centre
    plane) is the roll test's (the contact points' common lateral motion per radian of roll), by
    virtual work on a linkage whose joints do no work; on the independent front it is also the
    instant-centre construction from the bump test: h = t/2 × the contact point's outward motion per
    metre of bump, the wheel centre's half-track change less r × the camber gain."""
    roll, _ = metrics_of(default_rig, "roll")
    lateral, _ = metrics_of(default_rig, "lateral")
    bump, _ = metrics_of(default_rig, "bump")
    base, r = design_contact_base(default_rig), default_rig.vehicle.tyre.radius
    for axle in ("front", "rear"):
        kinematic, force = roll[axle]["roll_centre_height_kinematic_mm"], lateral[axle]["roll_centre_height_force_mm"]
        assert 20.0 < kinematic < 300.0, (axle, kinematic)   # above the ground, below the wheel centres' 303 mm
        assert force == pytest.approx(kinematic, abs=3.0), axle   # the bushings' compliance: 1.4 mm here
    outward = bump["front"]["half_track_change_mm_per_m"] * 1e-3 - r * math.radians(bump["front"]["bump_camber_deg_per_m"])
    assert 1e3 * base["front"] / 2 * outward == pytest.approx(roll["front"]["roll_centre_height_kinematic_mm"], abs=3.0)


def test_the_trailing_arm_recession_and_anti_lift_follow_its_pivot(tmp_path):
    """In parallel bump the twist beam turns about its arms' pivots: the wheel centre recedes by
    (z_c − z_p)/(x_c − x_p) per metre of bump; braking at the contact point with the pads held, the
    arm's moment about its pivot gives the pad ΔFz = −z_p/(x_p − x_c) per N of braking force, the
    side-view tan θ, and an anti-lift of tan θ·L/h. The pivot is drawn from the seed."""
    rng = np.random.default_rng(SEED)
    dz = float(rng.uniform(-0.030, 0.030))
    pivot = load_vehicle(DEFAULT_VEHICLE).rear.hardpoints["arm_pivot"]
    moved = (pivot[0], pivot[1], round(pivot[2] + dz, 4))
    old = f"arm_pivot:           [{pivot[0]:.3f}, {pivot[1]:.3f}, {pivot[2]:.3f}]"
    v = vehicle_with(tmp_path, "pivot", {old: f"arm_pivot:           [{moved[0]:.3f}, {moved[1]:.3f}, {moved[2]:.4f}]"})
    rig = KCRig(v)
    bump, _ = metrics_of(rig, "bump")
    braking, _ = metrics_of(rig, "longitudinal")
    (xc, _, zc), (xp, _, zp) = v.rear.hardpoints["wheel_centre"], v.rear.hardpoints["arm_pivot"]
    assert bump["rear"]["wheel_recession_mm_per_m"] == pytest.approx(1e3 * (zc - zp) / (xc - xp), rel=0.02)
    tan_theta = -zp / (xp - xc)
    assert braking["rear"]["braking_pad_fz_ratio"] == pytest.approx(tan_theta, rel=0.015)
    car = car_figures(v)
    assert car.wheelbase_m == pytest.approx(2.608)
    # the whole car's centre of mass: under the body's (543 mm), lowered by the wheels and axles
    assert 0.50 < car.cg_height_m < 0.543
    assert car.tyre_vertical_stiffness_n_per_m == coefficients(read_tir(v.tyre.property_file))["VERTICAL_STIFFNESS"]


def test_the_drive_at_the_wheel_centre_is_the_bump_recession_by_reciprocity(tmp_path):
    """A drive force Fx at a wheel centre with the pads held loads the pad by the wheel centre's
    fore-aft motion per unit of pad travel in bump, by Maxwell-Betti reciprocity on the clamped
    car (the bump test's pad force does no work in the drive test, whose pad does not move):
    ΔFz/Fx = −dx_c/dz_pad, measured in the bump test, within 2 % (5e-4 where the ratio nears zero:
    the soft closures and the fits). Reciprocity needs elastic laws: the bushings
    are linear here (the default car's hysteretic front laws move the front's small ratio by 14 %).
    On the twist beam the ratio is its arms' pivot's (z_c − z_p)/(x_c − x_p); the pivot is drawn
    from the seed. Anti-squat (rear) and anti-lift (front), in
    :func:`test_the_car_level_metrics_of_vsim_kc`, are these ratios scaled by L/h."""
    rng = np.random.default_rng(SEED + 2)
    dz = float(rng.uniform(-0.030, 0.030))
    pivot = load_vehicle(DEFAULT_VEHICLE).rear.hardpoints["arm_pivot"]
    old = f"arm_pivot:           [{pivot[0]:.3f}, {pivot[1]:.3f}, {pivot[2]:.3f}]"
    v = vehicle_with(tmp_path, "pivot", {old: f"arm_pivot:           [{pivot[0]:.3f}, {pivot[1]:.3f}, {pivot[2] + dz:.4f}]"})
    rig = KCRig(v, BuildOptions(bushing_model="linear"))
    drive, _ = metrics_of(rig, "drive")
    _, (down, up) = metrics_of(rig, "bump")
    window = fit_window("bump", TEST["bump"].amplitude, math.nan)

    def fore_aft_per_pad_travel(corner: str) -> float:
        x = lambda leg: np.array([o.wheels[corner].pad_height for o in leg])
        y = lambda leg: np.array([o.wheels[corner].wheel_centre[0] for o in leg])
        return centre_slope(Branches(x(down), y(down), x(up), y(up)), window)

    for axle in ("front", "rear"):
        recession = -0.5 * (fore_aft_per_pad_travel(f"{axle}_left") + fore_aft_per_pad_travel(f"{axle}_right"))
        assert drive[axle]["drive_pad_fz_ratio"] == pytest.approx(recession, rel=0.02, abs=5e-4), axle
    (xc, _, zc), (xp, _, zp) = v.rear.hardpoints["wheel_centre"], v.rear.hardpoints["arm_pivot"]
    assert drive["rear"]["drive_pad_fz_ratio"] == pytest.approx((zc - zp) / (xc - xp), rel=0.02, abs=5e-4)


def test_the_car_level_metrics_of_vsim_kc():
    """Shares add up to 100 %; the ride rate is the wheel rate in series with the tyre; anti-dive
    and anti-lift are the braking ratios scaled by L/h with their signs (a rear arm pulling its
    wheel up under braking holds the tail down), anti-lift (front) and anti-squat (rear) under
    drive the drive ratios."""
    v = load_vehicle(DEFAULT_VEHICLE)
    m, car = vehicle_kc(v), car_figures(v)
    assert m["front"]["roll_stiffness_share_pct"] + m["rear"]["roll_stiffness_share_pct"] == pytest.approx(100.0)
    kt = car.tyre_vertical_stiffness_n_per_m * 1e-3
    for axle in ("front", "rear"):
        kw = m[axle]["wheel_rate_n_per_mm"]
        assert m[axle]["ride_rate_n_per_mm"] == pytest.approx(kw * kt / (kw + kt), rel=1e-12)
        assert m[axle]["ride_rate_n_per_mm"] < kw
    assert m["rear"]["braking_pad_fz_ratio"] < 0 < m["rear"]["braking_anti_pitch_pct"]
    assert m["front"]["braking_anti_pitch_pct"] == pytest.approx(
        100 * m["front"]["braking_pad_fz_ratio"] * car.wheelbase_m / car.cg_height_m, rel=1e-12)
    # a wheel pushed down under drive holds the body up: anti-squat at the rear, pro-lift at the front
    for axle, sign in (("front", -1.0), ("rear", 1.0)):
        assert m[axle]["drive_anti_pitch_pct"] == pytest.approx(
            sign * 100 * m[axle]["drive_pad_fz_ratio"] * car.wheelbase_m / car.cg_height_m, rel=1e-12)


def test_the_front_wheels_steer_about_the_axis_their_hardpoints_give(tmp_path):
    """The steering sweep's measured wheel motion against the design axis of `vsim kc` (lower ball
    joint to top mount, the top mount moved fore-aft by an offset drawn from the seed): turning by δ
    about an axis of caster τ and inclination σ, a wheel's camber goes as ±tan τ·δ + tan σ·δ²/2
    (+ on the left) and its centre moves by (−tan σ·r_z − r_y, r_x + tan τ·r_z) per radian, with
    r = centre − the axis's ground point."""
    rng = np.random.default_rng(SEED + 1)
    dx = float(rng.uniform(-0.030, 0.030))
    top = load_vehicle(DEFAULT_VEHICLE).front.hardpoints["strut_top"]
    old = f"strut_top:           [{top[0]:.3f}, {top[1]:.3f}, {top[2]:.3f}]"
    v = vehicle_with(tmp_path, "caster", {old: f"strut_top:           [{top[0] + dx:.4f}, {top[1]:.3f}, {top[2]:.3f}]"})
    design = vehicle_kc(v)["front"]
    rig = KCRig(v)
    down, up = run_triangle(rig, STEERING)
    grid = np.linspace(-0.8 * STEERING.amplitude, 0.8 * STEERING.amplitude, 81)

    def centre_line(corner: str, y) -> np.ndarray:
        b = Branches(*[np.array(a) for a in (
            [triangle_input(STEERING, o.time) for o in down], [y(o.wheels[corner]) for o in down],
            [triangle_input(STEERING, o.time) for o in up], [y(o.wheels[corner]) for o in up])])
        return np.mean(b.on(grid), axis=0)

    f = v.front
    contact = contact_point(f.hardpoints["wheel_centre"], f.static_toe, f.static_camber, 1.0, v.tyre.radius)
    for corner, sign in (("front_left", 1.0), ("front_right", -1.0)):
        steer = centre_line(corner, lambda w: w.steer)
        camber = np.polyfit(steer, centre_line(corner, lambda w: w.camber), 3)
        assert math.degrees(math.atan(sign * camber[2])) == pytest.approx(design["caster_deg"], abs=0.15), corner
        assert math.degrees(math.atan(2 * camber[1])) == pytest.approx(design["kingpin_inclination_deg"], abs=0.15)
    steer = centre_line("front_left", lambda w: w.steer)
    vx, vy = (np.polyfit(steer, centre_line("front_left", lambda w, i=i: w.wheel_centre[i]), 3)[2] for i in (0, 1))
    tan_caster, tan_kpi = (math.tan(math.radians(design[k])) for k in ("caster_deg", "kingpin_inclination_deg"))
    centre = np.array(f.hardpoints["wheel_centre"])
    rz = centre[2] - contact[2]
    ry, rx = -vx - tan_kpi * rz, vy - tan_caster * rz
    assert 1e3 * (contact[1] - centre[1] + ry) == pytest.approx(design["scrub_radius_mm"], abs=0.5)
    assert 1e3 * (centre[0] - contact[0] - rx) == pytest.approx(design["mechanical_trail_mm"], abs=0.5)


@pytest.mark.parametrize("share", [0.0, 0.5, 1.0])
def test_ackermann_is_the_share_of_the_ideal_steer_difference(share):
    """On legs whose outer wheel steers ``share`` of the way from parallel to Ackermann's angle
    (cot δo − cot δi = base / wheelbase) at either end of the sweep, the metric is 100·share %;
    the rack gain and the steering ratio are those of the mean steer's slope."""
    base, car = 1.5, CarFigures(2.6, 0.5, None, 0.05)
    rack = np.linspace(-STEERING.amplitude, STEERING.amplitude, 201)

    def steers(r: float) -> tuple[float, float]:
        inner = math.atan(10.0 * abs(r))   # 10 rad per m of rack at the centre
        if inner == 0.0:
            return 0.0, 0.0
        outer = inner - share * (inner - math.atan(1.0 / (1.0 / math.tan(inner) + base / car.wheelbase_m)))
        return (inner, outer) if r > 0 else (-outer, -inner)   # (left, right)

    table = np.array([steers(r) for r in rack])
    leg = lambda q, c: rack if q == "rack" else table[:, 0 if c == "front_left" else 1]
    m = steering_metrics(leg, leg, 0.8 * STEERING.amplitude, base, car)
    assert m["ackermann_pct"] == pytest.approx(100.0 * share, abs=0.05)
    gain = np.polyfit(rack[np.abs(rack) <= 0.032], np.degrees(table.mean(axis=1))[np.abs(rack) <= 0.032], 1)[0]
    assert 1e3 * m["rack_gain_deg_per_mm"] == pytest.approx(gain, rel=0.01)
    assert m["steering_ratio"] == pytest.approx(360.0 / car.rack_travel_per_rev_m / gain, rel=0.01)
