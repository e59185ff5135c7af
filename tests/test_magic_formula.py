"""The Magic Formula 6.1 tyre (issue 26, step 2): the compiled evaluation against an independent
evaluation of the book's equations written here, its closed forms (cornering and slip stiffness
B·C·D, peak force D, vertical stiffness at the nominal load), the shipped 195/65 R15 file, bad
coefficient files, and the first-order transient slip against 1 − exp(−distance/σ)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from tests.tyre_helpers import assert_formula_is
from elastokin.core.errors import InputError
from elastokin.core.shipped import DEFAULT_TYRE
from elastokin.tyres import magic_formula as mf
from elastokin.tyres.tir_file import read_tir
from elastokin.tyres.transient import lag, low_speed_damping, relaxation_lengths


@pytest.fixture(scope="module")
def tyre() -> np.record:
    return mf.coefficients(read_tir(DEFAULT_TYRE))


def varied(tyre: np.record, seed: int) -> np.record:
    """The tyre with every scaling factor drawn in [0.7, 1.3] and the pressure off its nominal, so
    that no term of the equations hides behind a factor of 1 or a zero pressure change."""
    rng = np.random.default_rng(seed)
    record = tyre.copy()
    for key in mf.SCALING + mf.SCALING_61:
        record[key] = rng.uniform(0.7, 1.3)
    record["INFLPRES"] = record["NOMPRES"] * rng.uniform(0.8, 1.2)
    return record


def reference(c: dict, fz: float, kappa: float, alpha: float, gamma: float, vx: float) -> tuple:
    """Pacejka, Tire and Vehicle Dynamics, 3rd ed., eqs 4.E1–4.E78, evaluated line by line in plain
    Python for a tyre rolling forward (sgn V_cx = 1), no turn slip; Fy' of the trail at γ = 0."""
    def mf_curve(b, cc, d, e, x):
        return d * math.sin(cc * math.atan(b * x - e * (b * x - math.atan(b * x))))

    def sgn(x):
        return (x > 0) - (x < 0)

    fz0 = c["LFZO"] * c["FNOMIN"]
    dfz = fz / fz0 - 1.0
    # MF-Tyre's low-speed reduction of the shifts
    low = 1.0 if abs(vx) >= c["VXLOW"] else (1 - math.cos(math.pi * abs(vx) / c["VXLOW"])) / 2
    dpi = c["INFLPRES"] / c["NOMPRES"] - 1.0
    a = math.tan(alpha)
    g = math.sin(gamma)
    lmux_p = 10 * c["LMUX"] / (1 + 9 * c["LMUX"])
    lmuy_p = 10 * c["LMUY"] / (1 + 9 * c["LMUY"])
    # pure longitudinal
    shx = (c["PHX1"] + c["PHX2"] * dfz) * c["LHX"] * low
    kx = kappa + shx
    mux = (c["PDX1"] + c["PDX2"] * dfz) * (1 + c["PPX3"] * dpi + c["PPX4"] * dpi ** 2) * (1 - c["PDX3"] * g ** 2) \
        * c["LMUX"]
    ex = min(1.0, (c["PEX1"] + c["PEX2"] * dfz + c["PEX3"] * dfz ** 2) * (1 - c["PEX4"] * sgn(kx)) * c["LEX"])
    kxk = fz * (c["PKX1"] + c["PKX2"] * dfz) * math.exp(c["PKX3"] * dfz) * (1 + c["PPX1"] * dpi + c["PPX2"] * dpi ** 2) \
        * c["LKX"]
    cx = c["PCX1"] * c["LCX"]
    bx = kxk / (cx * mux * fz + 1e-6)
    fx0 = mf_curve(bx, cx, mux * fz, ex, kx) + fz * (c["PVX1"] + c["PVX2"] * dfz) * c["LVX"] * lmux_p * low

    # pure lateral (as a function of camber, for Fy' at γ = 0)
    def lateral(g):
        kya = c["PKY1"] * fz0 * (1 + c["PPY1"] * dpi) * (1 - c["PKY3"] * abs(g)) * c["LKY"] * math.sin(
            c["PKY4"] * math.atan(fz / ((c["PKY2"] + c["PKY5"] * g ** 2) * (1 + c["PPY2"] * dpi) * fz0)))
        svyg = fz * (c["PVY3"] + c["PVY4"] * dfz) * g * c["LKYC"] * lmuy_p
        kyg0 = fz * (c["PKY6"] + c["PKY7"] * dfz) * (1 + c["PPY5"] * dpi) * c["LKYC"]
        shy = low * ((c["PHY1"] + c["PHY2"] * dfz) * c["LHY"] + (kyg0 * g - svyg) / (kya + math.copysign(1e-6, kya)))
        svy = low * (fz * (c["PVY1"] + c["PVY2"] * dfz) * c["LVY"] * lmuy_p + svyg)
        ay = a + shy
        muy = (c["PDY1"] + c["PDY2"] * dfz) * (1 + c["PPY3"] * dpi + c["PPY4"] * dpi ** 2) * (1 - c["PDY3"] * g ** 2) \
            * c["LMUY"]
        ey = min(1.0, (c["PEY1"] + c["PEY2"] * dfz) * (1 + c["PEY5"] * g ** 2 - (c["PEY3"] + c["PEY4"] * g) * sgn(ay))
                 * c["LEY"])
        cy = c["PCY1"] * c["LCY"]
        by = kya / (cy * muy * fz + 1e-6)
        return mf_curve(by, cy, muy * fz, ey, ay) + svy, kya, muy, by, cy, shy, svy

    fy0, kya, muy, by, cy, shy, svy = lateral(g)
    # combined
    bxa = (c["RBX1"] + c["RBX3"] * g ** 2) * math.cos(math.atan(c["RBX2"] * kappa)) * c["LXAL"]
    exa = min(1.0, c["REX1"] + c["REX2"] * dfz)
    def xcos(x):
        return math.cos(c["RCX1"] * math.atan(bxa * x - exa * (bxa * x - math.atan(bxa * x))))

    fx = xcos(a + c["RHX1"]) / xcos(c["RHX1"]) * fx0
    shyk = c["RHY1"] + c["RHY2"] * dfz
    byk = (c["RBY1"] + c["RBY4"] * g ** 2) * math.cos(math.atan(c["RBY2"] * (a - c["RBY3"]))) * c["LYKA"]
    eyk = min(1.0, c["REY1"] + c["REY2"] * dfz)

    def gcos(x):
        return math.cos(c["RCY1"] * math.atan(byk * x - eyk * (byk * x - math.atan(byk * x))))

    gyk = gcos(kappa + shyk) / gcos(shyk)
    svyk = muy * fz * (c["RVY1"] + c["RVY2"] * dfz + c["RVY3"] * g) * math.cos(math.atan(c["RVY4"] * a)) \
        * math.sin(c["RVY5"] * math.atan(c["RVY6"] * kappa)) * c["LVYKA"]
    fy = gyk * fy0 + svyk
    # aligning moment
    r0 = c["UNLOADED_RADIUS"]
    kya_p = kya + math.copysign(1e-6, kya)
    at = a + c["QHZ1"] + c["QHZ2"] * dfz + (c["QHZ3"] + c["QHZ4"] * dfz) * g
    ar = a + shy + svy / kya_p
    bt = (c["QBZ1"] + c["QBZ2"] * dfz + c["QBZ3"] * dfz ** 2) * (1 + c["QBZ4"] * g + c["QBZ5"] * abs(g)) * c["LKY"] \
        / c["LMUY"]
    ct = c["QCZ1"]
    dt = fz * (c["QDZ1"] + c["QDZ2"] * dfz) * (1 - c["PPZ1"] * dpi) * c["LTR"] * (r0 / fz0) \
        * (1 + c["QDZ3"] * abs(g) + c["QDZ4"] * g ** 2)
    et = min(1.0, (c["QEZ1"] + c["QEZ2"] * dfz + c["QEZ3"] * dfz ** 2)
             * (1 + (c["QEZ4"] + c["QEZ5"] * g) * 2 / math.pi * math.atan(bt * ct * at)))
    br = c["QBZ9"] * c["LKY"] / c["LMUY"] + c["QBZ10"] * by * cy
    dr = fz * r0 * ((c["QDZ6"] + c["QDZ7"] * dfz) * c["LRES"] + ((c["QDZ8"] + c["QDZ9"] * dfz) * (1 + c["PPZ2"] * dpi)
                                                              + (c["QDZ10"] + c["QDZ11"] * dfz) * abs(g)) * g * c["LKZC"]) \
        * c["LMUY"] * math.cos(alpha)
    ratio2 = (kxk / kya_p) ** 2 * kappa ** 2
    at_eq = math.sqrt(at ** 2 + ratio2) * sgn(at)
    ar_eq = math.sqrt(ar ** 2 + ratio2) * sgn(ar)
    t = dt * math.cos(ct * math.atan(bt * at_eq - et * (bt * at_eq - math.atan(bt * at_eq)))) * math.cos(alpha)
    mzr = dr / math.sqrt(1 + (br * ar_eq) ** 2)
    s = r0 * (c["SSZ1"] + c["SSZ2"] * fy / fz0 + (c["SSZ3"] + c["SSZ4"] * dfz) * g) * c["LS"]
    mz = -t * gyk * lateral(0.0)[0] + mzr + s * fx
    # rolling resistance, fading below VXLOW
    v = vx / c["LONGVL"]
    my = -r0 * fz0 * c["LMY"] * (c["QSY1"] + c["QSY2"] * fx / fz0 + c["QSY3"] * abs(v) + c["QSY4"] * v ** 4
                                 + (c["QSY5"] + c["QSY6"] * fz / fz0) * gamma ** 2) \
        * (fz / fz0) ** c["QSY7"] * (c["INFLPRES"] / c["NOMPRES"]) ** c["QSY8"] * max(-1.0, min(1.0, vx / c["VXLOW"]))
    return fx, fy, mz, my


@pytest.mark.parametrize("seed", [None, 1, 2])
def test_the_compiled_formula_equals_the_books_equations_at_a_grid(tyre: np.record, seed: int | None) -> None:
    assert_formula_is(tyre if seed is None else varied(tyre, seed), reference)


@pytest.mark.parametrize("fz", [1500.0, 4000.0, 7000.0])
@pytest.mark.parametrize("gamma_deg", [0.0, 3.0])
def test_slip_stiffnesses_are_b_c_d_the_slopes_at_zero_slip(tyre: np.record, fz: float, gamma_deg: float) -> None:
    """K = B·C·D is the slope where the shifted slip is zero; the formula's slopes there equal the
    stiffnesses computed from PKX*/PKY* alone."""
    gamma = math.radians(gamma_deg)
    kxk, kya = mf.slip_stiffnesses(tyre, fz, gamma)
    h = 1e-6
    # zero of the shifted slip: the slope is flat in its neighbourhood to second order
    kappa0 = -(tyre["PHX1"] + tyre["PHX2"] * (fz / tyre["FNOMIN"] - 1))
    slope_x = (mf.forces(tyre, fz, kappa0 + h, 0.0, gamma, 20.0)[0] - mf.forces(tyre, fz, kappa0 - h, 0.0, gamma, 20.0)[0]) / (2 * h)
    alpha0 = _alpha_at_zero_shifted_slip(tyre, fz, gamma, kya)
    slope_y = (mf.forces(tyre, fz, 0.0, alpha0 + h, gamma, 20.0)[1] - mf.forces(tyre, fz, 0.0, alpha0 - h, gamma, 20.0)[1]) / (2 * h)
    # d(tan α)/dα = 1/cos²α at the (small) shifted zero
    assert slope_x == pytest.approx(kxk, rel=1e-5)
    assert slope_y * math.cos(alpha0) ** 2 == pytest.approx(kya, rel=1e-5)
    assert kya < 0 < kxk                        # ISO-W: a positive slip angle pulls the tyre to −y


def _alpha_at_zero_shifted_slip(tyre: np.record, fz: float, gamma: float, kya: float) -> float:
    fz0 = tyre["FNOMIN"]
    dfz = fz / fz0 - 1
    g = math.sin(gamma)
    svyg = fz * (tyre["PVY3"] + tyre["PVY4"] * dfz) * g
    kyg0 = fz * (tyre["PKY6"] + tyre["PKY7"] * dfz)
    shy = tyre["PHY1"] + tyre["PHY2"] * dfz + (kyg0 * g - svyg) / (kya - 1e-6)
    return math.atan(-shy)


def test_peak_side_force_is_d_and_friction_falls_with_load(tyre: np.record) -> None:
    alpha = np.radians(np.linspace(0.0, 40.0, 40001))
    peaks = []
    for fz in (2000.0, 4000.0, 6000.0):
        dfz = fz / tyre["FNOMIN"] - 1
        muy = tyre["PDY1"] + tyre["PDY2"] * dfz
        svy = fz * (tyre["PVY1"] + tyre["PVY2"] * dfz)
        fy = mf.evaluate(tyre, fz, alpha=alpha, vx=20.0)["Fy"]
        assert fy.min() == pytest.approx(-muy * fz + svy, rel=1e-6)   # C > 1: sin reaches −1 at the peak
        peaks.append(-fy.min() / fz)
    assert peaks[0] > peaks[1] > peaks[2]       # PDY2 < 0: the friction coefficient falls with load


def test_combined_slip_shares_one_friction(tyre: np.record) -> None:
    kappa, alpha = np.meshgrid(np.linspace(-0.4, 0.4, 81), np.radians(np.linspace(-15, 15, 61)))
    both = mf.evaluate(tyre, 4000.0, kappa, alpha, vx=20.0)
    pure_x = mf.evaluate(tyre, 4000.0, kappa, 0.0, vx=20.0)["Fx"]
    pure_y = mf.evaluate(tyre, 4000.0, 0.0, alpha, vx=20.0)["Fy"]
    strong = (np.abs(kappa) > 0.05) & (np.abs(alpha) > math.radians(3))
    assert np.all(np.abs(both["Fx"][strong]) < np.abs(pure_x[strong]))
    assert np.all(np.abs(both["Fy"][strong]) < np.abs(pure_y[strong]))
    # combining slips redistributes grip, it does not add to it (within the fit's 1 %)
    resultant = np.hypot(both["Fx"], both["Fy"])
    assert resultant.max() < 1.01 * max(np.abs(pure_x).max(), np.abs(pure_y).max())


def test_camber_thrust_leans_the_force_to_the_tilt_and_moments_align(tyre: np.record) -> None:
    tilt = mf.evaluate(tyre, 4000.0, gamma=np.radians([-3.0, 0.0, 3.0]), vx=20.0)["Fy"]
    assert tilt[2] < tilt[1] < tilt[0]          # γ > 0 tilts the top to −y: thrust to −y (PKY6 < 0)
    small = mf.evaluate(tyre, 4000.0, alpha=np.radians([-2.0, 2.0]), vx=20.0)
    assert small["Mz"][1] > 0 > small["Mz"][0]   # the aligning moment turns the wheel towards its path


def test_rolling_resistance_opposes_rolling_and_fades_out_at_rest(tyre: np.record) -> None:
    vx = np.array([0.0, 0.25, 0.5, 1.0, 16.7, -16.7])
    my = mf.evaluate(tyre, 4000.0, vx=vx)["My"]
    assert my[0] == 0.0 and my[4] < 0 < my[5]
    at_rest = mf.evaluate(tyre, 4000.0, gamma=0.05, vx=0.0)
    assert at_rest["Fx"] == 0.0 and at_rest["Fy"] == 0.0     # no offsets nor camber thrust standing still

    def speed_law(v):  # the file's QSY2 and camber terms are zero
        return tyre["QSY1"] + tyre["QSY3"] * abs(v / tyre["LONGVL"]) + tyre["QSY4"] * (v / tyre["LONGVL"]) ** 4

    for i in (1, 2):   # linear fade below VXLOW = 1 m/s
        assert my[i] / my[3] == pytest.approx(vx[i] * speed_law(vx[i]) / speed_law(1.0), rel=1e-12)
    assert -my[4] / tyre["UNLOADED_RADIUS"] / 4000.0 == pytest.approx(0.0106, abs=0.001)   # about QSY1 at nominal


def test_vertical_stiffness_at_the_nominal_load_is_the_files(tyre: np.record) -> None:
    rho = brentq(lambda d: mf.vertical_force(tyre, d, 0.0) - tyre["FNOMIN"], 1e-4, 0.1, xtol=1e-14)
    h = 1e-7
    slope = (mf.vertical_force(tyre, rho + h, 0.0) - mf.vertical_force(tyre, rho - h, 0.0)) / (2 * h)
    assert slope == pytest.approx(tyre["VERTICAL_STIFFNESS"], rel=1e-6)
    assert mf.vertical_force(tyre, -0.001, -1.0) == 0.0                          # off the road
    assert mf.vertical_force(tyre, rho, 0.1) - tyre["FNOMIN"] == pytest.approx(0.1 * tyre["VERTICAL_DAMPING"])
    assert mf.vertical_force(tyre, 1e-5, -10.0) == 0.0                            # the road never pulls


def test_a_wheel_off_the_ground_has_no_force(tyre: np.record) -> None:
    assert mf.forces(tyre, 0.0, 0.1, 0.1, 0.05, 20.0) == (0.0, 0.0, 0.0, 0.0)
    assert mf.forces(tyre, -50.0, 0.1, 0.1, 0.05, 20.0) == (0.0, 0.0, 0.0, 0.0)


def test_the_shipped_tyre_is_a_plausible_195_65_r15(tyre: np.record) -> None:
    kxk, kya = mf.slip_stiffnesses(tyre, 4000.0, 0.0)
    sigma_k, sigma_a = relaxation_lengths(tyre, 4000.0, 0.0)
    assert tyre["UNLOADED_RADIUS"] == pytest.approx(0.195 * 0.65 + 7.5 * 0.0254, abs=1e-4)
    assert 15.0 < -kya / 4000.0 < 25.0                # cornering stiffness coefficient [1/rad]
    assert 0.3 < sigma_a < 0.8 and 0.1 < sigma_k < 0.6
    assert "SCALED FROM A PUBLISHED SET" in DEFAULT_TYRE.read_text()


def _edited(tmp_path: Path, old: str, new: str) -> Path:
    text = DEFAULT_TYRE.read_text()
    assert old in text
    path = tmp_path / "edited.tir"
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize("old, new, message", [
    ("PKY4                     = 2.7364\n", "", r"edited\.tir: \[LATERAL_COEFFICIENTS\] PKY4: missing; expected a number"),
    ("[ROLLING_COEFFICIENTS]\n", "[ROLLING]\n", r"\[ROLLING_COEFFICIENTS\] QSY1: missing.*no \[ROLLING_COEFFICIENTS\] section"),
    ("FNOMIN                   = 4000", "FNOMIN = 0", r"edited\.tir:\d+: \[VERTICAL\] FNOMIN: 0: expected a positive number"),
    ("LATERAL_STIFFNESS        = 139780", "LATERAL_STIFFNESS = -1", r"\[STRUCTURAL\] LATERAL_STIFFNESS: -1: expected a positive"),
    ("LMP                      = 1\n", "LMP = 1\nLMUV = 0.3\n", r"\[SCALING_COEFFICIENTS\] LMUV: friction's dependence on slip speed"),
    ("Q_FZ2                    = 20.7558", "Q_FZ2 = 900", r"\[VERTICAL\] Q_FZ2: 900 leaves no linear term"),
    ("PCY1                     = 1.4759", "PCY1 = 'one'", r"\[LATERAL_COEFFICIENTS\] PCY1: expected a number, got 'one'"),
])
def test_bad_coefficient_files_are_refused_naming_file_section_and_key(tmp_path: Path, old: str, new: str,
                                                                        message: str) -> None:
    with pytest.raises(InputError, match=message):
        mf.coefficients(read_tir(_edited(tmp_path, old, new)))


def test_missing_scaling_factors_default_to_one(tmp_path: Path, tyre: np.record) -> None:
    plain = mf.coefficients(read_tir(_edited(tmp_path, "LKY                      = 1\n", "")))
    assert plain["LKY"] == 1.0 and plain.tobytes() == tyre.tobytes()


# --- transient slip ---------------------------------------------------------------------------

def _slip_angle_step(tyre: np.record, vx: float, alpha0: float, h: float, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Side force after a slip-angle step at constant speed: times [s] and Fy [N]."""
    fz = 4000.0
    sigma = relaxation_lengths(tyre, fz, 0.0)[1]
    q, fy = 0.0, []
    for _ in range(steps):
        q = lag(q, vx * math.tan(alpha0), vx, sigma, h)
        fy.append(mf.forces(tyre, fz, 0.0, math.atan(q), 0.0, vx)[1])
    return h * np.arange(1, steps + 1), np.array(fy)


@pytest.mark.parametrize("vx", [8.0, 30.0])
def test_a_slip_angle_step_builds_the_side_force_over_the_relaxation_length(tyre: np.record, vx: float) -> None:
    alpha0 = math.radians(0.1)                              # linear range: Fy ∝ the lagged slip
    sigma = relaxation_lengths(tyre, 4000.0, 0.0)[1]
    t, fy = _slip_angle_step(tyre, vx, alpha0, 1e-3, int(5 * sigma / vx / 1e-3))
    built_slip = math.tan(alpha0) * (1 - np.exp(-vx * t / sigma))
    np.testing.assert_allclose(fy, [mf.forces(tyre, 4000.0, 0.0, math.atan(q), 0.0, vx)[1] for q in built_slip],
                               rtol=1e-9)
    offset = mf.forces(tyre, 4000.0, 0.0, 0.0, 0.0, vx)[1]
    final = mf.forces(tyre, 4000.0, 0.0, alpha0, 0.0, vx)[1]
    # the force follows within the formula's curvature over 0.1° (about 0.1 % of the step)
    np.testing.assert_allclose((fy - offset) / (final - offset), 1 - np.exp(-vx * t / sigma), atol=2e-3)


def test_the_lagged_slip_does_not_depend_on_the_step(tyre: np.record) -> None:
    """Exact integration for held inputs: 1 ms and 5 ms steps reach the same slip at 0.2 s."""
    fine = _slip_angle_step(tyre, 20.0, math.radians(2.0), 1e-3, 200)[1][-1]
    coarse = _slip_angle_step(tyre, 20.0, math.radians(2.0), 5e-3, 40)[1][-1]
    assert coarse == pytest.approx(fine, rel=1e-12)


def test_at_rest_the_tyre_holds_like_its_carcass_spring(tyre: np.record) -> None:
    """At zero speed the lagged slip integrates the sliding velocity: a lateral displacement y
    gives Fy = −C_y·y, the file's lateral stiffness at that load (no creep)."""
    fz, y, steps, h = 3000.0, 2e-4, 100, 1e-3
    sigma = relaxation_lengths(tyre, fz, 0.0)[1]
    q = 0.0
    for _ in range(steps):
        q = lag(q, y / (steps * h), 0.0, sigma, h)
    assert q == pytest.approx(y / sigma, rel=1e-12)
    pushed = mf.forces(tyre, fz, 0.0, math.atan(q), 0.0, 0.0)[1] - mf.forces(tyre, fz, 0.0, 0.0, 0.0, 0.0)[1]
    cy = mf.carcass_stiffnesses(tyre, fz)[1]
    assert -pushed / y == pytest.approx(cy, rel=0.01)


def test_low_speed_damping_fades_smoothly_to_zero_at_vxlow(tyre: np.record) -> None:
    cx, cy = mf.carcass_stiffnesses(tyre, 4000.0)
    at_rest = low_speed_damping(tyre, 4000.0, 0.0)
    assert at_rest == pytest.approx((tyre["DAMP_VLOW"] * cx, tyre["DAMP_VLOW"] * cy))
    assert low_speed_damping(tyre, 4000.0, tyre["VXLOW"]) == (0.0, 0.0)
    assert low_speed_damping(tyre, 4000.0, 0.5 * tyre["VXLOW"])[1] == pytest.approx(0.5 * at_rest[1])
    assert low_speed_damping(tyre, 4000.0, -0.999 * tyre["VXLOW"])[1] < 1e-5 * at_rest[1]
