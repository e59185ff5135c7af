"""The scenario runner and `vsim run`: shortened default scenarios, recordings and their metadata,
switching the bushing laws on, divergence, Ctrl-C, refusal to overwrite, bit-identical reruns."""

from __future__ import annotations

import dataclasses
import textwrap
from pathlib import Path

import numpy as np
import pytest

from elastokin.vehicle.scenarios.channels import INPUT_CHANNELS
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.vehicle.simulation.runner import DivergenceError
from elastokin.cli import main as cli
from elastokin.core.errors import InputError
from elastokin.presentation.run_summary import summary
from elastokin.recordings.recorder import run_scenario, simulate
from elastokin.recordings.run_format import PARTIAL_SUFFIX
from elastokin.recordings.run_reader import load_run

SCENARIO_DIR = Path(__file__).resolve().parent.parent / "scenarios"
QUICK = 0.05   #: duration scale of the shortened default scenarios

SMALL = """\
type: pumping
vehicle: {vehicle}
settle: {{before_bushings_s: 0.2, before_input_s: 0.2}}
defaults: {{frequency_hz: 2, cycles: 2}}
cases:
  - amplitude_mm: 20
"""


def small_scenario(tmp_path: Path, text: str = SMALL, name: str = "small.yaml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text).format(vehicle=SCENARIO_DIR.parent / "models/vehicles/c_segment.yaml"))
    return path


@pytest.mark.parametrize("name, case", [
    ("pumping", -1), ("roll", -1), ("lateral_force", -1), ("pumping_speeds", -1), ("rack_step", 0),
    ("double_rack_step_same", 0), ("double_rack_step_opposite", 0),
])
def test_shortened_default_scenario_runs_and_records(tmp_path: Path, name: str, case: int) -> None:
    """One case of each default scenario, durations × 0.05: a complete, self-describing recording."""
    scenario = load_scenario(SCENARIO_DIR / f"{name}.yaml")
    scenario = dataclasses.replace(scenario, cases=scenario.cases[case:][:1])
    result = run_scenario(scenario, tmp_path / "run.mcap", duration_scale=QUICK)
    run = load_run(result.path)
    assert run.complete, run.reason
    phase = run.signals["phase"]
    assert set(np.unique(phase)) == {0.0, 1.0, 2.0} and np.all(np.diff(phase) >= 0)
    assert run.t_s[-1] == pytest.approx(result.simulated_s)
    assert run.metadata.scenario_yaml == scenario.path.read_text()
    assert run.metadata.vehicle_yaml == scenario.vehicle.read_text()
    assert run.metadata.software_version and run.metadata.git_revision
    assert len(run.metadata.bushing_parameters) == 36
    assert run.metadata.extra["duration_scale"] == QUICK
    # the input really went in: the recorded command (sampled at the output rate) nears the case's peak
    peak = np.abs(scenario.cases[0].inputs(np.linspace(0, scenario.cases[0].duration_s, 2001))).max(axis=0)
    driven = int(np.argmax(peak))
    unit_scale = 1e3 if INPUT_CHANNELS[driven].startswith(("pad_z", "rack")) else 1.0
    assert np.abs(run.signals[INPUT_CHANNELS[driven]]).max() == pytest.approx(peak[driven] * unit_scale, rel=0.05)
    for spec in run.specs:
        assert np.all(np.isfinite(run.signals[spec.name])), spec.name
    text = summary(run)
    assert "peak bushing deflections" in text and ("gradient = centre-line slope" in text or "toe over the final hold" in text)
    # the run kept in memory is the file's, bit for bit, and summarises the same (vsim run prints it)
    assert np.array_equal(result.run.t_s, run.t_s) and result.run.signals.keys() == run.signals.keys()
    assert all(np.array_equal(result.run.signals[k], v) for k, v in run.signals.items())
    assert summary(result.run) == text
    assert 0.0 < result.stepping_s < result.wall_s


def test_pumping_records_loops_against_wheel_travel(tmp_path: Path) -> None:
    run_scenario(load_scenario(small_scenario(tmp_path)), tmp_path / "run.mcap")
    run = load_run(tmp_path / "run.mcap")
    pairs = run.pairs()
    assert ("wheel_travel_fl", "camber_fl") in pairs and ("wheel_travel_rr", "half_track_rr") in pairs
    assert ("e1_front_left_y_deflection", "e1_front_left_y_force") in pairs
    assert run.units["camber_fl"] == "deg" and run.units["e1_front_left_rx_force"] == "N·m"
    inputs = run.signals["phase"] == 2
    travel = run.signals["wheel_travel_fl"][inputs]
    assert travel.max() == pytest.approx(20.0, abs=1.5) and travel.min() == pytest.approx(-20.0, abs=1.5)
    rows = [line.split() for line in summary(run).splitlines() if line.startswith("  amplitude_mm=20")]
    assert [r[1] for r in rows] == ["fl", "rl"]
    for row in rows:   # gradient, loop width (largest) for camber, toe and half-track
        values = [float(v.strip("()")) for v in row[2:]]
        assert len(values) == 9 and np.all(np.isfinite(values)) and values[2] > 0.0, row


def test_bushing_laws_are_linear_at_their_reference_stiffness_before_switching_on(tmp_path: Path) -> None:
    run_scenario(load_scenario(small_scenario(tmp_path)), tmp_path / "run.mcap")
    run = load_run(tmp_path / "run.mcap")
    params = run.metadata.bushing_parameters["e2_front_left.y"]
    assert params["model"] != "linear"
    k_ref = params["K0"] + params["Kpa"]   # N/m
    linear = np.flatnonzero(run.signals["phase"] == 0)[-1]
    e = run.signals["e2_front_left_y_deflection"] * 1e-3
    f = run.signals["e2_front_left_y_force"]
    assert abs(e[linear]) > 1e-5   # the car's weight deflects it
    assert f[linear] / e[linear] == pytest.approx(k_ref, rel=0.02)
    on = np.flatnonzero(run.signals["phase"] == 1)[-1]
    assert f[on] / e[on] < 0.98 * k_ref   # the law's secant, softer than its small-amplitude tangent


def test_same_inputs_give_bit_identical_signals(tmp_path: Path) -> None:
    scenario = load_scenario(small_scenario(tmp_path))
    runs = [load_run(run_scenario(scenario, tmp_path / f"run{i}.mcap").path) for i in range(2)]
    assert runs[0].t_s.tobytes() == runs[1].t_s.tobytes()
    assert runs[0].signals.keys() == runs[1].signals.keys()
    for name in runs[0].signals:
        assert runs[0].signals[name].tobytes() == runs[1].signals[name].tobytes(), name
    assert runs[0].body_pos.tobytes() == runs[1].body_pos.tobytes()
    assert runs[0].body_quat_wxyz.tobytes() == runs[1].body_quat_wxyz.tobytes()
    assert runs[0].metadata == runs[1].metadata


@pytest.mark.parametrize("name", ["pumping", "lateral_force", "pumping_speeds"])
def test_a_case_on_the_first_cases_settled_car_is_the_same_bits_as_played_alone(name: str) -> None:
    """Every case of a scenario settles the same car the same way; each after the first restores
    the first's settled state (MuJoCo's, the bushing bank's and its effects', the tangents the model
    holds: runner.Settled) instead of stepping it again: the last case's samples, every signal but
    the case's number and the bodies' poses, are the same bits as that case played alone, its own
    settling stepped (pumping_speeds: every bushing STVS); a restore without MuJoCo's state or the
    bank's moves its input phase."""
    scenario = load_scenario(SCENARIO_DIR / f"{name}.yaml")
    whole = simulate(scenario, duration_scale=QUICK, poses=True)
    alone = simulate(dataclasses.replace(scenario, cases=scenario.cases[-1:]), duration_scale=QUICK, poses=True)
    rows = whole.signals["case"] == len(scenario.cases)
    assert len(scenario.cases) > 1 and rows.sum() == len(alone.t_s)
    for signal, values in alone.signals.items():
        if signal != "case":
            assert whole.signals[signal][rows].tobytes() == values.tobytes(), signal
    assert whole.body_pos[rows].tobytes() == alone.body_pos.tobytes()
    assert whole.body_quat_wxyz[rows].tobytes() == alone.body_quat_wxyz.tobytes()


def test_divergence_stops_with_a_clear_error_and_a_readable_incomplete_file(tmp_path: Path) -> None:
    path = small_scenario(tmp_path, """\
        type: lateral_force
        vehicle: {vehicle}
        settle: {{before_bushings_s: 0.1, before_input_s: 0.1}}
        cases:
          - {{amplitude_daN: 100000, frequency_hz: 1}}
    """)
    out = tmp_path / "blow.mcap"
    with pytest.raises(DivergenceError) as err:
        run_scenario(load_scenario(path), out)
    message = str(err.value)
    assert message.startswith("diverged at t = ") and "case 1 'amplitude_daN=100000, frequency_hz=1'" in message
    assert "bushing " in message and "direction " in message and " mm beyond the limit 20 mm" in message
    run = load_run(out)
    assert not run.complete and run.reason.startswith("DivergenceError: diverged at t = ")
    assert run.t_s[-1] == pytest.approx(err.value.time_s) and run.t_s.size > 10
    assert not out.with_name(out.name + PARTIAL_SUFFIX).exists()
    assert "INCOMPLETE" in summary(run)


def test_interrupted_run_leaves_a_readable_incomplete_file(tmp_path: Path) -> None:
    out = tmp_path / "stopped.mcap"
    calls = []

    def progress(p) -> None:
        calls.append(p)
        if len(calls) == 3:   # after the third block of samples
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_scenario(load_scenario(small_scenario(tmp_path)), out, progress=progress)
    run = load_run(out)
    assert not run.complete and run.reason == "KeyboardInterrupt"
    assert run.t_s.size > 3 and calls[-1].done_s == pytest.approx(run.t_s[-1])   # every sample reported is kept
    assert not out.with_name(out.name + PARTIAL_SUFFIX).exists()


def test_existing_output_is_not_overwritten_without_overwrite(tmp_path: Path) -> None:
    out = tmp_path / "run.mcap"
    out.write_bytes(b"precious")
    scenario = load_scenario(small_scenario(tmp_path))
    with pytest.raises(InputError, match="--overwrite"):
        run_scenario(scenario, out)
    assert out.read_bytes() == b"precious"
    run_scenario(scenario, out, overwrite=True)
    assert load_run(out).complete


def test_vsim_run_command(tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    scenario = small_scenario(tmp_path)
    assert cli.main(["run", str(scenario), "--duration-scale", "0.5"]) == 0
    out = capsys.readouterr()
    default = tmp_path / "out" / "small.mcap"
    assert default.is_file() and "gradient = centre-line slope" in out.out and "wrote out/small.mcap" in out.out
    assert "case 1/1" in out.err   # progress lines (not a terminal here)
    before = default.read_bytes()
    assert cli.main(["run", str(scenario)]) == 2
    assert "--overwrite" in capsys.readouterr().err and default.read_bytes() == before
    assert cli.main(["run", str(scenario), "-o", "other.mcap", "--bushing-model", "linear", "--duration-scale", "0.5"]) == 0
    run = load_run(tmp_path / "other.mcap")
    assert run.metadata.extra["bushing_model"] == "linear"
    assert all(p["model"] == "linear" for p in run.metadata.bushing_parameters.values())


@pytest.mark.parametrize("limit, words", [
    ("translation_mm: 0.05", ["bushing ", "direction ", "mm beyond the limit 0.05 mm"]),
    ("rotation_deg: 0.01", ["bushing ", "direction r", "deg beyond the limit 0.01 deg"]),
    ("closure_error_mm: 0.000001", ["loop-closure error", "mm beyond the limit 1e-06 mm"]),
])
def test_vsim_run_reports_divergence_with_status_1(tmp_path: Path, capsys: pytest.CaptureFixture[str], limit: str,
                                                   words: list[str]) -> None:
    path = small_scenario(tmp_path, SMALL + f"limits: {{{{{limit}}}}}\n")
    assert cli.main(["run", str(path), "-o", str(tmp_path / "d.mcap")]) == 1
    err = capsys.readouterr().err
    assert "vsim: run stopped: diverged at t = " in err and "incomplete recording is kept in" in err
    for word in words:
        assert word in err, err
    assert not load_run(tmp_path / "d.mcap").complete


def test_csv_and_bisine_inputs_reach_the_rig(tmp_path: Path) -> None:
    (tmp_path / "in.csv").write_text("t_s,pad_z_fl_mm,rack_mm\n0,0,0\n0.2,5,0\n0.4,5,-2\n")
    csv_run = small_scenario(tmp_path, """\
        type: csv
        vehicle: {vehicle}
        settle: {{before_bushings_s: 0.1, before_input_s: 0.1}}
        cases: [{{path: in.csv}}]
    """, "csv.yaml")
    run = load_run(run_scenario(load_scenario(csv_run), tmp_path / "csv.mcap").path)
    end = -1
    assert run.signals["pad_z_fl"][end] == pytest.approx(5.0) and run.signals["rack"][end] == pytest.approx(-2.0)
    assert run.signals["pad_height_fl"][end] == pytest.approx(5.0, abs=0.1)
    assert abs(run.signals["steer_fl"][end]) > 0.3 and run.signals["pad_z_fr"][end] == 0.0
    bisine = small_scenario(tmp_path, """\
        type: bisine
        vehicle: {vehicle}
        axles: [rear]
        settle: {{before_bushings_s: 0.1, before_input_s: 0.1}}
        cases:
          - {{input: roll, duration_s: 0.5, components: [{{amplitude_mm: 4, frequency_hz: 1}}, {{amplitude_mm: 1, frequency_hz: 10}}]}}
    """, "bisine.yaml")
    run = load_run(run_scenario(load_scenario(bisine), tmp_path / "bisine.mcap").path)
    inputs = run.signals["phase"] == 2
    expected = 4 * np.sin(2 * np.pi * run.signals["input_time"][inputs]) + np.sin(20 * np.pi * run.signals["input_time"][inputs])
    np.testing.assert_allclose(run.signals["pad_z_rl"][inputs], expected, atol=1e-9)
    np.testing.assert_allclose(run.signals["pad_z_rr"][inputs], -expected, atol=1e-9)
    assert ("wheel_travel_rl", "toe_rl") in run.pairs()
