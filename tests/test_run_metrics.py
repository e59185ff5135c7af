"""K&C metrics of a recorded run (elastokin/analysis/run_metrics.py): agreement with `vsim kc`, exact recovery
of a known slope, loop width and area from synthetic signals, and the run summary.

Agreement with `vsim kc`: one short run per K&C test (amplitude and rate of elastokin.vehicle.scenarios.kc_tests.TESTS, two
cycles, durations × 0.5, so twice kc's rate) against kc_metrics on the same car. The bushings see
another history (linear settling, a first cycle, the doubled rate), which moves gradients by less
than 1 % (measured); the test allows 2 % (plus 2e-4 in the metric's unit for values near 0). Loop
widths depend on that history and are not compared.
"""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np
import pytest

from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.channels import CORNER_TAGS
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.vehicle.simulation.kc_triangles import design_contact_base
from elastokin.vehicle.simulation.rig import KCRig
from elastokin.analysis.kc_metrics import BUMP_WINDOW_M, TEST_METRICS
from elastokin.analysis.kc_test import kc_metrics
from elastokin.analysis.run_metrics import case_loop, case_metrics, cases, contact_base_m, run_metrics, tyre_radius_m
from elastokin.core.errors import InputError
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.presentation.run_summary import summary
from elastokin.recordings.recorder import run_scenario
from elastokin.recordings.run_format import Run, RunMetadata, SignalSpec
from elastokin.recordings.run_reader import load_run

SCALE = 1.0        #: duration scale of the runs (at vsim kc's rates)
TOLERANCE = 0.02   #: relative agreement of gradients with `vsim kc`
#: scenario type → (kc test, case line: kc's amplitude and rate in the file's units)
KC_CASES = {
    "pumping": ("bump", "{amplitude_mm: 25, speed_mm_s: 25}"),
    "roll": ("roll", "{amplitude_mm: 25, speed_mm_s: 25}"),
    "lateral_force": ("lateral", "{amplitude_daN: 200, speed_daN_s: 200}"),
    "longitudinal_force": ("longitudinal", "{amplitude_daN: 150, speed_daN_s: 200}"),
    "aligning_torque": ("aligning", "{amplitude_Nm: 150, speed_Nm_s: 200}"),
}


@pytest.fixture(scope="module")
def kc_rig() -> KCRig:
    return KCRig(load_vehicle())


@pytest.fixture(scope="module")
def kc_values(kc_rig: KCRig) -> dict[str, dict[str, float]]:
    return kc_metrics(kc_rig)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Run]:
    """One short recorded run per scenario type of KC_CASES."""
    out = {}
    for kind, (_, case) in KC_CASES.items():
        folder = tmp_path_factory.mktemp(kind)
        path = folder / f"{kind}.yaml"
        path.write_text(textwrap.dedent(f"""\
            type: {kind}
            vehicle: {DEFAULT_VEHICLE}
            settle: {{before_bushings_s: 0.2, before_input_s: 0.5}}
            cases: [{{cycles: 2, {case[1:-1]}}}]
            """))
        out[kind] = load_run(run_scenario(load_scenario(path), folder / "run.mcap", duration_scale=SCALE).path)
    return out


@pytest.mark.parametrize("kind", KC_CASES)
def test_recorded_run_gives_the_kc_metrics_of_vsim_kc(runs, kc_values, kind: str) -> None:
    run = runs[kind]
    test = KC_CASES[kind][0]
    metrics = case_metrics(run, cases(run)[0])
    assert set(metrics) == {"front", "rear"}
    for axle, values in metrics.items():
        assert set(values) == set(TEST_METRICS[test])   # what a sweep may ask of this test
        gradients = {k: v for k, v in values.items() if "loop_width" not in k}
        assert gradients, (kind, values)
        for key, value in gradients.items():
            assert value == pytest.approx(kc_values[axle][key], rel=TOLERANCE, abs=2e-4), (test, axle, key)
    if test == "bump":
        assert {"toe_loop_width_deg", "camber_loop_width_max_deg"} <= set(metrics["front"])


def test_contact_base_from_the_recording_is_the_one_of_vsim_kc(runs, kc_rig) -> None:
    base = contact_base_m(runs["roll"])
    for axle, expected in design_contact_base(kc_rig).items():
        assert base[axle] == pytest.approx(expected, abs=1e-9)


def test_roll_metrics_need_a_contact_base_without_a_vehicle(runs) -> None:
    run = runs["roll"]
    bare = Run(**{**vars(run), "metadata": RunMetadata(extra=run.metadata.extra)})
    with pytest.raises(InputError, match="tyre radius"):
        run_metrics(bare)
    assert run_metrics(bare, radius_m=tyre_radius_m(run)) == run_metrics(run)
    given = {"front": 1.5, "rear": 1.5}
    without_radius = run_metrics(bare, given)
    assert without_radius[1]["rear"] == {k: v for k, v in run_metrics(run, given)[1]["rear"].items()
                                         if k != "roll_centre_height_kinematic_mm"}


def test_summary_prints_the_kc_metrics(runs) -> None:
    run = runs["pumping"]
    rows = {line.split()[0] + " " + line.split()[2]: float(line.split()[3])
            for line in summary(run).splitlines() if line.startswith("  bump_")}
    metrics = run_metrics(run)[1]
    assert rows == {f"{k} {axle}": pytest.approx(metrics[axle][k], rel=1e-4)
                    for axle in ("front", "rear") for k in ("bump_steer_deg_per_m", "bump_camber_deg_per_m")}


# -- synthetic signals -----------------------------------------------------------------------------
AMPLITUDE_MM = 30.0
RATE_HZ = 200.0
PERIOD_S = 4.0


def triangle(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """0 → +A → −A → 0 per period [mm], and +1 where it falls, −1 where it rises (or peaks)."""
    phase = (t / PERIOD_S) % 1.0
    x = AMPLITUDE_MM * np.where(phase < 0.25, 4 * phase, np.where(phase < 0.75, 2 - 4 * phase, 4 * phase - 4))
    falling = (phase > 0.25) & (phase <= 0.75)
    return x, np.where(falling, 1.0, -1.0)


UNITS = {"pad_fz": "N", "half_track": "mm", "wheel_centre_x": "mm"}   #: of synthetic outputs that are no angles


def synthetic_run(kind: str, outputs: dict[str, tuple[float, float]], *, right_sign: float = 1.0) -> Run:
    """A two-cycle ``kind`` case recorded at RATE_HZ: every corner's pad and wheel travel follow the
    triangle (right corners × ``right_sign``); output ``q`` of each corner is
    gradient·x + width/2 on the falling branch, − width/2 on the rising one, for
    ``outputs[q] = (gradient [unit/mm], width [unit])``, its unit deg unless :data:`UNITS` names it."""
    t = np.arange(int(2 * PERIOD_S * RATE_HZ) + 1) / RATE_HZ
    x, falling = triangle(t)
    signals, units = {"case": np.ones_like(t), "phase": np.full_like(t, 2.0), "input_time": t}, {}
    for corner, tag in CORNER_TAGS.items():
        xc = x * (right_sign if corner.endswith("right") else 1.0)
        for name in ("pad_z", "pad_height", "wheel_travel"):
            signals[f"{name}_{tag}"], units[f"{name}_{tag}"] = xc, "mm"
        for quantity, (gradient, width) in outputs.items():
            signals[f"{quantity}_{tag}"] = gradient * xc + 0.5 * width * falling
            units[f"{quantity}_{tag}"] = UNITS.get(quantity, "deg")
    extra = {"type": kind, "x_quantity": "wheel_travel", "axles": ["front", "rear"], "duration_scale": 1.0,
             "cases": [{"case": 1, "label": "synthetic", "parameters": {}, "cycles": 2, "input_start_s": 0.0,
                        "end_s": float(t[-1])}]}
    specs = [SignalSpec(n, units.get(n, "-"), "synthetic") for n in signals]
    return Run(path=Path("synthetic.mcap"), t_s=t, signals=signals, units={s.name: s.unit for s in specs},
               groups={s.name: s.group for s in specs}, specs=specs, body_names=[], body_pos=np.empty((t.size, 0, 3)),
               body_quat_wxyz=np.empty((t.size, 0, 4)), geometry=[], metadata=RunMetadata(extra=extra),
               complete=True, reason="")


def test_known_slope_width_and_area_are_recovered_exactly() -> None:
    gradient, width = -0.02, 0.003   # deg/mm, deg
    run = synthetic_run("pumping", {"camber": (gradient, width)})
    loop = case_loop(run, cases(run)[0], "wheel_travel_fl", "camber_fl", "pad_z_fl")
    assert loop.gradient == pytest.approx(gradient, rel=1e-12)
    assert loop.width == pytest.approx(width, rel=1e-9) and loop.width_max == pytest.approx(width, rel=1e-9)
    assert loop.window == pytest.approx(BUMP_WINDOW_M * 1e3)   # ±20 mm at most in bump
    # the falling branch lies above: the loop runs anticlockwise, ∮ y dx = −(2A)·width, less the
    # two triangles of width × half a sample step cut at the peaks
    step = 4 * AMPLITUDE_MM / (PERIOD_S * RATE_HZ)
    assert loop.area == pytest.approx(-(2 * AMPLITUDE_MM - step) * width, rel=1e-9)


def test_known_slopes_give_the_named_kc_metrics_exactly() -> None:
    toe, camber = (0.004, 0.001), (-0.02, 0.002)   # (deg/mm, deg)
    fz, track, x = (25.0, 3.0), (-0.03, 0.01), (-0.05, 0.0)   # (N/mm, N), (mm/mm, mm) ...
    run = synthetic_run("pumping", {"toe": toe, "camber": camber, "pad_fz": fz, "half_track": track,
                                    "wheel_centre_x": x})
    bump = case_metrics(run, cases(run)[0])
    for axle in ("front", "rear"):
        assert bump[axle]["wheel_rate_n_per_mm"] == pytest.approx(fz[0], rel=1e-9)
        assert bump[axle]["half_track_change_mm_per_m"] == pytest.approx(1e3 * track[0], rel=1e-9)
        assert bump[axle]["wheel_recession_mm_per_m"] == pytest.approx(-1e3 * x[0], rel=1e-9)
        assert bump[axle]["bump_steer_deg_per_m"] == pytest.approx(1e3 * toe[0], rel=1e-9)
        assert bump[axle]["bump_camber_deg_per_m"] == pytest.approx(1e3 * camber[0], rel=1e-9)
        assert bump[axle]["toe_loop_width_deg"] == pytest.approx(toe[1], rel=1e-9)
        assert bump[axle]["camber_loop_width_max_deg"] == pytest.approx(camber[1], rel=1e-9)
    # roll: right pads opposite, so roll = (zR − zL)/base = −2x/base; steer = toe·(±1) per side,
    # its mean over the axle cancels on a synthetic car whose steer is the same function on both sides
    base = 1.6   # m
    run = synthetic_run("roll", {"camber": camber, "steer": toe, "pad_fz": fz}, right_sign=-1.0)
    roll = case_metrics(run, cases(run)[0], {"front": base, "rear": base})
    per_roll_deg = math.radians(1.0) * base / -2.0 * 1e3   # mm of x per degree of roll
    for axle in ("front", "rear"):
        # two wheels of rate k at ±base/2: k·base²/2 per radian
        assert roll[axle]["roll_stiffness_nm_per_deg"] == pytest.approx(1e3 * fz[0] * base ** 2 / 2 * math.pi / 180,
                                                                        rel=1e-9)
        assert "roll_centre_height_kinematic_mm" not in roll[axle]   # no tyre radius: no contact points
        # (camber_R − camber_L)/2 = −camber gradient·x; plus the roll angle itself
        assert roll[axle]["roll_camber_deg_per_deg"] == pytest.approx(1.0 - camber[0] * per_roll_deg, rel=1e-9)
        assert roll[axle]["roll_steer_deg_per_deg"] == pytest.approx(0.0, abs=1e-12)
