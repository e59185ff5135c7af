"""`vsim rig export` and `vsim rig dataset`: a K&C dataset written as a rig's CSV exports in SAE or
ISO signs and brought back through `vsim rig import` is the dataset it was, to the CSV's digits; the
SAE signs are the axes' (y right, z down); bad input is refused naming what, and nothing is written."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from elastokin.cli import main as cli
from elastokin.core.errors import InputError
from elastokin.recordings.csv_export import CONVENTIONS, export_csv, export_csv_folder
from elastokin.recordings.csv_import import import_csv
from elastokin.recordings.kc_dataset import assemble_kc_dataset, read_kc_dataset
from elastokin.recordings.rig_recordings import measured_channels
from elastokin.vehicle.scenarios.channels import channel_quantity

ROOT = Path(__file__).resolve().parent.parent
SHIPPED = ROOT / "data" / "rig" / "kc"
DERIVED = ("case", "phase", "input_time")


def _import_all(exports: Path, dataset: Path) -> None:
    """Each CSV export in ``exports`` imported with `vsim rig import`, then `vsim rig dataset`."""
    for data in sorted(exports.glob("*.csv")):
        assert cli.main(["rig", "import", str(data), "--meta", str(data.with_name(f"{data.stem}.meta.yaml")),
                         "-o", str(dataset / f"{data.stem}.mcap")]) == 0
    assert cli.main(["rig", "dataset", str(dataset), "--vehicle", "the shipped example, round trip"]) == 0


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The shipped K&C dataset exported in each convention with `vsim rig export` (convention -> folder)."""
    out = {}
    for name in CONVENTIONS:
        out[name] = tmp_path_factory.mktemp(name) / "csv"
        assert cli.main(["rig", "export", str(SHIPPED), "-o", str(out[name]), "--convention", name]) == 0
    return out


def test_an_exported_dataset_imports_back_to_itself(exported, tmp_path, convention="sae"):
    """In SAE signs, the one that flips signs (the ISO export is checked against it below)."""
    _import_all(exported[convention], tmp_path / "dataset")
    original, back = read_kc_dataset(SHIPPED), read_kc_dataset(tmp_path / "dataset")
    assert [t.name for t in back.tests] == [t.name for t in original.tests]
    assert back.rig["name"] == original.rig["name"] and original.rig["notes"] in back.rig["notes"]
    for a, b in zip(original.tests, back.tests):
        # the scenario file where it still holds what was played, else inline: the same cases either way
        given = yaml.safe_load((exported[convention] / f"{a.name}.meta.yaml").read_text())["scenario"]
        if isinstance(given, str):
            assert b.scenario.text == a.scenario.text
        else:
            assert given["name"] == a.scenario.name and "vehicle" not in given
        assert b.run.metadata.extra["cases"] == a.run.metadata.extra["cases"]
        np.testing.assert_allclose(b.run.t_s, a.run.t_s, rtol=0, atol=1e-12)
        assert set(b.run.signals) == set(a.run.signals)
        for name, x in a.run.signals.items():
            if name in DERIVED:
                np.testing.assert_allclose(b.run.signals[name], x, rtol=0, atol=1e-9, err_msg=name)
            else:   # 10 significant digits
                np.testing.assert_allclose(b.run.signals[name], x, rtol=1e-9, atol=1e-12, err_msg=name)


def test_sae_signs_are_its_axes_y_right_and_z_down(exported):
    """In the pumping test's first sample (the car at rest on its pads): the left front wheel's centre
    is on the right of ISO's y axis, its pad load pushes up (−z in SAE), its centre's height above the
    ground is negative; toe, camber and wheel travel read alike in both."""
    read = {name: np.genfromtxt(folder / "01_kc_pumping.csv", delimiter=",", names=True, max_rows=5)
            for name, folder in exported.items()}
    iso, sae = read["iso"], read["sae"]
    assert iso["wheel_centre_y_FL_mm"][0] > 500.0 and sae["wheel_centre_y_FL_mm"][0] < -500.0
    assert iso["pad_fz_FL_N"][0] > 2000.0 and sae["pad_fz_FL_N"][0] < -2000.0
    assert sae["wheel_centre_z_FL_mm"][0] == -iso["wheel_centre_z_FL_mm"][0] and iso["wheel_centre_z_FL_mm"][0] > 0
    for column in ("toe_FL_deg", "camber_FR_deg", "wheel_travel_RL_mm", "half_track_RR_mm", "wheel_centre_x_FL_mm"):
        np.testing.assert_array_equal(sae[column], iso[column])
    flipped = {channel_quantity(c["channel"]) for c in yaml.safe_load(
        (exported["sae"] / "01_kc_pumping.meta.yaml").read_text())["columns"].values() if c.get("sign") == -1}
    assert flipped == CONVENTIONS["sae"].flipped & {channel_quantity(n) for n in measured_channels()}


def test_a_recording_whose_scenario_file_is_gone_is_exported_with_its_scenario_inline(tmp_path):
    """Copied away from scenarios/, a recording's relative scenario path no longer resolves: META then
    carries the scenario inline, and the import splits the test into the same cases."""
    moved = tmp_path / "far" / "away"
    moved.mkdir(parents=True)
    shutil.copy(SHIPPED / "04_kc_rack_step.mcap", moved / "rack.mcap")
    data, meta = export_csv(moved / "rack.mcap", tmp_path / "rack.csv", convention="iso")
    assert meta == tmp_path / "rack.meta.yaml" and isinstance(yaml.safe_load(meta.read_text())["scenario"], dict)
    back = assemble_kc_dataset(_imported(data, meta, tmp_path / "ds")).tests[0]
    original = read_kc_dataset(SHIPPED).tests[3]
    np.testing.assert_array_equal(back.run.signals["phase"], original.run.signals["phase"])
    np.testing.assert_allclose(back.run.signals["toe_fl"], original.run.signals["toe_fl"], rtol=1e-9, atol=1e-12)


def _imported(data: Path, meta: Path, folder: Path) -> Path:
    import_csv(data, meta, folder / f"{data.stem}.mcap")
    return folder


def test_bad_exports_and_datasets_are_refused_and_nothing_is_written(tmp_path, capsys):
    recording = SHIPPED / "01_kc_pumping.mcap"
    with pytest.raises(InputError, match="unknown convention 'jis'; expected one of iso, sae"):
        export_csv(recording, tmp_path / "a.csv", convention="jis")
    assert cli.main(["rig", "export", str(recording), "-o", str(tmp_path / "x"), "--convention", "jis"]) == 2
    assert "unknown convention 'jis'" in capsys.readouterr().err and not (tmp_path / "x").exists()
    (tmp_path / "a.csv").write_text("an older export")
    with pytest.raises(InputError, match="the output exists"):
        export_csv(recording, tmp_path / "a.csv")
    assert (tmp_path / "a.csv").read_text() == "an older export" and not (tmp_path / "a.meta.yaml").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv"]
    # a dataset: no recording; a recording listed that is not there; an existing rig.yaml kept
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match=r"no recording \(\.mcap\)") as error:
        assemble_kc_dataset(tmp_path / "empty")
    assert error.value.key == "recordings" and not any((tmp_path / "empty").iterdir())
    folder = export_csv_folder(recording, tmp_path / "one")[0]
    dataset = _imported(*folder, tmp_path / "ds")
    with pytest.raises(InputError, match="no such recording file 'missing.mcap'") as error:
        assemble_kc_dataset(dataset, ["01_kc_pumping.mcap", "missing.mcap"])
    assert error.value.key == "recordings[1]" and not (dataset / "rig.yaml").exists()
    assemble_kc_dataset(dataset, vehicle_text="first")
    with pytest.raises(InputError, match="the output exists"):
        assemble_kc_dataset(dataset, vehicle_text="second")
    assert read_kc_dataset(dataset).vehicle_text == "first"
    assert assemble_kc_dataset(dataset, vehicle_text="second", overwrite=True).vehicle_text == "second"
