"""The virtual rig at the K&C level and the K&C dataset format: what is measured (the truth
vehicle's run plus the declared imperfections, on the simulated schedule), that nothing of the
truth is written, that effects show where physics puts them, and the errors of bad truth files and
bad datasets. One short scenario (one triangle at duration scale 0.2: ~1 s per simulation)."""

from __future__ import annotations

import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from elastokin.vehicle.scenarios.channels import INPUT_CHANNELS
from elastokin.cli.main import main as vsim
from elastokin.core.errors import InputError
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.diagnosis.truths import load_truth
from elastokin.diagnosis.virtual_kc_rig import (DEFAULT_SCENARIOS, MEASUREMENT_DEFAULTS, KCTruth, measure_kc, parse_kc_truth,
                                           sensor)
from elastokin.recordings.kc_dataset import read_kc_dataset
from elastokin.recordings.recorder import simulate
from elastokin.recordings.rig_recordings import DERIVED, measured_channels
from elastokin.recordings.run_reader import load_run
from elastokin.recordings.run_writer import RunWriter

SCALE = 0.2
PUMPING = """name: tiny_pumping
description: one 30 mm pumping triangle (test)
type: pumping
vehicle: car.yaml
axles: [front, rear]
output_rate_hz: 50
cases:
  - {shape: triangle, frequency_hz: 0.1, cycles: 1, amplitude_mm: 30}
"""
ROLL = PUMPING.replace("tiny_pumping", "tiny_roll").replace("type: pumping", "type: roll")
#: The hidden effect: its cause, location and value must appear nowhere in the dataset.
EFFECT = {"cause": "coupling", "location": "e1_rear", "directions": ["x", "z"], "stiffness": 83.7}
TRUTH = {"level": "kc", "scenarios": ["pumping.yaml"], "duration_scale": SCALE, "effects": [EFFECT], "seed": 11}
EXACT = {k: 0.0 for k in MEASUREMENT_DEFAULTS}   # a perfect rig: the truth's run as simulated


@pytest.fixture(scope="module")
def where(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("kc")
    (root / "pumping.yaml").write_text(PUMPING)
    shutil.copy(DEFAULT_VEHICLE, root / "car.yaml")   # the scenario's own vehicle, beside it
    (root / "roll.yaml").write_text(ROLL)
    return root


def truth(where: Path, **changes) -> KCTruth:
    return parse_kc_truth({**TRUTH, **changes}, str(where / "t.yaml"), where)


@pytest.fixture(scope="module")
def measured(where) -> Path:
    return measure_kc(truth(where), where / "measured")


@pytest.fixture(scope="module")
def clean(where):
    """The truth vehicle's run without the rig's imperfections."""
    t = truth(where)
    return simulate(replace(t.scenarios[0], bushing_model=None), t.vehicle, duration_scale=SCALE)


def test_dataset_reads_back_on_the_simulated_channels_units_and_schedule(where, measured):
    data = read_kc_dataset(measured)
    assert [t.name for t in data.tests] == ["01_tiny_pumping"]
    assert data.vehicle_text.startswith("c_segment") and data.rig["name"] == "virtual K&C rig"
    test = data.tests[0]
    t = truth(where)
    base = simulate(replace(t.scenarios[0], bushing_model=None), t.baseline, duration_scale=SCALE)
    assert test.run.metadata.source == "rig" and test.run.complete
    channels = measured_channels()
    assert set(test.run.signals) == set(channels) | set(DERIVED)
    assert {n: test.run.units[n] for n in channels} == channels == {n: base.units[n] for n in channels}
    np.testing.assert_allclose(test.run.t_s, base.t_s, atol=1e-9)
    assert test.run.t_s.size == base.t_s.size == 121
    for name in DERIVED:
        np.testing.assert_allclose(test.run.signals[name], base.signals[name], atol=1e-9)
    for name in INPUT_CHANNELS:   # the commanded inputs, written unchanged
        np.testing.assert_array_equal(test.run.signals[name], base.signals[name])
    assert np.ptp(test.run.signals["pad_z_fl"]) == pytest.approx(60.0, abs=1e-9)
    assert test.run.metadata.extra["cases"] == base.metadata.extra["cases"]
    s = test.scenario
    assert (s.name, s.type, s.axles, s.output_rate_hz) == ("tiny_pumping", "pumping", ("front", "rear"), 50.0)
    assert [c.parameters for c in s.cases] == [c.parameters for c in t.scenarios[0].cases]
    assert s.text == PUMPING
    assert s.path == where / "pumping.yaml" and s.vehicle == where / "car.yaml"   # found from the dataset


def test_noise_offsets_and_resolution_are_the_declared_ones(measured, clean):
    run = read_kc_dataset(measured).tests[0].run
    m = MEASUREMENT_DEFAULTS
    for unit in ("deg", "mm", "N"):
        noise, bound, step = sensor(unit, m)
        names = [n for n, u in measured_channels().items() if u == unit and n not in INPUT_CHANNELS]
        residual = np.array([run.signals[n] - clean.signals[n] for n in names])      # (channels, samples)
        offsets = residual.mean(axis=1)
        n = residual.shape[1]
        # each channel's zero error is in ± bound (plus the mean of its noise and quantisation)
        assert np.all(np.abs(offsets) <= bound + 4 * noise / np.sqrt(n) + step / 2), unit
        assert np.abs(offsets).max() > 0.3 * bound, unit      # and offsets were drawn (0.82 to 0.97 of the bound here)
        expected = np.hypot(noise, step / np.sqrt(12.0))
        assert (residual - offsets[:, None]).std() == pytest.approx(expected, rel=0.2), unit
        grid = np.array([run.signals[n] for n in names]) / step
        assert np.abs(grid - np.round(grid)).max() < 1e-6, unit


def test_same_seed_same_signals_other_seed_other_noise(where, measured, tmp_path):
    first = read_kc_dataset(measured).tests[0].run
    again = read_kc_dataset(measure_kc(truth(where), tmp_path / "again")).tests[0].run
    other = read_kc_dataset(measure_kc(truth(where, seed=12), tmp_path / "other")).tests[0].run
    for name in measured_channels():
        np.testing.assert_array_equal(again.signals[name], first.signals[name])
    noisy = [n for n in measured_channels() if n not in INPUT_CHANNELS]
    changed = [n for n in noisy if not np.array_equal(other.signals[n], first.signals[n])]
    assert len(changed) == len(noisy)
    for name in INPUT_CHANNELS:
        np.testing.assert_array_equal(other.signals[name], first.signals[name])


def test_dataset_carries_no_trace_of_the_truth(measured):
    files = sorted(measured.iterdir())
    assert [f.name for f in files] == ["01_tiny_pumping.mcap", "rig.yaml"]
    blob = b"".join(f.read_bytes() for f in files)
    for secret in (b"coupling", b"stiffness", b"83.7", b"e1_rear", b"seed", b"effects", b"truth"):
        assert secret not in blob, secret
    manifest = yaml.safe_load((measured / "rig.yaml").read_text())
    assert set(manifest) == {"level", "vehicle", "rig", "recordings"} and manifest["level"] == "kc"
    run = load_run(files[0])
    assert run.metadata.vehicle_yaml == "" and run.metadata.bushing_parameters == {}
    assert not any(k in run.metadata.extra for k in ("vehicle_file", "bushing_model"))


def _loop_width(run, pad: str, travel: str) -> float:
    """Mean pad force on the way up minus on the way down, within 3 mm of mid travel [N]."""
    s = run.signals
    on = s["phase"] == 2
    x, f = s[travel][on], s[pad][on]
    v = np.gradient(s[f"pad_z_{pad[-2:]}"][on])
    mid = np.abs(x) < 3.0
    return float(f[mid & (v > 0)].mean() - f[mid & (v < 0)].mean())


def test_strut_friction_widens_the_front_pad_force_loop(where, tmp_path):
    base = read_kc_dataset(measure_kc(truth(where, effects=[], measurement=EXACT), tmp_path / "b")).tests[0].run
    friction = {"cause": "strut_friction", "strut_friction": 200.0}
    rubbed = read_kc_dataset(measure_kc(truth(where, effects=[friction], measurement=EXACT),
                                        tmp_path / "f")).tests[0].run
    growth = _loop_width(rubbed, "pad_fz_fl", "wheel_travel_fl") - _loop_width(base, "pad_fz_fl", "wheel_travel_fl")
    # 2 x friction x (strut sliding per wheel travel, ~0.95 on this car): ~380 N
    assert 0.75 * 400.0 < growth < 1.1 * 400.0, growth
    assert _loop_width(rubbed, "pad_fz_fr", "wheel_travel_fr") - _loop_width(base, "pad_fz_fr", "wheel_travel_fr") \
        == pytest.approx(growth, rel=1e-3)
    for tag in ("rl", "rr"):   # the rear has no strut
        assert np.abs(rubbed.signals[f"pad_fz_{tag}"] - base.signals[f"pad_fz_{tag}"]).max() < 1e-6


def test_beam_torsion_changes_the_rear_and_leaves_the_front(where, tmp_path):
    def roll(effects, name):
        t = truth(where, scenarios=["roll.yaml"], effects=effects, measurement=EXACT)
        return read_kc_dataset(measure_kc(t, tmp_path / name)).tests[0].run.signals

    base = roll([], "b")
    stiff = roll([{"cause": "beam_torsion", "beam_torsion_scale": 2.0}], "s")
    diff = {n: np.abs(stiff[n] - base[n]).max() for n in measured_channels()}
    front = [n for n in diff if n.endswith(("_fl", "_fr"))]
    assert max(diff[n] for n in front if not n.startswith("pad_fz")) < 1e-8     # mm, deg (~3e-9: solver round-off)
    # N, of ~5000 N: the front bushings see the same deflections to round-off, so their implicit
    # solves differ only where round-off changes a Newton pass, which places the nodes to the bank's
    # tolerance, 1e-8 m (measured: 1.5e-6 N; 5e-5 N with an earlier predictor); a leak of the rear
    # cause is ≥ 1 N.
    assert max(diff[n] for n in front if n.startswith("pad_fz")) < 1e-3
    for tag in ("rl", "rr"):
        assert diff[f"pad_fz_{tag}"] > 300.0      # a stiffer beam carries more of the roll moment at the rear
        assert diff[f"camber_{tag}"] > 0.02
        assert diff[f"toe_{tag}"] > 0.002


def test_load_truth_reads_either_level_and_the_default_campaign(where):
    path = where / "truth_file.yaml"
    path.write_text(yaml.safe_dump({"level": "kc", "vehicle": str(DEFAULT_VEHICLE),
                                    "effects": [{"cause": "mullins", "location": "e1_front.y", "mullins": 0.15}]}))
    t = load_truth(path)
    assert isinstance(t, KCTruth)
    assert [s.name for s in t.scenarios] == ["kc_pumping", "kc_roll", "kc_lateral_force", "kc_rack_step"]
    assert [s.path for s in t.scenarios] == list(DEFAULT_SCENARIOS)
    assert t.seed == 0 and t.duration_scale == 1.0 and t.measurement == MEASUREMENT_DEFAULTS
    assert t.effects[0].location == ("e1_front", "y")
    assert t.vehicle.bushings != t.baseline.bushings


def test_cli_measures_a_kc_truth_and_refuses_to_overwrite(where, tmp_path, capsys):
    path = where / "cli_truth.yaml"
    path.write_text(yaml.safe_dump({**TRUTH, "effects": []}))
    assert vsim(["rig", "measure", str(path), "-o", str(tmp_path / "out")]) == 0
    captured = capsys.readouterr()
    assert "scenario 1/1: tiny_pumping" in captured.err and "K&C dataset" in captured.out
    assert len(read_kc_dataset(tmp_path / "out").tests) == 1
    assert vsim(["rig", "measure", str(path), "-o", str(tmp_path / "out")]) == 2
    assert "--overwrite" in capsys.readouterr().err


@pytest.mark.parametrize("change, key, says", [
    ({"level": "bench"}, "level", "kc"),
    ({"colour": 1}, "colour", "unknown key"),
    ({"vehicle": "no_such.yaml"}, "vehicle", "no such vehicle file"),
    ({"scenarios": ["missing.yaml"]}, "scenarios[0]", "no such scenario file"),
    ({"scenarios": "pumping.yaml"}, "scenarios", "list"),
    ({"duration_scale": 0}, "duration_scale", "> 0"),
    ({"effects": {"cause": "mullins"}}, "effects", "list"),
    ({"effects": ["mullins"]}, "effects[0]", "mapping"),
    ({"effects": [{"cause": "gremlins"}]}, "effects[0].cause", "unknown cause"),
    ({"effects": [{"cause": "self_heating", "heating": 0.1, "heating_tau_s": 100}]}, "effects[0].cause", "bench"),
    ({"effects": [{"cause": "mullins", "location": "e1_front.y"}]}, "effects[0].mullins", "missing parameter"),
    ({"effects": [{"cause": "mullins", "location": "e1_front.y", "mullins": 0.1, "pw": 2}]}, "effects[0].pw",
     "unknown key"),
    ({"effects": [{"cause": "mullins", "location": "e1_front.y", "mullins": "much"}]}, "effects[0].mullins",
     "finite number"),
    ({"effects": [{"cause": "mullins", "mullins": 0.1}]}, "effects[0].location", "missing key"),
    ({"effects": [{"cause": "mullins", "location": "e1_front.q", "mullins": 0.1}]}, "effects[0].location",
     "e1_front.x, e1_front.y"),
    ({"effects": [{"cause": "viscoelasticity_excess", "location": "e1_front.y", "Ff": 10, "co_scale": 0.5}]},
     "effects[0].location", "e2_front.x, e2_front.y, e2_front.z"),
    ({"effects": [{"cause": "preload", "location": "e1_front.y", "preload": 100}]}, "effects[0].location",
     "applies to no bushing direction"),
    ({"effects": [{**EFFECT, "location": "e9"}]}, "effects[0].location", "e1_front, e2_front, e1_rear"),
    ({"effects": [{**EFFECT, "directions": ["x", "x"]}]}, "effects[0].directions", "two distinct"),
    ({"effects": [{**EFFECT, "stiffness": 1e6}]}, "effects[0]", "positive definite"),
    ({"effects": [{"cause": "strut_friction", "location": "front", "strut_friction": 200.0}]},
     "effects[0].location", "unknown key"),
    ({"effects": [{"cause": "strut_friction", "strut_friction": -1.0}]}, "effects[0]", "non-negative"),
    ({"effects": [{"cause": "backlash", "location": "e1_front.y", "backlash": True}]}, "effects[0].backlash",
     "finite number"),
    ({"measurement": {"force_noise_N": 1.0}}, "measurement.force_noise_N", "unknown key"),
    ({"measurement": {"angle_noise_deg": -1.0}}, "measurement.angle_noise_deg", ">= 0"),
    ({"seed": 1.5}, "seed", "whole number"),
    ({"chain": [1]}, "chain", "mapping of channel"),
    ({"chain": {"toe_xx": {"gain": 0.01}}}, "chain.toe_xx", "no measured channel"),
    ({"chain": {"pad_fy": {"gain": 0.01, "delay_ms": 5.0}}}, "chain.pad_fy.delay_ms", "servoed rig input"),
    ({"chain": {"toe": {"crosstalk": 0.01}}}, "chain.toe.crosstalk", "mapping of quantity of the same wheel"),
    ({"chain": {"toe": {"crosstalk": {"camber_x": 0.01}}}}, "chain.toe.crosstalk.camber_x", "no other quantity"),
    ({"chain": {"toe_fl": {"crosstalk": {"toe": 0.01}}}}, "chain.toe_fl.crosstalk.toe", "no other quantity"),
    ({"chain": {"pad_fz": {"crosstalk": {"pad_fy": "x"}}}}, "chain.pad_fz.crosstalk.pad_fy", "number"),
    ({"chain": {"toe": {"lag_ms": 1.0}}}, "chain.toe.lag_ms", "unknown chain element"),
    ({"chain": {"toe": {"delay_ms": -1.0}}}, "chain.toe.delay_ms", ">= 0"),
    ({"chain": {"camber_fl": {"gain": -1.5}}}, "chain.camber_fl.gain", "> -1"),
    ({"chain": {"toe": {"ar1_sigma": 0.01}, "toe_fl": {"ar1_sigma": 0.0}}}, "chain", "toe_fr: ar1_sigma and"),
])
def test_truth_errors_name_the_file_and_key(where, change, key, says):
    with pytest.raises(InputError) as err:
        parse_kc_truth({**TRUTH, **change}, "truth.yaml", where)
    assert err.value.key == key and err.value.source == "truth.yaml"
    assert says in str(err.value)


def _rewrite(src: Path, dst: Path, *, source: str = "rig", complete: bool = True) -> None:
    """``src`` written again as a ``source`` run, closed as stopped unless ``complete``."""
    run = load_run(src)
    table = np.column_stack([run.signals[s.name] for s in run.specs])
    with RunWriter(dst, signals=run.specs, bodies=[], geometry=[], metadata=replace(run.metadata, source=source),
                   overwrite=True) as writer:
        for t, row in zip(run.t_s, table):
            writer.write(t, row, np.empty((0, 3)), np.empty((0, 4)))
        if not complete:
            writer.close(complete=False, reason="stopped by the test")


RECORDING = "01_tiny_pumping.mcap"


@pytest.mark.parametrize("edit, key, says", [
    (lambda d: (d / "rig.yaml").unlink(), None, "no rig.yaml"),
    (lambda d: (d / "rig.yaml").write_text("- a list\n"), None, "mapping"),
    (lambda d: _manifest(d, extra=1), "extra", "unknown key"),
    (lambda d: _manifest(d, level="bench"), "level", "level: kc"),
    (lambda d: _manifest(d, vehicle=3), "vehicle", "free text"),
    (lambda d: _manifest(d, rig="bench 3"), "rig", "mapping"),
    (lambda d: _manifest(d, recordings=None), "recordings", "non-empty list"),
    (lambda d: _manifest(d, recordings=RECORDING), "recordings", "non-empty list"),
    (lambda d: _manifest(d, recordings=[RECORDING, "02_missing.mcap"]), "recordings[1]", "no such recording"),
    (lambda d: _manifest(d, recordings=[RECORDING, RECORDING]), "recordings[1]", "listed twice"),
    (lambda d: (d / RECORDING).write_bytes(b"not an mcap"), "recordings[0]", "unreadable MCAP"),
    (lambda d: _rewrite(d / RECORDING, d / RECORDING, source="simulation"), "recordings[0]", "not a rig recording"),
    (lambda d: _rewrite(d / RECORDING, d / RECORDING, complete=False), "recordings[0]", "incomplete"),
])
def test_dataset_errors_name_the_key(measured, tmp_path, edit, key, says):
    copy = tmp_path / "copy"
    shutil.copytree(measured, copy)
    edit(copy)
    with pytest.raises(InputError) as err:
        read_kc_dataset(copy)
    assert err.value.key == key and err.value.source == str(copy / "rig.yaml")
    assert says in str(err.value)


def _manifest(directory: Path, **changes) -> None:
    path = directory / "rig.yaml"
    data = {**yaml.safe_load(path.read_text()), **changes}
    path.write_text(yaml.safe_dump({k: v for k, v in data.items() if v is not None}))


def test_a_moved_dataset_still_rebuilds_its_scenarios(measured, tmp_path):
    moved = tmp_path / "elsewhere" / "deeper" / "kc"
    shutil.copytree(measured, moved)
    test = read_kc_dataset(moved).tests[0]   # the scenario file is out of reach: its text is enough
    assert test.scenario.name == "tiny_pumping" and test.scenario.text == PUMPING
    assert test.scenario.vehicle == DEFAULT_VEHICLE    # car.yaml does not resolve: the default stands in
    assert test.scenario.cases[0].duration_s == pytest.approx(10.0)
