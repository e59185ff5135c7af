"""K&C metrics of the default car (elastokin/analysis/kc_metrics.py) fall in plausible ranges.

Ranges, per axle, as (low, high) in the metric's unit and sign convention (elastokin/analysis/kc_metrics.py):

* from spec vehicle.md §4 (plausible C-segment values): front bump steer −10 … 0 deg/m, rear bump
  steer 0 … +4 deg/m (toe-in), aligning-torque compliance steer 0.5 … 1.5 deg/kN·m (front; the
  rear, without steering, is stiffer: 0.05 … 1.5);
* the rest: engineering judgement (assumption), wide bands that hold the usual passenger-car
  values and mainly fix the sign: a McPherson loses camber in bump (−40 … −5 deg/m), a twist beam
  in heave hardly changes it (±10 deg/m); both axles roll and comply under lateral force with
  understeer (front steers away from a lateral force, rear with it; in roll the front steers out
  of the turn, −0.2 … 0 deg/deg, the rear into it, 0 … 0.15 deg/deg); the
  wheel leans with the body in roll by 0.5 … 1 (McPherson) or 0.2 … 1 (twist beam) deg/deg;
  camber compliance 0 … 0.5 deg/kN (top outward under an inboard force); lateral compliance
  0.1 … 3 mm/kN; braking compliance steer small either way (±0.3 deg/kN); quasi-static loop widths
  of the default bushings below 0.05 deg.
"""

from __future__ import annotations

import pytest

from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.analysis.kc_metrics import METRICS, STEERING_METRICS
from elastokin.analysis.kc_test import vehicle_kc

RANGES = {
    "front": {
        "bump_steer_deg_per_m": (-10.0, 0.0),
        "bump_camber_deg_per_m": (-40.0, -5.0),
        "roll_steer_deg_per_deg": (-0.2, 0.0),
        "roll_camber_deg_per_deg": (0.5, 1.0),
        "lateral_force_compliance_steer_deg_per_kn": (-0.4, 0.0),
        "lateral_force_compliance_camber_deg_per_kn": (0.0, 0.5),
        "lateral_compliance_mm_per_kn": (0.1, 3.0),
        "longitudinal_compliance_steer_deg_per_kn": (-0.3, 0.3),
        "aligning_torque_compliance_steer_deg_per_knm": (0.5, 1.5),
        "toe_loop_width_deg": (0.0, 0.05),
        "camber_loop_width_deg": (0.0, 0.05),
        "wheel_rate_n_per_mm": (20.0, 35.0),      # the spring's ≈ 23 N/mm at the wheel, plus the bushings'
        "roll_stiffness_share_pct": (50.0, 75.0),   # a front-heavy car rolls on its front axle
        "steering_ratio": (16.0, 17.5),            # the file's 16.7:1 (kinematic), compliance aside
        "caster_deg": (1.0, 7.0),
        "kingpin_inclination_deg": (8.0, 16.0),
    },
    "rear": {
        "bump_steer_deg_per_m": (0.0, 4.0),
        "bump_camber_deg_per_m": (-10.0, 10.0),
        "roll_steer_deg_per_deg": (0.0, 0.15),
        "roll_camber_deg_per_deg": (0.2, 1.0),
        "lateral_force_compliance_steer_deg_per_kn": (0.0, 0.2),
        "lateral_force_compliance_camber_deg_per_kn": (0.0, 0.5),
        "lateral_compliance_mm_per_kn": (0.1, 3.0),
        "longitudinal_compliance_steer_deg_per_kn": (-0.3, 0.3),
        "aligning_torque_compliance_steer_deg_per_knm": (0.05, 1.5),
        "toe_loop_width_deg": (0.0, 0.05),
        "camber_loop_width_deg": (0.0, 0.05),
    },
}


@pytest.fixture(scope="module")
def metrics():
    return vehicle_kc(load_vehicle())


def test_metrics_are_reported_for_both_axles(metrics):
    assert set(metrics) == {"front", "rear"}
    assert set(metrics["front"]) == {key for key, _, _ in METRICS}
    assert set(metrics["rear"]) == {key for key, _, _ in METRICS} - set(STEERING_METRICS)


@pytest.mark.parametrize("axle, key", [(a, k) for a, r in RANGES.items() for k in r])
def test_metric_in_plausible_range(metrics, axle, key):
    low, high = RANGES[axle][key]
    assert low <= metrics[axle][key] <= high, (axle, key, metrics[axle][key])


def test_vsim_kc_json_has_the_issue_keys(metrics, monkeypatch, capsys):
    import json

    from elastokin.api import vehicles
    from elastokin.cli.main import main

    monkeypatch.setattr(vehicles, "vehicle_kc", lambda vehicle, options: metrics)
    assert main(["kc", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) == {"front", "rear"}
    for axle, ranges in RANGES.items():
        assert set(ranges) <= set(out[axle])
    assert main(["kc"]) == 0
    assert "bump_steer_deg_per_m" in capsys.readouterr().out
