"""Sweeps (issue 27): the same table serially, on a local Dask cluster and on a scheduler with
workers started as separate processes; a killed worker costs only its tasks; a diverged run is a
row with its reason; Ctrl-C leaves a valid table that --resume completes to the same bits; a
parameter set at its place gives the run of the vehicle file edited by hand; Sobol' indices of the
Ishigami function; bad sweep files refused before any run."""

from __future__ import annotations

import csv
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from distributed import KilledWorker

import elastokin

from elastokin.vehicle.model.file_overrides import PlaceError, file_value, vehicle_with
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.analysis.run_metrics import run_metrics
from elastokin.cli.main import main
from elastokin.cluster.executor import WORKERS_DIED, ClusterLost, Outcome, SerialExecutor, executor, reason
from elastokin.core.documents import Document
from elastokin.core.errors import InputError
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.recordings.recorder import simulate
from elastokin.sweeps.designs import Design, design_points, unit_points
from elastokin.sweeps.sensitivity import sobol_indices
from elastokin.sweeps.sweep import run_sweep
from elastokin.sweeps.sweep_file import load_sweep

#: A short pumping of the front axle: one 30 mm triangle (a few tenths of a second of wall time).
SCENARIO = """name: short_pumping
type: pumping
vehicle: {vehicle}
axles: [front]
output_rate_hz: 50
settle: {{before_bushings_s: 0.5, before_input_s: 0.5}}
{limits}
cases:
  - {{amplitude_mm: 30, shape: triangle, frequency_hz: 0.1, cycles: 1}}
"""


def _sweep(tmp: Path, body: str, limits: str = "") -> Path:
    (tmp / "short_pumping.yaml").write_text(SCENARIO.format(vehicle=DEFAULT_VEHICLE, limits=limits))
    path = tmp / "sweep.yaml"
    path.write_text(f"name: test\nscenarios: [short_pumping.yaml]\nduration_scale: 0.2\n{body}")
    return path


LHS = """parameters:
  front.spring.rate: {min_factor: 0.8, max_factor: 1.2}
  bushings.e2_front.y.Kr: {min: 2000, max: 4000}
design: {type: latin_hypercube, runs: 3, seed: 7}
metrics: [front.toe_loop_width_deg, front.bump_camber_deg_per_m]
"""


def _table(folder: Path) -> str:
    return (folder / "sweep.csv").read_text()


def _rows(folder: Path) -> list[list[str]]:
    return list(csv.reader(_table(folder).splitlines()))[1:]


@pytest.fixture(scope="module")
def serial_table(tmp_path_factory) -> tuple[Path, Path]:
    tmp = tmp_path_factory.mktemp("serial")
    sweep = _sweep(tmp, LHS)
    run_sweep(load_sweep(sweep), tmp / "out", SerialExecutor())
    return sweep, tmp / "out"


def test_a_place_set_by_the_sweep_is_the_vehicle_file_edited_by_hand(serial_table):
    sweep_path, out = serial_table
    sweep = load_sweep(sweep_path)
    rows = _rows(out)
    assert len(rows) == 3 and all(r[-1] == "" for r in rows)
    row = rows[1]
    rate, kr = float(row[1]), float(row[2])
    assert 0.8 * 28000 <= rate <= 1.2 * 28000 and 2000 <= kr <= 4000
    # the same car written by hand: the front spring rate and the E2 front y law inline
    text = DEFAULT_VEHICLE.read_text()
    text = text.replace("rate: 28000.0 ", f"rate: {rate!r} ", 1)
    text = text.replace("y:  {set: fig5_9_caption}", "y:  {model: stvs, params: {N: 15, K0: 508.2, Kpa: 1076.7, "
                                             f"Kr: {kr!r}, Ff: 9.0, Co: 32.0, pw: 0.15}}}}", 1)
    hand = tmp_vehicle = out.parent / "hand.yaml"
    tmp_vehicle.write_text(text)
    run = simulate(load_scenario(sweep.scenarios[0].path), load_vehicle(hand), duration_scale=0.2)
    metrics = run_metrics(run)[1]["front"]
    header = _table(out).splitlines()[0].split(",")
    for name in ("toe_loop_width_deg", "bump_camber_deg_per_m"):
        assert float(row[header.index(f"short_pumping.c1.front.{name}")]) == metrics[name]
    # the sweep's lower and upper runs differ: the parameters reach the car
    widths = [float(r[header.index("short_pumping.c1.front.bump_camber_deg_per_m")]) for r in rows]
    assert len(set(widths)) == 3
    inputs = json.loads((out / "sweep.json").read_text())
    files = {Path(f["path"]).name: f["text"] for f in inputs["files"]}
    assert files["sweep.yaml"] == sweep_path.read_text() and inputs["software_version"]
    # every file the runs read: the vehicle, its bushing sets and its tyre
    assert {"c_segment.yaml", "short_pumping.yaml", "fig5_9_caption.yaml", "195_65R15.tir"} <= set(files)


def test_serial_local_cluster_and_external_scheduler_give_the_same_bits(serial_table, tmp_path):
    sweep_path, serial = serial_table
    with executor("local", 2) as ex:
        run_sweep(load_sweep(sweep_path), tmp_path / "local", ex)
    assert _table(tmp_path / "local") == _table(serial)
    with _external_cluster(tmp_path) as (address, _):
        assert main(["sweep", str(sweep_path), "-o", str(tmp_path / "external"), "--scheduler", address]) == 0
    assert _table(tmp_path / "external") == _table(serial)
    assert len(list((tmp_path / "external" / "plots").glob("*.png"))) == 2   # a PNG per metric column


class _external_cluster:
    """A scheduler and two single-threaded workers started as separate processes (``dask`` commands)."""

    last: "_external_cluster"

    def __init__(self, tmp: Path):
        self.file = tmp / "scheduler.json"
        self.procs: list[subprocess.Popen] = []
        _external_cluster.last = self

    def __enter__(self) -> tuple[str, object]:
        dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
        self.procs.append(subprocess.Popen([*dask, "--scheduler-file", str(self.file), "--port", "0",
                                            "--dashboard-address", ":0"], stderr=subprocess.DEVNULL))
        deadline = time.monotonic() + 60
        while not self.file.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        self.procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file",
                                            str(self.file), "--nworkers", "2", "--nthreads", "1"],
                                           stderr=subprocess.DEVNULL))
        from distributed import Client
        self.client = Client(scheduler_file=str(self.file), timeout="60s")
        self.client.wait_for_workers(2, timeout=60)
        return json.loads(self.file.read_text())["address"], self.client

    def __exit__(self, *exc) -> None:
        self.client.close(timeout=10)
        for p in reversed(self.procs):
            p.terminate()
            p.wait(timeout=30)


def test_a_killed_worker_costs_only_its_tasks(serial_table, tmp_path):
    sweep_path, serial = serial_table
    with _external_cluster(tmp_path) as (address, client):
        pids = list(client.run(os.getpid).values())
        killed = []

        def kill_one(progress) -> None:
            if not killed:   # a run finished: the other worker is in the middle of one
                os.kill(pids[0], signal.SIGKILL)
                killed.append(pids[0])

        with executor(address) as ex:
            report = run_sweep(load_sweep(sweep_path), tmp_path / "out", ex, progress=kill_one)
        assert killed and report.failed == 0
    assert _table(tmp_path / "out") == _table(serial)


def test_a_lost_scheduler_leaves_the_finished_rows_for_resume(serial_table, tmp_path):
    sweep_path, serial = serial_table
    with _external_cluster(tmp_path) as (address, _):
        scheduler = _external_cluster.last.procs[0]

        def kill_scheduler(progress) -> None:
            if scheduler.poll() is None:
                scheduler.kill()

        with pytest.raises(ClusterLost), executor(address) as ex:
            run_sweep(load_sweep(sweep_path), tmp_path / "out", ex, progress=kill_scheduler)
    rows = _rows(tmp_path / "out")
    assert 1 <= len(rows) < 3 and all(r[-1] == "" for r in rows)    # finished runs only, none "failed"
    run_sweep(load_sweep(sweep_path), tmp_path / "out", SerialExecutor(), resume=True)
    assert _table(tmp_path / "out") == _table(serial)


class _WorkersDieUnderTheSecondRun(SerialExecutor):
    """This process's runs, but the second ends as Dask ends a task whose workers kept dying."""

    def each(self, fn, items):
        for outcome in super().each(fn, items):
            died = KilledWorker("run_point-2", SimpleNamespace(address="tcp://10.0.0.2:40000"), 3)
            yield Outcome(outcome.index, error=reason(died)) if outcome.index == 1 else outcome


def test_resume_makes_again_a_run_whose_workers_died(serial_table, tmp_path):
    """A run lost with its workers is a failed row naming it, which --resume makes again; a run's
    own failure (test_a_diverged_run_is_a_row_with_its_reason) is kept."""
    sweep_path, serial = serial_table
    report = run_sweep(load_sweep(sweep_path), tmp_path / "out", _WorkersDieUnderTheSecondRun())
    rows = _rows(tmp_path / "out")
    assert report.failed == 1 and rows[1][-1].startswith(WORKERS_DIED) and rows[1][-2] == "nan"
    resumed = run_sweep(load_sweep(sweep_path), tmp_path / "out", SerialExecutor(), resume=True)
    assert resumed.computed == 1 and resumed.failed == 0
    assert _table(tmp_path / "out") == _table(serial)


def test_a_diverged_run_is_a_row_with_its_reason(tmp_path):
    # a stiffer front spring loads the wishbone bushings beyond the scenario's 0.9 mm limit (0.63 mm at 28 kN/m, 1.18 at 150)
    sweep = _sweep(tmp_path, """parameters:
  front.spring.rate: {min: 28000, max: 150000}
design: {type: grid, levels: 2}
metrics: [front.toe_loop_width_deg]
""", limits="limits: {translation_mm: 0.9}")
    report = run_sweep(load_sweep(sweep), tmp_path / "out", SerialExecutor())
    rows = _rows(tmp_path / "out")
    assert report.failed == 1 and rows[0][-1] == ""
    assert "DivergenceError" in rows[1][-1] and "deflection" in rows[1][-1] and rows[1][2] == "nan"


def test_a_folder_another_sweep_is_writing_is_refused(serial_table, tmp_path):
    """A second session on the folder a first one is writing (here: its lock held) stops before
    touching anything; once the first is gone the folder is free."""
    import subprocess
    import sys

    from elastokin.core.files import LOCK_NAME

    sweep, _ = serial_table
    folder = tmp_path / "out"
    folder.mkdir()
    holder = subprocess.Popen([sys.executable, "-c", "import fcntl, sys, time; f = open(sys.argv[1], 'a'); "
                               "fcntl.flock(f, fcntl.LOCK_EX); print('held', flush=True); time.sleep(60)",
                               str(folder / LOCK_NAME)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(InputError, match="another vsim sweep is writing this folder"):
            run_sweep(load_sweep(sweep), folder, SerialExecutor())
        assert sorted(p.name for p in folder.iterdir()) == [LOCK_NAME]   # nothing written
    finally:
        holder.kill()
        holder.wait()
    assert run_sweep(load_sweep(sweep), folder, SerialExecutor()).failed == 0


def test_interrupted_sweep_leaves_a_valid_table_that_resume_completes(tmp_path):
    sweep = _sweep(tmp_path, LHS.replace("runs: 3", "runs: 4"))
    whole = tmp_path / "whole"
    run_sweep(load_sweep(sweep), whole, SerialExecutor())

    def stop_after_two(progress) -> None:
        if progress.done == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(load_sweep(sweep), tmp_path / "cut", SerialExecutor(), progress=stop_after_two)
    assert [r[0] for r in _rows(tmp_path / "cut")] == ["1", "2"]
    with pytest.raises(InputError, match="--resume"):
        run_sweep(load_sweep(sweep), tmp_path / "cut", SerialExecutor())
    report = run_sweep(load_sweep(sweep), tmp_path / "cut", SerialExecutor(), resume=True)
    assert report.computed == 2 and report.finished == 4
    assert _table(tmp_path / "cut") == _table(whole)
    # a changed sweep file is not resumed into the old table
    sweep.write_text(sweep.read_text().replace("seed: 7", "seed: 8"))
    with pytest.raises(InputError, match="not made from the same"):
        run_sweep(load_sweep(sweep), tmp_path / "cut", SerialExecutor(), resume=True)


def test_a_sobol_design_runs_its_matrices_and_writes_the_indices(tmp_path):
    sweep = _sweep(tmp_path, """parameters:
  front.spring.rate: {min_factor: 0.8, max_factor: 1.2}
design: {type: sobol, base_runs: 2, seed: 4}
metrics: [front.bump_camber_deg_per_m]
""")
    report = run_sweep(load_sweep(sweep), tmp_path / "out", SerialExecutor())
    rows = _rows(tmp_path / "out")
    assert report.runs == 2 * (1 + 2) and len(rows) == 6
    # one parameter: A_B^1 is B, point for point, and its runs give B's bits
    assert [r[1:] for r in rows[4:6]] == [r[1:] for r in rows[2:4]]
    indices = list(csv.reader((tmp_path / "out" / "sensitivity.csv").read_text().splitlines()))
    assert indices[0] == ["metric", "parameter", "first_order", "total", "samples"]
    assert [r[:2] for r in indices[1:]] == [["short_pumping.c1.front.bump_camber_deg_per_m", "front.spring.rate"]]
    assert indices[1][4] == "2" and all(math.isfinite(float(v)) for v in indices[1][2:4])


def test_sobol_indices_of_the_ishigami_function():
    a, b = 7.0, 0.1
    v1 = 0.5 * (1 + b * math.pi ** 4 / 5) ** 2
    v2 = a ** 2 / 8
    v13 = b ** 2 * math.pi ** 8 * (1 / 18 - 1 / 50)
    v = v1 + v2 + v13
    first, total = np.array([v1, v2, 0.0]) / v, np.array([v1 + v13, v2, v13]) / v
    x = -math.pi + 2 * math.pi * unit_points(Design("sobol", base_runs=8192, seed=3), 3)
    y = np.sin(x[:, 0]) + a * np.sin(x[:, 1]) ** 2 + b * x[:, 2] ** 4 * np.sin(x[:, 0])
    s = sobol_indices(y, 3)
    assert np.allclose(s.first, first, atol=0.03) and np.allclose(s.total, total, atol=0.03)
    # a failed run drops its base sample from every index, not the estimate
    y[5] = np.nan
    assert sobol_indices(y, 3).samples == 8191


@pytest.mark.parametrize("change, key, message", [
    (("front.spring.rate:", "front.spring.rat:"), "parameters.front.spring.rat", "no value there to scale"),
    (("front.spring.rate: {min_factor: 0.8, max_factor: 1.2}", "front.spring.rat: {min: 25000, max: 30000}"),
     "parameters.front.spring.rat", "unknown key 'rat'"),
    (("bushings.e2_front.y.Kr:", "bushings.e2_frnt.y.Kr:"), "parameters.bushings.e2_frnt.y.Kr", "no bushing"),
    (("{min: 2000, max: 4000}", "{min: 4000, max: 2000}"), "parameters.bushings.e2_front.y.Kr", "min < max"),
    (("runs: 3", "runs: 0"), "design.runs", "at least 1"),
    (("front.toe_loop_width_deg", "front.toe_loop_width"), "metrics[0]", "no scenario of the sweep gives"),
    (("front.toe_loop_width_deg", "rear.toe_loop_width_deg"), "metrics[0]", "no scenario of the sweep gives"),
    (("latin_hypercube, runs: 3", "sobol, base_runs: 6"), "design.base_runs", "power of two"),
    (("{min: 2000, max: 4000}", "{min: -4000, max: 2000}"), "parameters.bushings.e2_front.y.Kr",
     "does not build with -4000.0"),
    (("bushings.e2_front.y.Kr:", "1:"), "parameters[1]", "expected a dotted place"),
    (("front.spring.rate:", "front.hardpoints.tie_rod_inner.²:"), "parameters.front.hardpoints.tie_rod_inner.²",
     "expected an index"),
    (("parameters:", "vehicle: c_segmnt\nparameters:"), "vehicle", "no such vehicle file"),
    (("metrics: [front.toe_loop_width_deg,", "metrics: [front.toe_loop_width_deg, front.toe_loop_width_deg,"),
     "metrics[1]", "twice"),
])
def test_bad_sweep_files_are_refused_before_any_run(tmp_path, change, key, message):
    sweep = _sweep(tmp_path, LHS.replace(*change))
    with pytest.raises(InputError, match=message) as err:
        load_sweep(sweep)
    assert err.value.source.startswith(str(sweep)) and err.value.key == key
    assert main(["sweep", str(sweep), "-o", str(tmp_path / "out")]) == 2 and not (tmp_path / "out").exists()


def test_a_bad_base_vehicle_or_scheduler_is_named_before_any_run(tmp_path):
    bad = tmp_path / "car.yaml"
    bad.write_text(DEFAULT_VEHICLE.read_text().replace("wheel_mass: 17.0", "wheel_mass: -17.0"))
    sweep = _sweep(tmp_path, f"vehicle: {bad}\n" + LHS)
    with pytest.raises(InputError, match="positive") as err:
        load_sweep(sweep)
    assert err.value.source.startswith(str(bad)) and err.value.key == "tyre.wheel_mass"
    good = _sweep(tmp_path, LHS)
    escaping = tmp_path / "escaping.yaml"
    escaping.write_text(good.read_text().replace("name: test", "name: ../elsewhere"))
    with pytest.raises(InputError, match="plain name") as err:
        load_sweep(escaping)
    assert err.value.key == "name"
    for address in ("http://127.0.0.1:8786", "tcp://127.0.0.1:notaport"):
        assert main(["sweep", str(good), "-o", str(tmp_path / "out"), "--scheduler", address]) == 2


def test_grid_points_on_the_bounds_are_the_bounds():
    points = design_points(Design("grid", levels=3), np.array([-0.3, 2.0]), np.array([0.1, 4.0]))
    assert points[:, 0].min() == -0.3 and points[:, 0].max() == 0.1 and points[:, 1].max() == 4.0


def test_places_of_the_vehicle_file():
    text = DEFAULT_VEHICLE.read_text()
    data = Document(text, str(DEFAULT_VEHICLE)).data
    assert file_value(data, "bushings.e2_front.y.Kr") == 2935.0          # from its set, fig5_9_caption
    assert file_value(data, "front.hardpoints.tie_rod_inner.z") == 0.19
    assert file_value(data, "rear.beam_torsion_scale") == 1.0
    for bad in ("name", "front.hardpoints.tie_rod_inner.w", "bushings.e2_front.y.Kq", "bushings.e1_rear"):
        with pytest.raises(PlaceError):
            file_value(data, bad)
    base = load_vehicle(DEFAULT_VEHICLE)
    same = vehicle_with(text, DEFAULT_VEHICLE, {"bushings.e2_front.y.Kr": 2935.0}, "test")
    changed = vehicle_with(text, DEFAULT_VEHICLE, {"bushings.e2_front.y.Kr": 3500.0,
                                                   "front.hardpoints.tie_rod_inner.z": 0.2}, "test")
    law = lambda v: {b.name: b for b in v.bushings}["e2_front"].directions["y"]
    # the set written inline is the same law; both sides share the one bushing entry
    assert law(same).channel() == law(base).channel() and law(same).effects_si() == law(base).effects_si()
    assert law(changed).channel().Kr == pytest.approx(3500.0e3)
    assert changed.front.hardpoints["tie_rod_inner"][2] == 0.2 and "3500.0" in changed.text
    # an optional key the file leaves out (the beam rigid in bending) is set where the file would write it
    assert "beam_bending_stiffness" not in text and base.rear.beam_bending_stiffness is None
    bent = vehicle_with(text, DEFAULT_VEHICLE, {"rear.beam_bending_stiffness": 5e4}, "test")
    assert bent.rear.beam_bending_stiffness == 5e4


def test_the_apis_sweep_is_the_commands(serial_table, tmp_path):
    """``elastokin.sweep`` makes the table ``run_sweep`` does, the same bits, and keeps its rows in
    the report."""
    sweep_path, folder = serial_table
    report = elastokin.sweep(sweep_path, tmp_path / "api", scheduler="serial")
    assert _table(tmp_path / "api") == _table(folder)
    assert report.finished == report.runs == 3 and len(report.table) == 3
