"""The virtual bench rig and the bench dataset format: what is measured, what is not written, and
the errors of bad truth files and bad datasets."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from elastokin.bushings.bench.campaign import CAMPAIGN
from elastokin.bushings.extended_bank import ExtendedBank
from elastokin.cli.main import main as vsim
from elastokin.core.errors import InputError
from elastokin.diagnosis.virtual_bench import OVERSAMPLING, measure_bench, parse_truth, rest_before
from elastokin.recordings.bench_dataset import read_bench_dataset

SHORT = CAMPAIGN[:3]
TRUTH = {"level": "bench", "baseline": "fig5_9_progressive", "seed": 7,
         "effects": [{"cause": "mullins", "mullins": 0.123456}],
         "measurement": {"force_noise_n": 2.0, "force_resolution_n": 0.0, "displacement_noise_mm": 0.0,
                         "displacement_offset_mm": 0.0, "force_offset_n": 0.0, "displacement_resolution_mm": 0.0}}


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    out = tmp_path_factory.mktemp("rig") / "measured"
    return measure_bench(parse_truth(TRUTH, "<truth>"), out, tests=SHORT)


def test_dataset_carries_no_trace_of_the_truth(measured):
    text = "".join(p.read_text() for p in measured.iterdir())
    for secret in ("mullins", "0.123456", "fig5_9", "stvs", "seed"):
        assert secret not in text


def test_measured_force_is_the_truth_plus_the_declared_noise(measured):
    data = read_bench_dataset(measured)
    truth = parse_truth(TRUTH, "<truth>")
    bank = ExtendedBank([truth.model.channel()], [truth.model.effects_si()])
    residuals = []
    for test, rec in zip(SHORT, data.records):
        rest_before(bank, test.rest_before_s)
        t, e = test.signal(test.dt_s / OVERSAMPLING)
        clean = bank.run(e, test.dt_s / OVERSAMPLING)[::OVERSAMPLING, 0]
        np.testing.assert_allclose(rec.record.e, e[::OVERSAMPLING], atol=5e-11)  # no displacement error declared
        residuals.append(rec.record.F - clean)
    noise = np.concatenate(residuals)
    assert abs(noise.mean()) < 0.1
    assert noise.std() == pytest.approx(2.0, rel=0.05)


def test_same_truth_gives_identical_files(measured, tmp_path):
    again = measure_bench(parse_truth(TRUTH, "<truth>"), tmp_path / "again", tests=SHORT)
    for path in measured.iterdir():
        assert (again / path.name).read_bytes() == path.read_bytes()


def test_cli_measures_and_refuses_to_overwrite(tmp_path, capsys):
    truth = tmp_path / "truth.yaml"
    truth.write_text(yaml.safe_dump({**TRUTH, "effects": []}))
    out = tmp_path / "out"
    out.mkdir()
    assert vsim(["rig", "measure", str(truth), "-o", str(out)]) == 2
    assert "--overwrite" in capsys.readouterr().err


@pytest.mark.parametrize("change, key", [
    ({"level": "kc"}, "level"),
    ({"colour": 1}, "colour"),
    ({"baseline": "no_such_set"}, "baseline"),
    ({"effects": [{"cause": "gremlins"}]}, "effects[0].cause"),
    ({"effects": [{"cause": "mullins"}]}, "effects[0].mullins"),
    ({"effects": [{"cause": "mullins", "mullins": 0.1, "extra": 2}]}, "effects[0].extra"),
    ({"effects": [{"cause": "viscoelasticity_missing", "Co": 20, "pw": 0.2}]}, "effects[0].cause"),
    ({"measurement": {"force_noise_n": -1}}, "measurement.force_noise_n"),
    ({"seed": "x"}, "seed"),
])
def test_truth_errors_name_the_key(change, key):
    with pytest.raises(InputError) as err:
        parse_truth({**TRUTH, **change}, "truth.yaml")
    assert err.value.key == key and "truth.yaml" in str(err.value)


@pytest.mark.parametrize("edit, key", [
    (lambda m: m.update(level="kc"), "level"),
    (lambda m: m.update(extra=1), "extra"),
    (lambda m: m["records"][0].update(file="missing.csv"), "records[0].file"),
    (lambda m: m["records"][1].update(rest_before_s=-1), "records[1].rest_before_s"),
    (lambda m: m.update(records=[]), "records"),
])
def test_dataset_errors_name_the_key(measured, tmp_path, edit, key):
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(measured, copy)
    manifest = yaml.safe_load((copy / "rig.yaml").read_text())
    edit(manifest)
    (copy / "rig.yaml").write_text(yaml.safe_dump(manifest))
    with pytest.raises(InputError) as err:
        read_bench_dataset(copy)
    assert err.value.key == key


def test_dataset_csv_errors_name_the_line(measured, tmp_path):
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(measured, copy)
    first = sorted(copy.glob("*.csv"))[0]
    lines = first.read_text().splitlines()
    lines[5] = lines[5].split(",")[0] + ",nan,1.0"
    first.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="finite") as err:
        read_bench_dataset(copy)
    assert "line 6" in str(err.value)
