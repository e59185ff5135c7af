"""`vsim compare` (elastokin/analysis/compare.py) and the metric functions it shares (elastokin/analysis/run_metrics.py):
exact metrics on synthetic signals, a run against itself, against a copy with scaled camber and
against a resampled bodiless copy written as a file, the CLI's outputs, and every input error."""

from __future__ import annotations

import dataclasses
import json
import math
import textwrap
from pathlib import Path

import numpy as np
import pytest

from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.analysis.compare import compare_runs
from elastokin.analysis.loops import dynamic_stiffness, loop_area, relaxation_amplitude, rms_error
from elastokin.cli import main as cli
from elastokin.core.errors import InputError
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.presentation.comparison_report import format_table
from elastokin.recordings.recorder import run_scenario
from elastokin.recordings.run_format import Run
from elastokin.recordings.run_reader import load_run
from elastokin.recordings.run_writer import RunWriter

#: Two pumping cases at 2 Hz, a triangle and a sine (which has a dynamic stiffness).
PUMPING = """\
type: pumping
vehicle: {vehicle}
settle: {{before_bushings_s: 0.2, before_input_s: 0.2}}
defaults: {{amplitude_mm: 20, frequency_hz: 2, cycles: 2}}
cases:
  - {{shape: triangle}}
  - {{shape: sine}}
"""
RACK_STEP = """\
type: rack_step
vehicle: {vehicle}
bushings: stvs
settle: {{before_bushings_s: 0.2, before_input_s: 0.2}}
cases: [{{rack_mm: 5, hold_s: 0.6}}]
"""


def _run(folder: Path, text: str) -> Path:
    scenario = folder / "scenario.yaml"
    scenario.write_text(textwrap.dedent(text).format(vehicle=DEFAULT_VEHICLE))
    return run_scenario(load_scenario(scenario), folder / "sim.mcap").path


@pytest.fixture(scope="module")
def pumping(tmp_path_factory: pytest.TempPathFactory) -> Run:
    return load_run(_run(tmp_path_factory.mktemp("pumping"), PUMPING))


@pytest.fixture(scope="module")
def rack_step(tmp_path_factory: pytest.TempPathFactory) -> Run:
    return load_run(_run(tmp_path_factory.mktemp("rack"), RACK_STEP))


def with_signals(run: Run, **changes: np.ndarray | None) -> Run:
    """A copy of ``run`` with signals replaced (or removed, for None), as if from another file."""
    signals = {k: v for k, v in {**run.signals, **changes}.items() if v is not None}
    return dataclasses.replace(run, path=run.path.with_name("rig.mcap"), signals=signals)


def with_extra(run: Run, **changes) -> Run:
    metadata = dataclasses.replace(run.metadata, extra={**run.metadata.extra, **changes})
    return dataclasses.replace(run, path=run.path.with_name("rig.mcap"), metadata=metadata)


# -- metric functions on synthetic signals ---------------------------------------------------------
def test_loop_area_of_an_ellipse_is_pi_a_b() -> None:
    a, b = 12.0, 0.3
    angle = np.linspace(0.0, 2 * np.pi, 60, endpoint=False)
    clockwise = loop_area(a * np.cos(angle), -b * np.sin(angle))
    assert clockwise == pytest.approx(math.pi * a * b, rel=0.01)
    assert loop_area(a * np.cos(angle), b * np.sin(angle)) == pytest.approx(-clockwise)


def test_dynamic_stiffness_of_a_spring_damper_is_k_plus_i_omega_c() -> None:
    k, c, frequency, amplitude = 2.0e5, 800.0, 3.0, 1.5   # N/mm, N·s/mm, Hz, mm
    w = 2 * np.pi * frequency
    t = np.arange(0.0, 2.0 / frequency, 1.0 / 250.0)      # 83.3 samples per period: not a whole number
    x = 0.2 + amplitude * np.sin(w * t)                    # with an offset (the first harmonic ignores it)
    force = k * (x - 0.2) + c * amplitude * w * np.cos(w * t)
    stiffness = dynamic_stiffness(t, force, x, frequency)
    assert abs(stiffness) == pytest.approx(abs(k + 1j * w * c), rel=0.005)
    assert stiffness.imag / stiffness.real == pytest.approx(w * c / k, rel=0.005)
    with pytest.raises(ValueError, match="one period"):
        dynamic_stiffness(t[:50], force[:50], x[:50], frequency)


def test_relaxation_and_rms() -> None:
    t = np.linspace(0.0, 3.0, 301)
    y = np.where(t < 1.0, 0.0, 2.0 + 0.5 * np.exp(-(t - 1.0)))
    assert relaxation_amplitude(t, y, 1.0) == pytest.approx(0.5 * (np.exp(-2.0) - 1.0))
    assert rms_error(y + 0.25, y) == pytest.approx(0.25)


# -- comparisons -----------------------------------------------------------------------------------
def test_a_run_compared_with_itself_differs_by_nothing(pumping: Run) -> None:
    result = compare_runs(pumping, pumping)
    assert [c.label for c in result.cases] == ["shape=triangle", "shape=sine"]
    triangle, sine = result.cases
    for case in result.cases:
        for ch in case.channels:
            assert ch.rms_error == 0.0 and all(m.diff == 0.0 for m in ch.metrics.values()), ch
    camber = {ch.channel: ch for ch in triangle.channels}["camber_fl"]
    assert set(camber.metrics) == {"gradient", "loop_width", "loop_area"}
    assert camber.metrics["gradient"].unit == "deg/m" and camber.metrics["gradient"].sim < -5.0  # McPherson
    assert triangle.not_applicable == {"relaxation": "no final hold", "dynamic_stiffness": "not a sine input"}
    # the sine's |K*|: the pad's vertical force over its height, the wheel rate (29 N/mm at 0.2 Hz)
    # and the dampers in quadrature: 36.9, 36.8, 36.7 N/mm at h = 2, 1, 0.5 ms (it was 41, 34, 26
    # while the pad force was read from a forward pass with the step's target held)
    pad = {ch.channel: ch for ch in sine.channels}["pad_fz_fl"]
    assert pad.metrics["dynamic_stiffness"].unit == "N/mm"
    assert 15.0 < pad.metrics["dynamic_stiffness"].sim < 40.0
    assert "dynamic_stiffness" in sine.not_applicable and "only on pad_fz" in sine.not_applicable["dynamic_stiffness"]


def test_scaled_camber_scales_its_gradient_and_nothing_else(pumping: Run) -> None:
    factor = 1.1
    rig = with_signals(pumping, **{n: factor * v for n, v in pumping.signals.items() if n.startswith("camber_")})
    for case in compare_runs(pumping, rig).cases:
        for ch in case.channels:
            gradient = ch.metrics["gradient"]
            if ch.channel.startswith("camber_"):
                assert gradient.rig / gradient.sim == pytest.approx(factor, rel=1e-9)
                assert gradient.diff == pytest.approx((1 - factor) * gradient.sim, rel=1e-9)
                assert ch.metrics["loop_width"].rig == pytest.approx(factor * ch.metrics["loop_width"].sim, rel=1e-9)
                assert ch.rms_error > 0.0
            else:
                assert gradient.diff == 0.0 and ch.rms_error == 0.0


def test_rack_step_compares_relaxation_over_the_hold(rack_step: Run) -> None:
    case = compare_runs(rack_step, rack_step).cases[0]
    assert case.not_applicable["gradient"] == "a time-only input, no x quantity"
    toe = {ch.channel: ch for ch in case.channels}["toe_fl"]
    assert set(toe.metrics) == {"relaxation"} and toe.metrics["relaxation"].unit == "deg"
    assert abs(toe.metrics["relaxation"].sim) > 1e-5 and toe.metrics["relaxation"].diff == 0.0   # STVS relaxes
    assert "relaxation over the hold [deg]" in format_table(compare_runs(rack_step, rack_step))


def write_resampled(run: Run, path: Path, rate_hz: float, offset_s: float) -> Path:
    """``run`` as a rig would record it: source ``rig`` and no model, no bodies, no bushing, spring or damper channels, sampled
    at ``rate_hz`` from ``offset_s``, between samples of the same case and phase (the runner's
    cases follow each other without a transition); signals interpolated, the schedule's steps held."""
    t = np.arange(offset_s, run.t_s[-1], 1.0 / rate_hz)
    previous = np.searchsorted(run.t_s, t, side="right") - 1
    same = (run.signals["case"][previous] == run.signals["case"][previous + 1]) & (
        run.signals["phase"][previous] == run.signals["phase"][previous + 1])
    t, previous = t[same], previous[same]
    specs = [s for s in run.specs if not s.group.startswith(("bushing_", "springs", "dampers"))]
    values = np.column_stack([run.signals[s.name][previous] if s.name in ("case", "phase")
                              else np.interp(t, run.t_s, run.signals[s.name]) for s in specs])
    measured = dataclasses.replace(run.metadata, source="rig", vehicle_yaml="", bushing_parameters={})
    with RunWriter(path, signals=specs, bodies=[], geometry=[], metadata=measured) as writer:
        for time_s, row in zip(t, values):
            writer.write(time_s, row, np.empty((0, 3)), np.empty((0, 4)))
    return path


def test_vsim_compare_with_a_resampled_rig_file_writes_json_and_pngs(pumping: Run, tmp_path: Path, capsys) -> None:
    rig = write_resampled(pumping, tmp_path / "rig.mcap", rate_hz=40.0, offset_s=0.0037)
    out = tmp_path / "cmp"
    assert cli.main(["compare", str(pumping.path), str(rig), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "gradient [deg/m]" in text and "loop width at design [deg]" in text and "RMS [deg]" in text
    assert "|K*| first harmonic [N/mm]" in text and "n/a: relaxation (no final hold)" in text
    assert sorted(p.name for p in out.iterdir()) == ["comparison.json", "loops_case1.png", "loops_case2.png",
                                                     "time_case1.png", "time_case2.png"]
    assert all(p.read_bytes().startswith(b"\x89PNG") for p in out.glob("*.png"))
    data = json.loads((out / "comparison.json").read_text())
    assert data["difference"] == "simulation - rig" and [c["case"] for c in data["cases"]] == [1, 2]
    channels = {ch["channel"]: ch for ch in data["cases"][0]["channels"]}
    assert "e1_front_left_x_force" not in channels
    # the rig's samples are the simulation's, interpolated: the simulation interpolated onto them
    # matches to rounding, and 40 Hz samples of the same loop give its gradient within 1 %
    camber = channels["camber_fl"]
    assert camber["rms_error"] < 1e-9
    assert camber["gradient"]["rig"] == pytest.approx(camber["gradient"]["sim"], rel=0.01)
    assert camber["gradient"]["diff"] == pytest.approx(camber["gradient"]["sim"] - camber["gradient"]["rig"])
    pad = {ch["channel"]: ch for ch in data["cases"][1]["channels"]}["pad_fz_fl"]["dynamic_stiffness"]
    assert pad["unit"] == "N/mm" and pad["rig"] == pytest.approx(pad["sim"], rel=0.02)


# -- errors ----------------------------------------------------------------------------------------
def test_missing_or_non_run_files_are_named(pumping: Run, tmp_path: Path, capsys) -> None:
    missing = tmp_path / "absent.mcap"
    assert cli.main(["compare", str(pumping.path), str(missing)]) == 2
    assert f"vsim: error: {missing}: no such run file" in capsys.readouterr().err
    junk = tmp_path / "junk.mcap"
    junk.write_text("not an MCAP file")
    assert cli.main(["compare", str(junk), str(pumping.path)]) == 2
    err = capsys.readouterr().err
    assert str(junk) in err and ("not a vsim run file" in err or "unreadable MCAP" in err)


@pytest.mark.parametrize("change, words", [
    (lambda r: with_extra(r, cases=r.metadata.extra["cases"][:1]), ["cases ['shape=triangle']",
                                                                      "expected the cases of"]),
    (lambda r: with_extra(r, cases=[{**c, "label": f"other {c['label']}"} for c in r.metadata.extra["cases"]]),
     ["expected the cases of"]),
    (lambda r: with_extra(r, type="roll"), ["type 'roll'; expected 'pumping'"]),
    (lambda r: with_extra(r, duration_scale=0.5), ["duration_scale 0.5; expected 1.0"]),
    (lambda r: with_signals(r, **{n: None for n in r.signals if n.startswith(("camber", "toe", "steer", "half_track",
                                                                              "wheel_centre", "pad_fz"))}),
     ["no channel in common with", "expected any of camber_fl"]),
    (lambda r: with_signals(r, input_time=None), ["not a run of a scenario", "input_time"]),
    (lambda r: with_signals(r, phase=np.zeros_like(r.t_s)), ["case 1 'shape=triangle' has no input samples"]),
    (lambda r: dataclasses.replace(with_signals(r), units={**r.units, "toe_fl": "rad"}),
     ["toe_fl in 'rad'; expected 'deg'"]),
])
def test_mismatched_rig_files_are_refused_with_the_file_named(pumping: Run, change, words: list[str]) -> None:
    with pytest.raises(InputError) as error:
        compare_runs(pumping, change(pumping))
    message = str(error.value)
    assert message.startswith(f"{pumping.path.with_name('rig.mcap')}: "), message
    for word in words:
        assert word in message, message


def test_swapped_files_are_refused_before_any_difference_is_taken(pumping: Run, tmp_path: Path, capsys) -> None:
    """Differences are simulation minus rig: a rig recording first and a simulated run second would flip
    their sign, so the command names the rig file and says which goes first."""
    rig = write_resampled(pumping, tmp_path / "rig.mcap", rate_hz=40.0, offset_s=0.0)
    assert load_run(rig).metadata.source == "rig" and pumping.metadata.source == "simulation"
    assert cli.main(["compare", str(rig), str(pumping.path)]) == 2
    err = capsys.readouterr().err
    assert f"{rig}: the files are swapped" in err and "expected the simulated run first" in err
    camber = {ch.channel: ch for ch in compare_runs(pumping, load_run(rig)).cases[0].channels}["camber_fl"]
    assert camber.rms_error < 1e-9  # in the right order the same files compare
