"""`vsim kc --curves DIR` writes the curves behind the metrics as a K&C rig delivers them, and `vsim
compare --kc DIR` reads a rig's curves back against the simulated car: the round trip keeps every
metric, a changed car shows its change where it is, and a damaged file is refused naming it."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from elastokin.analysis.kc_curves import UNITS, column, curves_metrics, design_base, read_curves
from elastokin.analysis.kc_metrics import METRICS
from elastokin.api.vehicles import load_vehicle
from elastokin.cli.main import main
from elastokin.core.errors import InputError
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.vehicle.simulation.kc_triangles import design_contact_base
from elastokin.vehicle.simulation.rig import KCRig


@pytest.fixture(scope="module")
def curves(tmp_path_factory):
    """The default car's curves and its metrics, written by `vsim kc --curves --json`."""
    folder = tmp_path_factory.mktemp("kc") / "curves"
    return folder, load_vehicle().kc_metrics(curves=folder)


def test_the_curves_read_back_give_vsim_kcs_metrics(curves, capsys):
    folder, metrics = curves
    assert sorted(p.name for p in folder.iterdir()) == [f"{t}.csv" for t in sorted(
        ("bump", "roll", "lateral", "longitudinal", "drive", "aligning", "steering"))]
    header = (folder / "bump.csv").read_text().splitlines()[0].split(",")
    assert header[0] == "time_s" and "pad_fz_rr_n" in header and "toe_fl_deg" in header
    assert main(["compare", "--kc", str(folder), "--json"]) == 0
    comparison = json.loads(capsys.readouterr().out)
    for axle, values in metrics.items():
        assert set(comparison[axle]) == set(values)
        for key, value in values.items():
            # the file's amplitude is its largest sample, half a sample step short of the test's
            assert comparison[axle][key]["rig"] == pytest.approx(value, rel=0.01, abs=1e-5), (axle, key)
            assert comparison[axle][key]["sim"] == value
    assert main(["compare", "--kc", str(folder)]) == 0
    assert "rig - sim" in capsys.readouterr().out


def test_a_stiffer_rear_spring_shows_in_the_rear_wheel_rate_only(curves, tmp_path):
    """Curves of a car whose rear spring is 20 % stiffer against the default car: the rear wheel
    rate is higher by Δk × its motion ratio squared, the front's and the kinematics unchanged."""
    folder, _ = curves
    text = DEFAULT_VEHICLE.read_text().replace("rate: 36000.0", "rate: 43200.0")
    path = tmp_path / "stiffer.yaml"
    path.write_text(text)
    stiff = tmp_path / "stiff"
    load_vehicle(path).kc_metrics(curves=stiff)
    comparison = load_vehicle().compare_kc(stiff)
    rear, front = comparison["rear"]["wheel_rate_n_per_mm"], comparison["front"]["wheel_rate_n_per_mm"]
    # the spring stands on the trailing arm: its motion ratio is its lever over the wheel's about the pivot
    hp = load_vehicle().definition.rear.hardpoints
    ratio = (hp["arm_pivot"][0] - hp["spring_lower"][0]) / (hp["arm_pivot"][0] - hp["wheel_centre"][0])
    assert rear["difference"] == pytest.approx(7.2 * ratio ** 2, rel=0.02)   # Δk = 7.2 N/mm
    assert abs(front["difference"]) < 1e-3 * front["sim"]
    assert comparison["front"]["bump_steer_deg_per_m"]["difference"] == pytest.approx(0.0, abs=1e-3)


def test_a_rigs_own_column_order_and_extra_columns_are_read(curves, tmp_path):
    folder, metrics = curves
    shuffled = tmp_path / "shuffled"
    shuffled.mkdir()
    rng = np.random.default_rng(0)
    for path in folder.iterdir():
        rows = list(csv.reader(path.read_text().splitlines()))
        order = [0] + list(1 + rng.permutation(len(rows[0]) - 1))   # time first, as the reader wants
        with (shuffled / path.name).open("w", newline="") as f:
            csv.writer(f).writerows([[r[i] for i in order] + [extra] for r, extra in
                                     zip(rows, ["temperature_c"] + ["21.5"] * (len(rows) - 1))])
    v = load_vehicle().definition
    assert curves_metrics(shuffled, v) == curves_metrics(folder, v)


def test_the_design_base_is_the_rigs(curves):
    v = load_vehicle().definition
    rig = design_contact_base(KCRig(v))
    for axle, base in design_base(v).items():
        assert base == pytest.approx(rig[axle], abs=1e-9)


def test_damaged_curves_are_refused_naming_the_file(curves, tmp_path):
    folder, _ = curves
    bad = tmp_path / "bad"
    bad.mkdir()
    for path in folder.iterdir():
        (bad / path.name).write_text(path.read_text())
    (bad / "roll.csv").unlink()
    with pytest.raises(InputError, match="no roll curves; expected roll.csv"):
        read_curves(bad)
    (bad / "roll.csv").write_text((folder / "roll.csv").read_text().replace(column("toe", "rear_left"), "toe_rl"))
    with pytest.raises(InputError, match=r"roll.csv.*missing column\(s\) toe_rl_deg"):
        read_curves(bad)
    # only the loading leg: no unloading leg to split off
    lines = (folder / "roll.csv").read_text().splitlines()
    (bad / "roll.csv").write_text("\n".join(lines[:1] + lines[1 + (len(lines) - 1) // 2:]))
    with pytest.raises(InputError, match=r"roll.csv.*pad_height_fr_mm: expected an unloading leg"):
        read_curves(bad)
    assert set(UNITS) >= {"pad_fz", "toe", "camber", "wheel_travel"} and len(METRICS) > 13
