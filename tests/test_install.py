"""The software works wherever it is installed (issue 25): built-in vehicles, scenarios and bench
programmes can be named, and a wheel, installed outside the source tree, carries them and runs a
built-in scenario from an empty folder."""

from __future__ import annotations

import gc
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from elastokin.bushings.bench.bench_file import load_bench
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.scenario_file import load_scenario
import elastokin.cli.main
from elastokin.cli import executable
from elastokin.core.errors import InputError
from elastokin.core.shipped import BENCH_DIR, DEFAULT_VEHICLE, KC_SCENARIO_DIR, SCENARIO_DIR
from elastokin.recordings.run_reader import load_run

ROOT = Path(__file__).resolve().parents[1]


def test_built_in_files_are_found_by_name_from_any_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert load_scenario("pumping") == load_scenario(SCENARIO_DIR / "pumping.yaml")
    assert load_scenario("kc/roll") == load_scenario(KC_SCENARIO_DIR / "roll.yaml")
    assert load_vehicle("c_segment") == load_vehicle(DEFAULT_VEHICLE)
    named, by_path = load_bench("bisine").programme, load_bench(BENCH_DIR / "bisine.yaml").programme
    assert named.kind == "bisine" and np.array_equal(named.e_m, by_path.e_m)
    # a file in the working folder comes first, even one named as a built-in
    (tmp_path / "pumping").write_text("name: mine\ntype: pumping\nvehicle: c_segment\n"
                                      "cases: [{amplitude_mm: 5, frequency_hz: 1}]\n")
    mine = load_scenario("pumping")
    assert mine.name == "mine" and mine.vehicle == DEFAULT_VEHICLE


@pytest.mark.parametrize("name, load, words", [
    ("pumpin", load_scenario, ["pumpin: no such scenario file, and no built-in one of that name", "kc/roll", "pumping"]),
    ("../models/vehicles/c_segment", load_scenario, ["no built-in one of that name"]),   # names stay in their folder
    ("c_segmnt", load_vehicle, ["built-in ones: c_segment"]),
    ("nope.yaml", load_bench, ["nope.yaml: no such bench file", "built-in ones: bisine"]),
])
def test_an_unknown_name_lists_the_built_in_ones(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str, load,
                                                 words: list[str]) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError) as error:
        load(name)
    for word in words:
        assert word in str(error.value), str(error.value)


def test_a_scenario_names_an_unknown_vehicle_at_its_line(tmp_path: Path) -> None:
    scenario = tmp_path / "s.yaml"
    scenario.write_text("type: pumping\nvehicle: c_segmnt\ncases: [{amplitude_mm: 5, frequency_hz: 1}]\n")
    with pytest.raises(InputError, match=r"s\.yaml:2: vehicle: .*c_segmnt: no such vehicle file.*built-in ones: c_segment"):
        load_scenario(scenario)


def test_the_wheel_runs_a_built_in_scenario_from_an_empty_folder(tmp_path: Path) -> None:
    """Build the wheel from the project's files, install it (without dependencies: they are this
    environment's) into a folder of its own, and run its ``vsim run pumping`` from an empty folder with
    only that folder on the path: the shipped data must come from the wheel, not the source tree."""
    wheels, target, empty, source = tmp_path / "wheels", tmp_path / "site", tmp_path / "empty", tmp_path / "source"
    empty.mkdir()
    # a copy without earlier builds (a stale build/ would hide a package missing from pyproject.toml)
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(".git", ".venv", "build", "*.egg-info", "out",
                                                                 "tests", "__pycache__", ".hypothesis"))
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation", "-w", str(wheels),
                    str(source)], check=True, capture_output=True, timeout=300, cwd=tmp_path)
    wheel, = wheels.glob("elastokin-*.whl")
    # one top-level import package (and its metadata): nothing of ours stands beside another project's modules
    tops = {name.split("/")[0] for name in zipfile.ZipFile(wheel).namelist()}
    assert {top for top in tops if not top.endswith(".dist-info")} == {"elastokin"}, tops
    # another distribution's top-level `vehicle` and `bushings`, installed first, are still there after ours
    other = tmp_path / "other"
    for name in ("vehicle", "bushings"):
        (other / name).mkdir(parents=True)
        (other / name / "__init__.py").write_text(f"WHO = 'the other {name}'\n")
    (other / "pyproject.toml").write_text('[project]\nname = "other-vehicle"\nversion = "1.0"\n'
                                          '[tool.setuptools]\npackages = ["vehicle", "bushings"]\n')
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--no-build-isolation", "--target",
                    str(target), str(other)], check=True, capture_output=True, timeout=300, cwd=tmp_path)
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(target), str(wheel)],
                   check=True, capture_output=True, timeout=300)
    env = {**os.environ, "PYTHONPATH": str(target)}
    where = subprocess.run([sys.executable, "-c", "import elastokin.core.shipped as s, vehicle, bushings, elastokin.vehicle;"
                            "print(s.SCENARIO_DIR, s.DEFAULT_TYRE.is_file(), (s.DATASET_DIR / 'kc' / 'rig.yaml').is_file(),"
                            "vehicle.WHO == 'the other vehicle', bushings.WHO == 'the other bushings')"],
                           env=env, cwd=empty, capture_output=True, text=True, check=True).stdout.split()
    # the .tir and the example datasets travel too
    assert Path(where[0]) == target / "elastokin" / "scenarios" and where[1:] == ["True"] * 4
    # the console script the README's first command runs (pip writes it into the target's bin/)
    done = subprocess.run([str(target / "bin" / "vsim"), "run", "pumping", "--duration-scale", "0.05"],
                          env=env, cwd=empty, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    run = load_run(empty / "out" / "pumping.mcap")
    assert run.complete and run.metadata.extra["scenario"] == "pumping"
    assert run.metadata.git_revision == "unknown"   # no source tree around an installed copy
    assert "c_segment" in run.metadata.vehicle_yaml and run.t_s[-1] > 5.0


@pytest.mark.parametrize("preset", [None, "egl"])
def test_the_executable_runs_the_command_with_the_collector_on(monkeypatch, preset) -> None:
    """``vsim`` (``elastokin.cli.executable``) passes the command's exit status through; the command runs
    with the garbage collector on (only what the imports made is set aside) and MuJoCo's OpenGL back
    end off unless the user chose one."""
    seen = {}

    def command() -> int:
        seen.update(enabled=gc.isenabled(), frozen=gc.get_freeze_count(), gl=os.environ.get("MUJOCO_GL"))
        return 3

    monkeypatch.setattr(elastokin.cli.main, "main", command)
    if preset is None:
        monkeypatch.delenv("MUJOCO_GL", raising=False)
    else:
        monkeypatch.setenv("MUJOCO_GL", preset)
    try:
        assert executable.main() == 3
    finally:
        gc.unfreeze()   # this test's process goes on: its objects back in the collector's care
        gc.enable()
    assert seen["enabled"] and seen["frozen"] > 0
    assert seen["gl"] == (preset or "disable")


def test_a_reader_that_leaves_ends_the_command_quietly(tmp_path: Path) -> None:
    """`vsim list | true`: the reader is gone before the command writes; the command ends with
    SIGPIPE's status and no traceback."""
    done = subprocess.run(["bash", "-c", f"{sys.executable} -m elastokin list 2>err.txt | true; echo ${{PIPESTATUS[0]}}"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.stdout.split()[-1] == "141" and (tmp_path / "err.txt").read_text() == ""
