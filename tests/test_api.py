"""The Python API (issue 49): the front door's examples run, a run's signals are the recording's in SI,
a run saved later is the recording made while it ran, values set by place change the car as physics
says, and the built-ins can be listed, copied and run from anywhere."""

from __future__ import annotations

import doctest
import io
import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

import elastokin
from elastokin.api import built_ins, diagnosis, runs, scenarios, simulation, sweeps, vehicles
from elastokin.api.kernels import compile_kernels
from elastokin.cli.main import main
from elastokin.core.errors import InputError
from elastokin.presentation.compile_notice import compile_notice
from elastokin.recordings.run_reader import load_run

ROOT = Path(__file__).resolve().parents[1]
QUICK = 0.02   #: duration scale of the runs here: 2.6 s of pumping


@pytest.fixture(scope="module")
def pumping() -> elastokin.Run:
    return elastokin.Simulation("c_segment", "pumping", duration_scale=QUICK).run()


@pytest.mark.parametrize("module", [vehicles, scenarios, runs, simulation, built_ins, diagnosis, sweeps],
                         ids=lambda m: m.__name__)
def test_the_api_examples_run(module) -> None:
    failed, tried = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert failed == 0
    assert tried > 0 or module in (diagnosis, sweeps)   # their examples are in the README and the notebook


def test_every_name_of_the_front_door_is_there_and_documented() -> None:
    for name in elastokin.__all__:
        value = getattr(elastokin, name)
        assert name == "__version__" or value.__doc__, name
    with pytest.raises(AttributeError, match="no attribute 'Simulaton'"):
        elastokin.Simulaton


def test_a_signal_is_the_recordings_in_si(pumping: elastokin.Run) -> None:
    recorded = pumping.recorded
    assert recorded.units["camber_fl"] == "deg" and pumping.units["camber_fl"] == "rad"
    assert np.array_equal(pumping["camber_fl"], recorded.signals["camber_fl"] * (math.pi / 180.0))
    assert recorded.units["wheel_travel_fl"] == "mm" and pumping.units["wheel_travel_fl"] == "m"
    assert np.allclose(pumping["wheel_travel_fl"] * 1e3, recorded.signals["wheel_travel_fl"], rtol=1e-15, atol=0)
    assert pumping["pad_fz_fl"].shape == pumping.t_s.shape == (len(pumping),)
    assert pumping.units["pad_fz_fl"] == "N"
    assert [c["case"] for c in pumping.cases] == [1, 2, 3, 4, 5, 6]
    mask = pumping.case(6)
    assert pumping.t_s[mask][0] >= pumping.cases[5]["start_s"] - 1e-9 and mask[-1]
    with pytest.raises(KeyError, match="did you mean camber_fr, camber_fl"):
        pumping["camber_f1"]


def test_the_metrics_are_those_vsim_run_prints(pumping: elastokin.Run) -> None:
    metrics = pumping.metrics()
    front = metrics[6]["front"]
    # bump camber of a McPherson front: negative (camber-top-out positive, ISO 8855), tens of deg/m
    assert -60.0 < front["bump_camber_deg_per_m"] < -5.0
    assert f"{front['bump_camber_deg_per_m']:.5g}" in pumping.summary()
    assert json.loads(json.dumps(metrics)) == {str(k): v for k, v in metrics.items()}   # plain numbers


def test_figures_are_returned_not_written(pumping: elastokin.Run, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    figures = pumping.plot()
    camber = figures["pairs_camber"]
    x, y = camber.axes[0].lines[0].get_data()
    assert np.array_equal(x, pumping.recorded.signals["wheel_travel_fl"]) and np.array_equal(y, pumping.recorded.signals["camber_fl"])
    assert set(pumping.plot("time")) == {k for k in pumping.plot("all") if k.startswith("time_")}
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match="pairs, time, all"):
        pumping.plot("loops")


def test_a_run_saved_later_is_the_recording_made_while_it_ran(pumping: elastokin.Run, tmp_path: Path) -> None:
    later = pumping.save(tmp_path / "later.mcap")
    streamed = elastokin.Simulation("c_segment", "pumping", duration_scale=QUICK).run(output=tmp_path / "while.mcap")
    assert later.read_bytes() == (tmp_path / "while.mcap").read_bytes()
    assert streamed.save(tmp_path / "again.mcap").read_bytes() == later.read_bytes()
    # and vsim run's, whose scenario names its car by another spelling of the path
    assert main(["run", "pumping", "--duration-scale", str(QUICK), "-o", str(tmp_path / "cli.mcap")]) == 0
    assert (tmp_path / "cli.mcap").read_bytes() == later.read_bytes()
    back = elastokin.load_run(later)
    assert back.complete and np.array_equal(back["camber_fl"], pumping["camber_fl"])
    assert back.recorded.body_names and back.recorded.body_pos.shape[0] == len(back)
    with pytest.raises(InputError, match="exists"):
        pumping.save(later)
    with pytest.raises(InputError, match="/proc: no file can be made here"):
        pumping.save("/proc/run.mcap")


def _spring_rate(run: elastokin.Run, case: int) -> float:
    """The front-left spring's force per wheel travel in case ``case`` (least squares) [N/m]."""
    mask = run.case(case) & (run.t_s >= run.cases[case - 1]["input_start_s"])
    return float(np.polyfit(run["wheel_travel_fl"][mask], run["front_left_spring_force"][mask], 1)[0])


def test_a_value_set_by_its_place_changes_the_car_as_physics_says(pumping: elastokin.Run) -> None:
    """A coil spring 1.5 times as stiff, on the same kinematics, pushes 1.5 times as hard per wheel
    travel (its preload solved again for the same ride height)."""
    car = elastokin.load_vehicle("c_segment")
    stiffer = car.with_values({"front.spring.rate": 1.5 * car.value("front.spring.rate")})
    assert stiffer.value("front.spring.rate") == 42000.0 and car.value("front.spring.rate") == 28000.0
    run = elastokin.Simulation(stiffer, "pumping", duration_scale=QUICK).run()
    assert _spring_rate(run, 6) / _spring_rate(pumping, 6) == pytest.approx(1.5, rel=0.01)
    assert run.metadata["vehicle_file"].endswith("c_segment.yaml (changed in code)")
    assert pumping.metadata["vehicle_file"].endswith("c_segment.yaml")


@pytest.mark.parametrize("values, words", [
    ({"front.spring.rte": 1.0}, ["front.spring.rte", "rte"]),
    ({"bushings.e2_frnt.y.Kr": 1.0}, ["no bushing 'e2_frnt'"]),
    ({"front.spring.rate": -5.0}, ["front.spring.rate", "-5"]),
    ({"front.spring.rate": "26000"}, ["with_values: front.spring.rate: expected a finite number, got '26000'"]),
    ({"front.spring.rate": True}, ["with_values: front.spring.rate: expected a finite number, got True"]),
    ({"front.spring.rate": None}, ["expected a finite number, got None"]),
    ({"front.spring.rate": float("nan")}, ["expected a finite number, got nan"]),
])
def test_a_bad_value_is_named_by_its_place(values, words) -> None:
    with pytest.raises(InputError) as error:
        elastokin.load_vehicle().with_values(values)
    for word in words:
        assert word in str(error.value), str(error.value)


def test_a_scenario_written_in_python_runs_and_is_checked(tmp_path: Path) -> None:
    spec = {"name": "quick", "type": "pumping", "vehicle": "c_segment", "output_rate_hz": 50,
            "cases": [{"amplitude_mm": 20, "frequency_hz": 1.0}]}
    run = elastokin.Simulation(None, elastokin.scenario_from(spec), duration_scale=0.2).run()
    assert run.metadata["scenario"] == "quick" and len(run.cases) == 1
    assert 15.0 < np.max(run.recorded.signals["wheel_travel_fl"]) <= 20.0 + 1e-6
    with pytest.raises(InputError, match="scenario_from.*amplitude_mm"):
        elastokin.scenario_from({**spec, "cases": [{"amplitude_mm": "big", "frequency_hz": 1.0}]})
    with pytest.raises(InputError, match="duration_scale"):
        elastokin.Simulation(None, "pumping", duration_scale=0)
    with pytest.raises(InputError, match="bushings.*stvs"):
        elastokin.Simulation(None, "pumping", bushings="magic")


def test_the_built_ins_are_listed_copied_and_run_from_the_copy(tmp_path: Path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["list"]) == 0
    listed = capsys.readouterr().out
    for name in ("c_segment", "road/step_steer", "fig5_9", "195_65R15", "e2_front_kr_co", "bisine", "kc", "bench"):
        assert f"  {name}\n" in listed
    assert main(["copy", "c_segment", "mine"]) == 0 and main(["copy", "pumping", "mine"]) == 0
    assert sorted(p.name for p in (tmp_path / "mine").iterdir()) == ["195_65R15.tir", "c_segment.yaml", "pumping.yaml"]
    copy = elastokin.load_vehicle(tmp_path / "mine" / "c_segment.yaml")
    assert copy.definition.tyre.property_file == tmp_path / "mine" / "195_65R15.tir"
    built = elastokin.load_vehicle().definition
    assert (copy.definition.front, copy.definition.rear, copy.definition.bushings) == (built.front, built.rear, built.bushings)
    # the scenario copied beside the copied car runs on it: an edit of the copy is the car the run plays
    assert elastokin.load_scenario(tmp_path / "mine" / "pumping.yaml").vehicle == tmp_path / "mine" / "c_segment.yaml"
    edited = (tmp_path / "mine" / "c_segment.yaml").read_text().replace("rate: 28000.0", "rate: 42000.0", 1)
    (tmp_path / "mine" / "c_segment.yaml").write_text(edited)
    sim = elastokin.Simulation(None, tmp_path / "mine" / "pumping.yaml", duration_scale=QUICK)
    assert sim.vehicle.value("front.spring.rate") == 42000.0
    # copied alone, a scenario names the built-in car
    assert main(["copy", "pumping", "alone"]) == 0
    assert elastokin.load_scenario(tmp_path / "alone" / "pumping.yaml").vehicle == elastokin.load_vehicle().path
    assert main(["copy", "pumping", "mine"]) == 2
    assert "already there" in capsys.readouterr().err
    assert main(["copy", "pumpin", "mine"]) == 2
    assert "no built-in of that name" in capsys.readouterr().err


def test_the_shipped_datasets_are_found_by_name(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert elastokin.dataset("kc") == ROOT / "data" / "rig" / "kc"
    with pytest.raises(InputError, match="shipped ones: bench, kc"):
        elastokin.dataset("kc_exampel")
    (tmp_path / "kc").mkdir()   # a folder of that name that is no dataset does not hide the shipped one
    assert elastokin.dataset("kc") == ROOT / "data" / "rig" / "kc"
    with pytest.raises(InputError, match="--bushing-set"):
        elastokin.diagnose("bench")
    with pytest.raises(InputError, match="not a bushing set"):
        elastokin.diagnose("kc", bushings="fig5_9")


def test_the_version_is_the_distributions(capsys) -> None:
    with pytest.raises(SystemExit):
        main(["--version"])
    assert capsys.readouterr().out.strip() == f"vsim (elastokin) {elastokin.__version__}"
    assert elastokin.__version__ not in ("", "unknown")


def test_the_five_lines_of_the_readme_run_from_an_empty_folder(tmp_path: Path) -> None:
    """The README's Python, from an empty folder in a fresh process: a built-in scenario played, a
    signal read, its metrics and a figure, a recording saved, a shipped dataset diagnosed."""
    readme = (ROOT / "README.md").read_text()
    code = readme.split("```python\n", 1)[1].split("```", 1)[0]
    assert len(code.strip().splitlines()) <= 8, code
    code = code.replace('Simulation("c_segment", "pumping")', f'Simulation("c_segment", "pumping", duration_scale={QUICK})')
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert load_run(tmp_path / "pumping.mcap").complete
    assert "rad" in done.stdout and "bump_camber_deg_per_m" not in done.stderr


def test_a_compile_is_said_once_with_its_time() -> None:
    """A kernel numba compiles is said on the stream with its time, a callee compiled into it not
    again, and nothing when it is compiled already."""
    stream = io.StringIO()

    @numba.njit
    def inner(x):
        return x + 1.0

    @numba.njit
    def outer(x):
        return inner(x) * 2.0

    with compile_notice(stream) as notice:
        assert outer(1.0) == 4.0
        assert outer(2.0) == 6.0
    lines = stream.getvalue().splitlines()
    assert lines[0].startswith("compiling the kernels for this machine") and len(lines) == 2, lines
    assert re.fullmatch(r"  compiled tests\.test_api\..*outer in \d+\.\d s", lines[1]) and notice.count == 1


def test_after_vsim_compile_a_first_run_compiles_nothing(tmp_path: Path) -> None:
    """`vsim compile` leaves every kernel a rig run and a road run need in numba's cache: a fresh
    process playing them compiles nothing (and so says nothing of it)."""
    count, wall_s = compile_kernels()
    assert count >= 0 and wall_s > 0
    for scenario, scale in (("pumping", "0.02"), ("road/step_steer", "0.05")):
        done = subprocess.run([sys.executable, "-m", "elastokin", "run", scenario, "--duration-scale", scale,
                               "-o", str(tmp_path / "run.mcap"), "--overwrite"], cwd=tmp_path, capture_output=True,
                              text=True, timeout=600)
        assert done.returncode == 0, done.stderr[-2000:]
        assert "compiling the kernels" not in done.stderr and "  compiled " not in done.stderr, done.stderr[-2000:]


def test_a_run_as_a_pandas_frame_is_its_signals_in_si(pumping: elastokin.Run) -> None:
    frame = pumping.to_pandas()
    assert list(frame.columns) == pumping.names and frame.index.name == "t_s"
    assert np.array_equal(frame.index.to_numpy(), pumping.t_s)
    assert np.array_equal(frame["toe_fl"].to_numpy(), pumping["toe_fl"]) and frame.attrs["units"]["toe_fl"] == "rad"


def test_the_kc_metrics_of_a_vehicle_are_those_of_vsim_kc(monkeypatch) -> None:
    """``Vehicle.kc_metrics`` builds the car as its file says, or with one model on every bushing,
    and refuses a model it does not know."""
    built = []
    monkeypatch.setattr(vehicles, "vehicle_kc", lambda vehicle, options: built.append((vehicle, options)) or {})
    car = elastokin.load_vehicle()
    car.kc_metrics()
    car.kc_metrics("stvs")
    assert [b[0] for b in built] == [car.definition] * 2
    assert [b[1].bushing_model for b in built] == [None, "stvs"]
    with pytest.raises(InputError, match="bushings.*linear, sts, rt, stvs"):
        car.kc_metrics("magic")


def test_a_rig_recordings_roll_metrics_take_the_measured_car(tmp_path: Path) -> None:
    """A measured roll recording carries no vehicle: its roll metrics need the car's tyre radius,
    given as the vehicle, and then are those of the run's own base."""
    run = elastokin.load_run(ROOT / "data" / "rig" / "kc" / "02_kc_roll.mcap")
    with pytest.raises(InputError, match=r"give the vehicle \(Run.metrics\(vehicle=...\)\)"):
        run.metrics()
    metrics = run.metrics(elastokin.load_vehicle())
    assert {"roll_steer_deg_per_deg", "roll_camber_deg_per_deg"} <= set(metrics[1]["front"])
    assert "roll_camber_deg_per_deg" in run.summary(elastokin.load_vehicle())


def test_the_front_doors_objects_say_briefly_what_they_are(pumping: elastokin.Run) -> None:
    car = elastokin.load_vehicle()
    assert repr(car) == f"<Vehicle 'c_segment' from {car.path}>" and len(repr(car)) < 200
    assert repr(car.with_values({"front.spring.rate": 30000.0})).endswith(", changed in code>")
    assert repr(pumping).startswith("<Run pumping (pumping): 6 case(s)")


def test_the_list_commands_kinds_are_the_apis() -> None:
    """`vsim list KIND` offers every kind the API lists (the command line keeps its own copy to load nothing)."""
    from elastokin.api.built_ins import KINDS
    from elastokin.cli.main import build_parser

    listing = build_parser()._subparsers._group_actions[0].choices["list"]
    assert list(next(a for a in listing._actions if a.dest == "kind").choices) == [k.name for k in KINDS]
