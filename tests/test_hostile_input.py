"""The hostile inputs of issue 25, one by one: each is refused with one line naming the file, the
line or key and the value (or, for signals and cut recordings, leaves what can be read). The fuzz
test (test_fuzz.py) draws many more; these pin the classes the issue lists."""

from __future__ import annotations

import copy
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import elastokin
from elastokin.analysis.compare import compare_runs
from tests.damage_helpers import damaged, damaged_kc_dataset
from elastokin.bushings.bench.bench_file import load_bench
from elastokin.bushings.bench.records import read_bench_csv
from elastokin.vehicle.model.builder import build
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.statics import resolve_preloads
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.cli.main import main
from elastokin.core.documents import Document, dump_yaml
from elastokin.core.errors import InputError
from elastokin.core.shipped import BENCH_DIR, DATASET_DIR, DEFAULT_VEHICLE, SCENARIO_DIR
from elastokin.recordings.csv_import import import_csv
from elastokin.diagnosis.kc_layout import Layout, RunRows
from elastokin.recordings.kc_dataset import read_kc_dataset
from elastokin.recordings.run_format import Run
from elastokin.recordings.run_reader import DamagedRecording, load_run

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "data" / "examples" / "kc_import"
VEHICLE = yaml.safe_load(DEFAULT_VEHICLE.read_text())


def _set(data: Any, path: tuple, value: Any) -> Any:
    data = copy.deepcopy(data)
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return data


# -- vehicles: out of range, inconsistent, unbuildable ---------------------------------------------
@pytest.mark.parametrize("path,value,expected", [
    (("tyre", "radius"), 310, r"tyre\.radius: expected at most 1 m.*got 310"),
    (("tyre", "radius"), 0.35, r"tyre\.radius: a loaded radius of 0\.35 m puts the front contact point -47\.0 mm"),
    (("front", "static_toe"), 90.0, r"front\.static_toe: expected at most 5 deg.*got 90"),
    (("front", "spring", "preload"), -500.0, r"front\.spring\.preload: expected a non-negative number, got -500"),
    (("front", "damper", "curve"), [[-1.0, -3600.0], [0.0, 0.0], [0.5, 1400.0], [1.0, 1000.0]],
     r"front\.damper\.curve\[3\]: slope -800 from point 2 to 3; expected a damper force not falling"),
    (("rear", "damper", "curve"), [[-1.0, 200.0], [0.0, 300.0], [1.0, 1400.0]],
     r"rear\.damper\.curve\[0\]: force 200 N at speed -1 m/s would push the motion on and create energy"),
    (("front", "strut_friction"), 1e9, r"front\.strut_friction: expected at most 5000 N.*got 1000000000"),
    (("body", "mass"), 1e12, r"body\.mass: expected at most 10000 kg.*got 1000000000000"),
    (("body", "inertia"), [-450.0, 1700.0, 1850.0], r"body\.inertia: expected positive inertias"),
    (("body", "inertia"), [100.0, 1700.0, 1850.0], r"body\.inertia: .*break the triangle inequality"),
    (("front", "hardpoints", "tie_rod_inner"), [0.140, 0.660, 0.183],
     r"front\.hardpoints\.tie_rod_outer: 0\.0 mm from tie_rod_inner: the tie rod has no length"),
    (("front", "hardpoints", "lower_ball_joint"), [-0.140, 0.375, 0.145],
     r"front\.hardpoints\.lower_ball_joint: .* from the wishbone's pivot axis"),
    (("front", "hardpoints", "wheel_centre"), [0.0, 745.0, 310.0],
     r"front\.hardpoints\.wheel_centre\[1\]: expected at most 5 m.*got 745"),
    (("front", "masses", "knuckle"), -15.0, r"front\.masses\.knuckle: expected a positive number, got -15"),
])
def test_implausible_vehicles_are_refused_at_their_key_before_building(tmp_path: Path, path: tuple, value: Any,
                                                                        expected: str) -> None:
    file = tmp_path / "car.yaml"
    file.write_text(yaml.safe_dump(_set(VEHICLE, path, value), sort_keys=False))
    with pytest.raises(InputError, match=rf"car\.yaml:\d+: {expected}"):
        build(resolve_preloads(load_vehicle(file)), BuildOptions())


def test_a_repeated_key_is_refused_rather_than_the_last_one_winning(tmp_path: Path) -> None:
    lines = DEFAULT_VEHICLE.read_text().splitlines()
    line = next(i for i, s in enumerate(lines) if s.startswith("  mass: 1110.0")) + 2   # the repeat's line
    lines.insert(line - 1, "  mass: 5.0")
    file = tmp_path / "car.yaml"
    file.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=rf"car\.yaml:{line}: body\.mass: duplicate key .mass."):
        load_vehicle(file)


#: A "billion laughs": nine levels of ten-fold expansion (10^9 values) in nine lines.
BOMB = "".join(f"b{i}: &b{i} [" + ", ".join([f"*b{i - 1}" if i > 1 else "lol"] * 10) + "]\n" for i in range(1, 10))


@pytest.mark.parametrize("text,expected", [
    (BOMB, r"t\.yaml:6: YAML aliases here expand to more than 200000 values"),   # 10^6 values at b6
    ("a: &x [1, *x]\n", r"t\.yaml:1: a YAML alias refers to a value from inside it"),
    ("a: 1\n1e3: x\n1000.0: y\n", r"t\.yaml:3: 1000\.0: duplicate key '1000\.0' \(the key '1e3' of line 2\)"),
    ("a: &x 3\nb:\n  <<: *x\n", r"t\.yaml:1: a merge key \(<<\) takes a mapping"),
    (b"name: caf\xe9\n", r"t\.yaml: .*UTF-8"),
    ("a: " + "[" * 5000 + "]" * 5000 + "\n", r"t\.yaml: not valid here: nested too deeply"),
    ("a: " + "1" * 5000 + "\n", r"t\.yaml:1: '1+' cannot be read as a value \(Exceeds the limit \(4300 digits\)"),
], ids=["alias-bomb", "alias-cycle", "same-key-spelt-twice", "merge-of-a-number", "latin-1", "deep", "huge-integer"])
def test_alias_bombs_undecodable_bytes_and_unparsable_yaml_are_refused(tmp_path: Path, text: str | bytes,
                                                                       expected: str) -> None:
    file = tmp_path / "t.yaml"
    file.write_bytes(text if isinstance(text, bytes) else text.encode())
    started = time.perf_counter()
    with pytest.raises(InputError, match=expected):
        Document.read(file)
    assert time.perf_counter() - started < 0.5   # a bomb is counted, not expanded


def test_anchors_aliases_and_merge_keys_are_yamls() -> None:
    """A damper curve shared between the axles by an anchor, a mapping merged and overridden: the
    data YAML gives, each place its own copy, the lines of the places where the values are written."""
    text = ("front:\n  damper: &damper {curve: [[-1.0, -900.0], [1.0, 3000.0]]}\n  spring: &spring {rate: 28000.0, preload: auto}\n"
            "rear:\n  damper: *damper\n  spring:\n    <<: *spring\n    rate: 36000.0\n")
    doc = Document(text, "car.yaml")
    assert doc.data == {"front": {"damper": {"curve": [[-1.0, -900.0], [1.0, 3000.0]]},
                                  "spring": {"rate": 28000.0, "preload": "auto"}},
                        "rear": {"damper": {"curve": [[-1.0, -900.0], [1.0, 3000.0]]},
                                 "spring": {"rate": 36000.0, "preload": "auto"}}}
    assert doc.data["rear"]["damper"] is not doc.data["front"]["damper"]   # changing one leaves the other
    assert doc.lines[("rear", "spring", "rate")] == 8 and doc.lines[("rear", "spring", "preload")] == 3
    assert doc.where(("rear", "damper", "curve")) == "car.yaml:2"


def test_what_yaml_safe_dump_writes_reads_back_as_the_same_data() -> None:
    """A scenario of 300 cases built in Python from one mapping: safe_dump writes it with an anchor
    and 299 aliases, and the reader gives back the data."""
    case = {"amplitude_mm": 20.0, "frequency_hz": 0.5}
    data = {"name": "many", "type": "pumping", "vehicle": "c_segment", "cases": [case] * 300}
    text = yaml.safe_dump(data)
    assert text.count("*id") == 299
    assert Document(text, "s.yaml").data == data


def test_exponents_without_a_dot_are_numbers_as_in_yaml_1_2_and_written_back_quoted_as_text() -> None:
    data = Document("a: 1e-6\nb: 1.5e3\nc: .5E2\nd: 1e400\ne: x1e5\nf: ._e5\n", "t.yaml").data
    assert data == {"a": 1e-6, "b": 1500.0, "c": 50.0, "d": float("inf"), "e": "x1e5", "f": "._e5"}
    texts = {"label": "2e3", "other": "1.5E-3", "number": 2e3}
    assert Document(dump_yaml(texts), "t.yaml").data == texts   # the project's own files read back alike


def test_a_scalar_python_cannot_convert_is_refused_at_its_line() -> None:
    with pytest.raises(InputError, match=r"t\.yaml:2: '2024-13-45' cannot be read as a value \(month must be"):
        Document("a: 1\nb: 2024-13-45\n", "t.yaml")


# -- scenarios and benches: names, durations, samples -----------------------------------------------
@pytest.mark.parametrize("name", ["../../x", "/tmp/x", "a/b", ".hidden"])
def test_a_scenario_name_cannot_leave_the_output_folder(tmp_path: Path, name: str) -> None:
    text = (SCENARIO_DIR / "pumping.yaml").read_text().replace("name: pumping", f"name: {name!r}", 1)
    text = "\n".join("vehicle: c_segment" if s.startswith("vehicle:") else s for s in text.splitlines())
    file = tmp_path / "s.yaml"
    file.write_text(text)
    with pytest.raises(InputError, match=r"s\.yaml:\d+: name: expected a plain name"):
        load_scenario(file)


def test_a_scenario_input_longer_than_an_hour_is_refused_before_it_is_built(tmp_path: Path) -> None:
    data = yaml.safe_load((SCENARIO_DIR / "lateral_force.yaml").read_text())
    data["defaults"]["cycles"], data["vehicle"] = 10 ** 300, "c_segment"
    file = tmp_path / "s.yaml"
    file.write_text(yaml.safe_dump(data, sort_keys=False))
    started = time.perf_counter()
    with pytest.raises(InputError, match=r"cycles: 1e\+300 cycles of 10 s last 1e\+301 s; expected at most 3600 s"):
        load_scenario(file)
    assert time.perf_counter() - started < 5.0


def test_a_triangle_faster_than_the_rig_samples_is_refused(tmp_path: Path) -> None:
    data = {**yaml.safe_load((SCENARIO_DIR / "pumping_speeds.yaml").read_text()), "vehicle": "c_segment"}
    data["cases"][0]["speed_mm_s"] = 1e300
    file = tmp_path / "s.yaml"
    file.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(InputError, match=r"cases\[0\]\.speed_mm_s: a triangle of period 2\.4e-298 s .* at most 50 Hz"):
        load_scenario(file)


@pytest.mark.parametrize("change,expected", [
    ({"dt_s": 1e-12}, r"dt_s|samples"),
    ({"programme": {"type": "sine", "amplitude_mm": 1.0, "frequency_hz": 1.0, "cycles": 1e9}},
     r"programme: 2e\+12 samples at dt_s = 0\.0005 s; expected at most 1e\+07"),
])
def test_a_bench_asking_for_terabytes_is_refused(tmp_path: Path, change: dict, expected: str) -> None:
    data = {**yaml.safe_load((BENCH_DIR / "bisine.yaml").read_text()), **change}
    data["params"] = "fig5_9_caption"
    file = tmp_path / "b.yaml"
    file.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(InputError, match=expected):
        load_bench(file)


# -- rig CSV files --------------------------------------------------------------------------------
@pytest.mark.parametrize("edit,expected", [
    (lambda lines: [lines[0] + "," + lines[0].split(",")[1]] + [r + ",0" for r in lines[1:]],
     r"line 1: column '\w+' appears 2 times"),
    (lambda lines: lines[:3] + [lines[3] + ",1"] + lines[4:], r"line 4: 26 fields; expected 25"),
    (lambda lines: lines[:5] + [",".join(["1e300"] + lines[5].split(",")[1:])] + lines[6:],
     r"line 6, column time_ms: '1e300' is beyond any plausible value"),
])
def test_malformed_rig_csv_files_are_refused_at_their_line(tmp_path: Path, edit, expected: str) -> None:
    lines = (EXAMPLE / "kc_pumping.csv").read_text().splitlines()
    meta = yaml.safe_load((EXAMPLE / "META.yaml").read_text())
    meta["scenario"] = str(SCENARIO_DIR / "pumping.yaml")
    (tmp_path / "META.yaml").write_text(yaml.safe_dump(meta, sort_keys=False))
    (tmp_path / "data.csv").write_text("\n".join(edit(lines)) + "\n")
    with pytest.raises(InputError, match=expected):
        import_csv(tmp_path / "data.csv", tmp_path / "META.yaml", tmp_path / "rig.mcap")
    assert not (tmp_path / "rig.mcap").exists()


def test_a_record_imported_under_another_scenario_is_refused(tmp_path: Path) -> None:
    """The shipped pumping export with a META naming the roll test: refused at its first pad sample
    off, naming the line, the column, the time and both values (issue 50: it was imported as roll)."""
    meta = (EXAMPLE / "META.yaml").read_text().replace("../../../scenarios/pumping.yaml", str(SCENARIO_DIR / "kc/roll.yaml"))
    (tmp_path / "META.yaml").write_text(meta)
    with pytest.raises(InputError) as error:
        import_csv(EXAMPLE / "kc_pumping.csv", tmp_path / "META.yaml", tmp_path / "rig.mcap")
    line = int(error.value.key.split(",")[0].removeprefix("line "))
    header, *rows = (EXAMPLE / "kc_pumping.csv").read_text().splitlines()
    column, row = error.value.key.split("column ")[1], rows[line - 2].split(",")
    recorded, t_s = float(row[header.split(",").index(column)]), float(row[0]) / 1e3
    assert column in ("pad_z_FL_mm", "pad_z_FR_mm", "pad_z_RL_mm", "pad_z_RR_mm")
    assert f"the rig input is {recorded:.6g} mm at t = {t_s:.9g} s where the scenario kc_roll commands " in str(error.value)
    assert not (tmp_path / "rig.mcap").exists()


def test_a_bench_record_with_one_absurd_force_sample_is_refused(tmp_path: Path) -> None:
    file = tmp_path / "r.csv"
    file.write_text("t_s,e_mm,F_N\n0,0,0\n0.01,0.1,1e30\n0.02,0.2,3\n")
    with pytest.raises(InputError, match=r"r\.csv: line 3, column F_N: '1e30' is beyond any plausible value"):
        read_bench_csv(file)


# -- the command line: arguments and output paths checked before any work --------------------------
def _vsim(capsys: pytest.CaptureFixture, *argv: str) -> tuple[int, str]:
    try:
        code = main(list(argv))
    except SystemExit as exc:   # argparse's own refusals
        code = int(exc.code)
    return code, capsys.readouterr().err


@pytest.mark.parametrize("scale", ["inf", "nan", "0", "-1", "1e400", "abc"])
def test_a_duration_scale_that_is_not_a_finite_positive_number_is_refused(capsys, scale: str) -> None:
    code, err = _vsim(capsys, "run", "pumping", "--duration-scale", scale)
    assert code == 2 and "--duration-scale" in err and "Traceback" not in err


@pytest.mark.parametrize("kind", ["directory", "under_a_file", "existing"])
def test_output_paths_are_checked_before_the_run_starts(tmp_path: Path, capsys, kind: str) -> None:
    target = {"directory": tmp_path, "under_a_file": tmp_path / "f.txt" / "run.mcap",
              "existing": tmp_path / "run.mcap"}[kind]
    (tmp_path / "f.txt").write_text("a file")
    (tmp_path / "run.mcap").write_bytes(b"earlier run")
    started = time.perf_counter()
    code, err = _vsim(capsys, "run", "pumping", "-o", str(target))
    assert code == 2 and "Traceback" not in err, err
    assert time.perf_counter() - started < 10.0   # the run would take over a minute
    assert (tmp_path / "run.mcap").read_bytes() == b"earlier run"


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_output_folder_is_refused_before_the_run(tmp_path: Path, capsys) -> None:
    folder = tmp_path / "ro"
    folder.mkdir(mode=0o555)
    code, err = _vsim(capsys, "run", "pumping", "-o", str(folder / "run.mcap"))
    assert code == 2 and "permission denied" in err


# -- signals and cut recordings -------------------------------------------------------------------
def test_sigterm_leaves_a_readable_incomplete_recording_and_status_143(tmp_path: Path) -> None:
    output = tmp_path / "run.mcap"
    # five times the main job's durations: a run of 20 s or so, never over before the signal (4 s at 1)
    proc = subprocess.Popen([sys.executable, "-m", "elastokin", "run", "pumping", "-o", str(output),
                             "--duration-scale", "5"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=tmp_path)
    deadline = time.monotonic() + 120.0
    while not list(tmp_path.glob("*.partial")) and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.2)
    time.sleep(3.0)   # some simulated time recorded
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "SIGTERM" in err and "Traceback" not in err
    run = load_run(output)
    assert not run.complete and "SIGTERM" in run.reason
    assert len(run.t_s) > 10 and np.all(np.diff(run.t_s) > 0)
    assert not list(tmp_path.glob("*.partial"))


@pytest.fixture(scope="module")
def short_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    output = tmp_path_factory.mktemp("run") / "run.mcap"
    assert main(["run", "pumping", "--duration-scale", "0.05", "-o", str(output)]) == 0
    return output


def test_a_cut_recording_is_read_as_far_as_it_goes_and_marked_incomplete(short_run: Path, tmp_path: Path) -> None:
    whole = load_run(short_run)
    data = short_run.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) * 2 // 3])
    part = load_run(cut)
    assert whole.complete and not part.complete
    n = len(part.t_s)
    assert 0 < n < len(whole.t_s)
    np.testing.assert_array_equal(part.t_s, whole.t_s[:n])
    for name in list(whole.signals)[:5]:
        np.testing.assert_array_equal(part.signals[name], whole.signals[name][:n])
    cut.write_bytes(data[:8])   # the magic bytes only
    with pytest.raises(InputError, match=r"cut\.mcap"):
        load_run(cut)


def test_a_vehicle_file_may_share_its_damper_curve_between_the_axles(tmp_path: Path) -> None:
    """The rear damper written as an alias of the front one is the vehicle with the front's curve
    written out at the rear, and its errors still name the place."""
    text = DEFAULT_VEHICLE.read_text()
    shared = text.replace("  damper:                           #", "  damper: &damper                  #", 1)
    shared = shared.replace("  damper:\n    curve: [[-1.0, -3000.0], [0.0, 0.0], [1.0, 1200.0]]  # [m/s, N]  # assumption\n",
                            "  damper: *damper\n", 1)
    written = text.replace("    curve: [[-1.0, -3000.0], [0.0, 0.0], [1.0, 1200.0]]",
                           "    curve: [[-1.0, -3600.0], [0.0, 0.0], [1.0, 1400.0]]", 1)
    assert shared.count("*damper") == 1 and written != text
    (tmp_path / "shared.yaml").write_text(shared)
    (tmp_path / "written.yaml").write_text(written)
    a, b = load_vehicle(tmp_path / "shared.yaml"), load_vehicle(tmp_path / "written.yaml")
    assert a.rear.damper == b.rear.damper == a.front.damper and (a.front, a.rear, a.bushings) == (b.front, b.rear, b.bushings)


#: Every command that writes, with what it reads (none of it read before the output is refused)
#: and whether its output is a folder: (argv before the output option, the option, folder).
WRITERS = [
    (["run", "pumping"], "-o", False),
    (["plot", "run.mcap"], "-o", True),
    (["view", "run.mcap"], "--save", False),
    (["compare", "a.mcap", "b.mcap"], "-o", True),
    (["bushing", "run", "bisine"], "-o", False),
    (["bushing", "run", "bisine", "-o", "ok.csv"], "--plot", True),
    (["bushing", "fit", "r.csv"], "-o", False),
    (["bushings-on-road", "road/step_steer"], "-o", True),
    (["diagnose", "kc"], "-o", True),
    (["sweep", "e2_front_kr_co"], "-o", True),
    (["rig", "import", "d.csv", "--meta", "m.yaml"], "-o", False),
    (["rig", "measure", "truth.yaml"], "-o", True),
    (["model", "export", "c_segment"], "-o", False),
    (["copy", "c_segment"], None, True),
]


@pytest.mark.parametrize("argv, option, folder, place", [
    (argv, option, folder, place) for argv, option, folder in WRITERS
    for place in ("proc", "file_for_folder" if folder else "folder_for_file", "under_a_file")],
    ids=lambda w: w if isinstance(w, str) else None)
def test_an_output_no_file_can_be_made_at_is_refused_before_any_work(tmp_path: Path, capsys, monkeypatch, argv, option,
                                                                     folder, place) -> None:
    """Where no file can be made (/proc, even as root), a file given for a folder and the reverse,
    a path under a file: refused by the command line with the path and the reason, before anything
    is read or run (the inputs named here do not exist)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a_file").write_text("x")
    (tmp_path / "a_folder").mkdir()
    target, words = {"proc": ("/proc/vsim_out", ["/proc", "no file can be made here"]),
                     "file_for_folder": ("a_file", ["a_file", "is a file; expected a folder"]),
                     "folder_for_file": ("a_folder", ["a_folder", "is a folder; expected a file"]),
                     "under_a_file": ("a_file/out", ["a_file", "is a file; it cannot hold"])}[place]
    code, err = _vsim(capsys, *argv, *([option] if option else []), target)
    assert code == 2 and "Traceback" not in err, err
    for word in words:
        assert word in err, err


@pytest.fixture(scope="module")
def chunked_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A pumping run of 1.4 MB: two chunks of 1 MiB."""
    output = tmp_path_factory.mktemp("chunked") / "run.mcap"
    assert main(["run", "pumping", "--duration-scale", "0.1", "-o", str(output)]) == 0
    return output


#: Damage kinds: the words the reading says, and whether the data is whole.
DAMAGE = {"cut_half": ([r"recording cut at \d+\.\d s of its 13\.\d s \((no summary section|the file ends inside a record)\): "
                       r"read as far as it goes"], False),
          "inverted": ([r"chunk \d+ of \d+ failed its CRC: \d\.\d s missing \(t = \d+\.\d to \d+\.\d s\)"], False),
          "cut_last_byte": ([r"its summary section is cut \(the file ends inside a record\); its data is whole"], True)}


def _read_damaged(chunked_run: Path, folder: Path, kind: str) -> tuple[Path, Run, Run, str]:
    """The run damaged as ``kind``, read: what is read is the original's, less what the warning says
    missing; returns the damaged file, its run, the original's and the warning."""
    words, whole = DAMAGE[kind]
    original = load_run(chunked_run)
    path = damaged(chunked_run, folder, kind)
    with pytest.warns(UserWarning) as said:
        run = load_run(path)
    message = str(said[0].message)
    assert all(re.search(w, message) for w in words), message
    assert run.complete == whole and run.damage == (message.removeprefix(f"{path}: "),)
    if whole:
        assert np.array_equal(run.t_s, original.t_s)
    else:
        assert 0 < len(run.t_s) < len(original.t_s) and np.all(np.isin(run.t_s, original.t_s))
        kept = np.isin(original.t_s, run.t_s)
        assert np.array_equal(run.signals["camber_fl"], original.signals["camber_fl"][kept])
    with pytest.raises(InputError, match="damaged"):
        elastokin.load_run(path, strict=True)
    return path, run, original, message


@pytest.mark.parametrize("kind", DAMAGE)
def test_a_damaged_recording_is_read_as_far_as_it_goes_and_said_damaged(chunked_run: Path, tmp_path: Path,
                                                                        kind) -> None:
    """Cut short, 64 bytes inverted, its summary cut: read as far as it goes, the reason and the part
    missing said in a warning and in the run and, for a run whose data is whole, in its comparison
    with the original; a strict reading refuses it."""
    path, run, original, message = _read_damaged(chunked_run, tmp_path, kind)
    if DAMAGE[kind][1]:
        assert compare_runs(run, original).to_json()["damage"] == {str(path): [message.removeprefix(f"{path}: ")]}


# plot and compare draw some 50 figures (30 s on a core): every damage in the slow stage
@pytest.mark.parametrize("kind", ["cut_half", *(pytest.param(k, marks=pytest.mark.slow) for k in DAMAGE
                                                if k != "cut_half")])
def test_a_damaged_recording_is_said_damaged_by_every_reader(chunked_run: Path, tmp_path: Path, capsys,
                                                            kind) -> None:
    """The damage said on stderr by plot, view, compare and in the comparison; --strict refuses it."""
    path, _, _, message = _read_damaged(chunked_run, tmp_path, kind)
    for argv in (["plot", str(path), "-o", str(tmp_path / "p")], ["view", str(path), "--save", str(tmp_path / "v.rrd")],
                 ["compare", str(path), str(chunked_run), "-o", str(tmp_path / "c")]):
        code, err = _vsim(capsys, *argv)
        # a run that lost a case's samples cannot be compared case by case: refused, the damage said first
        refused = argv[0] == "compare" and "has no input samples (the run is incomplete" in err
        assert code == (2 if refused else 0) and f"vsim: warning: {message}" in err, (argv, err)
        compared = argv[0] != "compare" or not refused
        code, err = _vsim(capsys, *argv, "--strict", *(["--overwrite"] if argv[0] == "view" else []))
        assert code == 2 and "damaged, and refused as strict reading asks" in err, (argv, err)
    if compared:
        comparison = json.loads((tmp_path / "c" / "comparison.json").read_text())
        assert comparison["damage"] == {str(path): [message.removeprefix(f"{path}: ")]}


def test_a_recording_cut_before_its_first_sample_is_refused_by_plot_and_view(chunked_run: Path, tmp_path: Path,
                                                                            capsys) -> None:
    path = damaged(chunked_run, tmp_path, "cut_at_start")
    for argv, what in ((["plot", str(path), "-o", str(tmp_path / "p")], "plot"),
                       (["view", str(path), "--save", str(tmp_path / "v.rrd")], "replay")):
        code, err = _vsim(capsys, *argv)
        assert code == 2 and "recording cut before its first whole sample" in err and "Traceback" not in err, err
        assert f"holds no whole sample: nothing to {what}" in err


def test_a_kc_dataset_with_a_damaged_recording_is_refused_unless_asked(tmp_path: Path, capsys) -> None:
    folder = damaged_kc_dataset(tmp_path)
    code, err = _vsim(capsys, "diagnose", str(folder))
    assert code == 2 and re.search(r"rig\.yaml: recordings\[1\]: 02_kc_roll\.mcap is incomplete \(chunk 4 of 6 failed "
                                   r"its CRC: [\d.]+ s missing \(t = [\d.]+ to [\d.]+ s\)\); --use-damaged", err), err
    assert "vsim: warning: " in err and "Traceback" not in err
    code, err = _vsim(capsys, "diagnose", "bench", "--bushing-set", "fig5_9_caption", "--use-damaged")
    assert code == 2 and "--use-damaged (use_damaged=True) is for a K&C dataset's recordings" in err
    with pytest.warns(DamagedRecording):
        kept = read_kc_dataset(folder, use_damaged=True)
    assert kept.damage == (f"02_kc_roll.mcap: {kept.tests[1].run.reason}",)
    vehicle = load_vehicle(DEFAULT_VEHICLE)
    whole, part = Layout.of(read_kc_dataset(DATASET_DIR / "kc"), vehicle), Layout.of(kept, vehicle)
    assert [t.name for t in part.tests] == [t.name for t in whole.tests]
    lost = {p.name: len(w.rows) - len(p.rows) for w, p in zip(whole.tests, part.tests)}
    assert sum(lost.values()) > 0 and all(n == 0 for name, n in lost.items() if not name.startswith("02_kc_roll"))
    whole_by_name = {t.name: t for t in whole.tests}
    for t in part.tests:   # each row is the whole dataset's at its test and sample
        np.testing.assert_array_equal(part.measured[t.rows], whole.measured[whole_by_name[t.name].rows][t.samples])
    # a simulation's input phase goes to the samples recorded
    simulated = {t.name: {ch: whole.measured[t.rows, j] for j, ch in enumerate(whole.channels)} for t in whole.tests}
    stacked = RunRows(part, [range(len(part.tests))])
    for i, t in enumerate(part.tests):
        stacked.place(0, simulated[t.name], i)
    np.testing.assert_array_equal(stacked[0], part.measured)
