"""Measured rig recordings and `vsim rig import`: round trip through units and signs, case/phase
splitting identical to the simulated run the data came from, every validation error (naming its
key or column, writing nothing), the shipped example."""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader

from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.cli import main as cli
from elastokin.core.errors import InputError
from elastokin.recordings.csv_export import write_declared_csv
from elastokin.recordings.csv_import import import_csv
from elastokin.recordings.recorder import run_scenario
from elastokin.recordings.rig_recordings import measured_channels, write_rig_recording
from elastokin.recordings.run_format import RUN_RECORD, TF_TOPIC, Run, RunMetadata, SignalSpec
from elastokin.recordings.run_reader import load_run
from elastokin.recordings.run_writer import RunWriter

ROOT = Path(__file__).resolve().parent.parent
PUMPING = ROOT / "scenarios/pumping.yaml"
EXAMPLE = ROOT / "data/examples/kc_import"
EXAMPLE_META, EXAMPLE_CSV = EXAMPLE / "META.yaml", EXAMPLE / "kc_pumping.csv"
QUICK = 0.05   #: the example's duration scale


@pytest.fixture(scope="module")
def simulated(tmp_path_factory: pytest.TempPathFactory) -> Run:
    """The example's source: pumping.yaml simulated with durations × 0.05."""
    path = tmp_path_factory.mktemp("sim") / "pumping.mcap"
    return load_run(run_scenario(load_scenario(PUMPING), path, duration_scale=QUICK).path)


@pytest.fixture(scope="module")
def imported(simulated: Run, tmp_path_factory: pytest.TempPathFactory) -> Run:
    """``simulated`` exported as the example META declares, then imported with `vsim rig import`."""
    folder = tmp_path_factory.mktemp("rig")
    write_declared_csv(simulated, EXAMPLE_META, folder / "data.csv")   # as a rig would export it
    out = folder / "rig.mcap"
    assert cli.main(["rig", "import", str(folder / "data.csv"), "--meta", str(EXAMPLE_META), "-o", str(out)]) == 0
    return load_run(out)


def test_import_round_trip_gives_the_original_signals(simulated: Run, imported: Run) -> None:
    declared = yaml.safe_load(EXAMPLE_META.read_text())["columns"]
    assert len(imported.t_s) == len(simulated.t_s)
    np.testing.assert_allclose(imported.t_s, simulated.t_s, rtol=0, atol=1e-9)
    for column in declared.values():
        name = column["channel"]
        assert imported.units[name] == simulated.units[name]
        scale = np.abs(simulated.signals[name]) + np.abs(column.get("offset", 0.0))  # 10 digits of the CSV value
        assert np.all(np.abs(imported.signals[name] - simulated.signals[name]) <= 1e-9 * scale + 1e-12), name
    assert {s.name for s in imported.specs} == {c["channel"] for c in declared.values()} | {"case", "phase",
                                                                                            "input_time"}


def test_rig_recording_splits_by_case_and_phase_like_the_simulated_run(simulated: Run, imported: Run) -> None:
    for name in ("case", "phase"):
        np.testing.assert_array_equal(imported.signals[name], simulated.signals[name])
    np.testing.assert_allclose(imported.signals["input_time"], simulated.signals["input_time"], atol=1e-9)
    sim_extra, rig_extra = simulated.metadata.extra, imported.metadata.extra
    for key in ("cases", "scenario", "type", "axles", "x_quantity", "duration_scale", "output_rate_hz", "settle"):
        assert rig_extra[key] == sim_extra[key], key
    hints = {s.name: s.x_axis for s in simulated.specs}
    assert all(s.x_axis == hints[s.name] for s in imported.specs)
    assert imported.pairs() and all(x.startswith("wheel_travel_") for x, _ in imported.pairs())


def test_rig_recording_holds_no_model(imported: Run) -> None:
    meta = imported.metadata
    assert meta.source == "rig" and meta.scenario_yaml == PUMPING.read_text()
    assert meta.vehicle_yaml == "" and meta.bushing_parameters == {}
    assert "vehicle_file" not in meta.extra and "bushing_model" not in meta.extra
    assert meta.extra["rig"]["name"] == "virtual K&C rig (vsim example)"
    assert meta.extra["rig"]["sample_rate_hz"] == pytest.approx(50.0)
    assert imported.body_names == [] and imported.geometry == [] and imported.complete
    with open(imported.path, "rb") as stream:
        reader = make_reader(stream)
        record = next(m.metadata for m in reader.iter_metadata() if m.name == RUN_RECORD)
        topics = {c.topic for c in reader.get_summary().channels.values()}
    assert "vehicle_yaml" not in record and "bushing_parameters" not in record
    assert TF_TOPIC not in topics


def test_shipped_example_imports_and_plots(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert EXAMPLE_CSV.stat().st_size < 300_000
    out = tmp_path / "kc.mcap"
    args = ["rig", "import", str(EXAMPLE_CSV), "--meta", str(EXAMPLE_META), "-o", str(out)]
    assert cli.main(args) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    run = load_run(out)
    assert set(np.unique(run.signals["case"])) == {1.0, 2.0, 3.0, 4.0, 5.0, 6.0}
    assert cli.main(["plot", str(out), "-o", str(tmp_path / "png")]) == 0
    assert (tmp_path / "png/pairs_camber.png").is_file()
    assert cli.main(args) == 2 and "the output exists" in capsys.readouterr().err
    assert cli.main([*args, "--overwrite"]) == 0


def test_inline_scenario_gives_the_same_schedule(tmp_path: Path) -> None:
    scenario = yaml.safe_load(PUMPING.read_text())
    del scenario["vehicle"]   # relative to scenarios/; the default car is the same
    meta = yaml.safe_load(EXAMPLE_META.read_text()) | {"scenario": scenario}
    (tmp_path / "META.yaml").write_text(yaml.safe_dump(meta, sort_keys=False, allow_unicode=True))
    inline = load_run(import_csv(EXAMPLE_CSV, tmp_path / "META.yaml", tmp_path / "inline.mcap"))
    from_file = load_run(import_csv(EXAMPLE_CSV, EXAMPLE_META, tmp_path / "file.mcap"))
    assert inline.metadata.extra["cases"] == from_file.metadata.extra["cases"]
    assert inline.metadata.extra["scenario"] == "pumping"
    np.testing.assert_array_equal(inline.signals["phase"], from_file.signals["phase"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["META.yaml", "file.mcap", "inline.mcap"]


# -- validation ---------------------------------------------------------------------------------------
Edit = Callable[[str, list[list[str]]], str]   #: changes the CSV rows in place, returns the META text


def cell(rows: list[list[str]], row: int, column: str, value: str) -> None:
    rows[row][rows[0].index(column)] = value


def meta_only(change: Callable[[str], str]) -> Edit:
    return lambda meta, rows: change(meta)


def csv_only(change: Callable[[list[list[str]]], None]) -> Edit:
    def edit(meta: str, rows: list[list[str]]) -> str:
        change(rows)
        return meta
    return edit


INVALID: dict[str, tuple[Edit, list[str]]] = {
    "unknown META key": (meta_only(lambda m: m + "colour: red\n"), ["META.yaml:", "unknown key 'colour'"]),
    "unknown column key": (meta_only(lambda m: m.replace("sign: -1}", "sign: -1, gain: 2}", 1)),
                           ["columns.camber_FL_rad.gain", "unknown key 'gain'"]),
    "unknown channel": (meta_only(lambda m: m.replace("channel: camber_fl,", "channel: camber_front_left,")),
                        ["columns.camber_FL_rad.channel", "unknown channel 'camber_front_left'", "camber_<c>"]),
    "unit mismatch": (meta_only(lambda m: m.replace("camber_fl, unit: rad", "camber_fl, unit: mm")),
                      ["columns.camber_FL_rad.unit", "unit mismatch: 'mm'", "camber_fl", "deg, rad, arcmin"]),
    "unknown unit": (meta_only(lambda m: m.replace("unit: daN", "unit: lbf", 1)),
                     ["columns.pad_fz_FL_daN.unit", "unknown unit 'lbf'"]),
    "bad sign": (meta_only(lambda m: m.replace("sign: -1", "sign: 2", 1)), ["columns.camber_FL_rad.sign", "+1 or -1"]),
    "time unit": (meta_only(lambda m: m.replace("unit: ms", "unit: mm")), ["time.unit", "'mm'", "s, ms"]),
    "channel twice": (meta_only(lambda m: m.replace("channel: toe_fl,", "channel: camber_fl,")),
                      ["columns.toe_FL_arcmin.channel", "camber_fl is already given by column 'camber_FL_rad'"]),
    "declared column missing from the CSV": (
        meta_only(lambda m: m + "  steer_FL_deg: {channel: steer_fl, unit: deg}\n"),
        ["kc.csv", "line 1", "missing column(s) steer_FL_deg"]),
    "driven input missing": (meta_only(lambda m: m.replace("  pad_z_RR_mm:     {channel: pad_z_rr, unit: mm}\n", "")),
                             ["missing required channel(s) pad_z_rr"]),
    "x signal missing": (meta_only(lambda m: m.replace("  travel_FL_m:     {channel: wheel_travel_fl, unit: m}\n", "")),
                         ["missing required channel(s) wheel_travel_fl"]),
    "no wheel with camber and toe": (
        meta_only(lambda m: "\n".join(line for line in m.splitlines() if "toe_" not in line) + "\n"),
        ["missing required channel(s) camber_<c> and toe_<c> of one wheel"]),
    "NaN": (csv_only(lambda rows: cell(rows, 10, "toe_FL_arcmin", "nan")),
            ["kc.csv", "line 11, column toe_FL_arcmin", "'nan'"]),
    "not a number": (csv_only(lambda rows: cell(rows, 20, "pad_z_RL_mm", "12;5")),
                     ["line 21, column pad_z_RL_mm", "'12;5'"]),
    "time not increasing": (csv_only(lambda rows: cell(rows, 30, "time_ms", rows[29][0])),
                            ["line 31, column time_ms", "increase strictly"]),
    "sampling gap": (csv_only(lambda rows: rows.__delitem__(slice(100, 104))),
                     ["line 101, column time_ms", "sampling gap of 0.1 s", "1.5 × the median step 0.02 s"]),
    "time too short": (csv_only(lambda rows: rows.__delitem__(slice(-20, None))),
                       ["column time_ms", "before the end of the scenario"]),
    "time not starting at the scenario's start": (
        meta_only(lambda m: m.replace("unit: ms\n", "unit: ms\n  offset: 1000\n")),
        ["line 2, column time_ms", "time starts at 1 s"]),
    "bad inline scenario": (meta_only(lambda m: m.replace(f"scenario: {PUMPING}", "scenario: {type: pumping, "
                                                          "cases: [{amplitude_mm: ten, frequency_hz: 0.1}]}")),
                            ["META.yaml:", "scenario: inline scenario, cases[0].amplitude_mm", "'ten'"]),
}


@pytest.mark.parametrize("name", INVALID)
def test_invalid_input_is_refused_naming_key_or_column_and_nothing_is_written(tmp_path: Path, name: str) -> None:
    edit, expected = INVALID[name]
    rows = [line.split(",") for line in EXAMPLE_CSV.read_text().splitlines()]
    meta = edit(EXAMPLE_META.read_text().replace("../../../scenarios/pumping.yaml", str(PUMPING)), rows)
    (tmp_path / "META.yaml").write_text(meta)
    (tmp_path / "kc.csv").write_text("\n".join(",".join(row) for row in rows) + "\n")
    with pytest.raises(InputError) as error:
        import_csv(tmp_path / "kc.csv", tmp_path / "META.yaml", tmp_path / "out/rig.mcap")
    for part in expected:
        assert part in str(error.value), str(error.value)
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
    assert sorted(p.name for p in tmp_path.iterdir() if p.is_file()) == ["META.yaml", "kc.csv"]


def test_existing_output_is_kept_without_overwrite(tmp_path: Path) -> None:
    out = tmp_path / "rig.mcap"
    out.write_bytes(b"an older recording")
    with pytest.raises(InputError, match="the output exists; pass --overwrite"):
        import_csv(EXAMPLE_CSV, EXAMPLE_META, out)
    assert out.read_bytes() == b"an older recording"
    assert [p.name for p in tmp_path.iterdir()] == ["rig.mcap"]


# -- the writer the virtual rig shares ---------------------------------------------------------------
def test_measured_channels_are_the_runs_wheel_pad_and_input_channels(simulated: Run) -> None:
    channels = measured_channels()
    assert all(simulated.units[name] == unit for name, unit in channels.items())
    assert {"camber_fl", "toe_rr", "half_track_fr", "steer_fl", "wheel_centre_z_rl", "pad_fz_fl", "pad_fy_rr",
            "pad_mz_fl", "pad_z_fl", "rack"} <= set(channels)
    assert not any(name.endswith(("_deflection", "_force")) or name in ("case", "phase") for name in channels)


@pytest.mark.parametrize("signal, unit, message", [
    ("e1_front_left_x_deflection", "mm", "not a channel a K&C rig measures"),
    ("phase", "-", "derived from the scenario"),
    ("camber_fl", "rad", "unit 'rad'; expected 'deg'"),
])
def test_writer_refuses_channels_a_rig_does_not_measure_and_wrong_units(simulated: Run, tmp_path: Path, signal: str,
                                                                         unit: str, message: str) -> None:
    signals = {name: simulated.signals[name] for name in measured_channels()}
    units = dict(measured_channels())
    signals[signal], units[signal] = simulated.signals[signal], unit
    with pytest.raises(InputError, match=message) as error:
        write_rig_recording(tmp_path / "rig.mcap", load_scenario(PUMPING), simulated.t_s, signals, units,
                            rig={"name": "test"}, duration_scale=QUICK)
    assert error.value.key == signal and not any(tmp_path.iterdir())


def test_run_writer_refuses_a_rig_record_with_a_model(tmp_path: Path) -> None:
    metadata = RunMetadata(vehicle_yaml="wheelbase_m: 2.6\n", source="rig")
    with pytest.raises(ValueError, match="carries no model"):
        RunWriter(tmp_path / "rig.mcap", signals=[SignalSpec("camber_fl", "deg", "camber")], bodies=[], geometry=[],
                  metadata=metadata)


def _pads_as_played(simulated: Run, lag_s: float = 0.0, gain: float = 1.0, noise_mm: float = 0.0
                    ) -> dict[str, np.ndarray]:
    """The simulated run's measured channels, its pad travels as a rig would have played them:
    ``lag_s`` late, ``gain`` times the command, with white noise of ``noise_mm`` (seeded)."""
    signals = {name: simulated.signals[name].copy() for name in measured_channels()}
    noise = np.random.default_rng(7)
    for tag in ("fl", "fr", "rl", "rr"):
        played = np.interp(simulated.t_s - lag_s, simulated.t_s, simulated.signals[f"pad_z_{tag}"])
        signals[f"pad_z_{tag}"] = gain * played + noise.normal(0.0, noise_mm, played.size)
    return signals


@pytest.mark.parametrize("lag_s, gain, noise_mm, refused", [
    (0.02, 1.02, 0.1, False),     # a rig's servo: late, a little high, noisy
    (-0.03, 0.98, 0.0, False),
    (0.15, 1.0, 0.0, True),       # 2 Hz triangles of 10 mm: 8 mm off beyond the 50 ms allowed
    (0.0, 1.25, 0.0, True),       # 2.5 mm off at the 10 mm peak: beyond 5 % + 0.5 mm
    (0.0, -1.0, 0.0, True),       # a sign wrong
])
def test_rig_inputs_must_follow_the_scenario(simulated: Run, tmp_path: Path, lag_s: float, gain: float,
                                             noise_mm: float, refused: bool) -> None:
    signals = _pads_as_played(simulated, lag_s, gain, noise_mm)
    write = lambda: write_rig_recording(tmp_path / "rig.mcap", load_scenario(PUMPING), simulated.t_s, signals,
                                        measured_channels(), rig={"name": "test"}, duration_scale=QUICK)
    if not refused:
        assert load_run(write()).signals["pad_z_fl"].tolist() == signals["pad_z_fl"].tolist()
        return
    with pytest.raises(InputError, match=r"the rig input is -?[\d.]+ mm at t = [\d.]+ s where the scenario pumping "
                                         r"commands -?[\d.]+ mm \(case 1 'amplitude_mm=10', input\)") as error:
        write()
    assert error.value.key.startswith("sample ") and error.value.key.endswith(", pad_z_fl")
    assert not any(tmp_path.iterdir())

