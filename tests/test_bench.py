"""Bench programmes, bench-file validation, the `vsim bushing run` command and its outputs."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
import yaml

from elastokin.bushings.bench.bench_file import load_bench, parse_bench, run_bench
from elastokin.bushings.bench.programmes import firtree, multisine, parse_programme, read_csv_record, sine, step, triangle
from elastokin.cli.main import build_parser, main
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output

MM = 1e-3
BENCH_DIR = Path(__file__).resolve().parent.parent / "models" / "bushings" / "benches"


# --- programme shapes -------------------------------------------------------------------------

def test_triangle_amplitude_period_and_speed():
    t, e = triangle(2 * MM, 0.5 * MM, cycles=2, dt_s=0.01)
    assert t[-1] == pytest.approx(2 * 16.0)  # period 4·A/v = 16 s
    assert e.max() == pytest.approx(2 * MM) and e.min() == pytest.approx(-2 * MM)
    assert e[np.searchsorted(t, 4.0)] == pytest.approx(2 * MM)  # tip at A/v
    speed = np.abs(np.diff(e)) / 0.01
    assert np.median(speed) == pytest.approx(0.5 * MM, rel=1e-9) and speed.max() <= 0.5 * MM * (1 + 1e-9)


def test_sine_and_bisine():
    t, e = sine(0.5 * MM, 10.0, cycles=3, dt_s=1e-3)
    assert t[-1] == pytest.approx(0.3) and np.max(np.abs(e)) == pytest.approx(0.5 * MM, rel=1e-3)
    assert e[np.searchsorted(t, 0.1)] == pytest.approx(0.0, abs=1e-12)  # period 0.1 s
    t, e = multisine([1 * MM, 0.2 * MM], [1.0, 10.0], duration_s=2.0, dt_s=1e-3)
    spectrum = np.abs(np.fft.rfft(e[:-1])) * 2 / (len(t) - 1)
    freqs = np.fft.rfftfreq(len(t) - 1, 1e-3)
    assert spectrum[freqs == 1.0][0] == pytest.approx(1 * MM, rel=1e-6)
    assert spectrum[freqs == 10.0][0] == pytest.approx(0.2 * MM, rel=1e-6)


def test_step_rise_and_hold():
    t, e = step(0.7 * MM, rise_time_s=0.1, hold_s=10.0, dt_s=1e-3)
    assert t[-1] == pytest.approx(10.1)
    assert e[np.searchsorted(t, 0.05)] == pytest.approx(0.35 * MM)
    assert np.all(e[t >= 0.1 - 1e-12] == pytest.approx(0.7 * MM))


def test_firtree_holds_every_millimetre():
    dt, hold = 1e-3, 2.0
    t, e = firtree(3 * MM, 10 * MM, 1 * MM, hold, cycles=1, dt_s=dt)
    # 12 legs of 1 mm at 10 mm/s and 11 holds
    assert t[-1] == pytest.approx(12 * 0.1 + 11 * hold)
    assert e.max() == pytest.approx(3 * MM) and e.min() == pytest.approx(-3 * MM)
    assert e[-1] == pytest.approx(0.0, abs=1e-15)
    moving = np.abs(np.diff(e)) > 1e-12
    assert np.abs(np.diff(e))[moving].max() == pytest.approx(10 * MM * dt)
    starts = np.flatnonzero(np.diff(moving.astype(int)) == -1) + 1  # first still sample of each hold
    ends = np.flatnonzero(np.diff(moving.astype(int)) == 1) + 1
    levels = np.round(e[starts] / MM, 9)
    assert list(levels) == [1, 2, 3, 2, 1, 0, -1, -2, -3, -2, -1]
    np.testing.assert_allclose((ends - starts) * dt, hold, atol=1.5 * dt)


def test_programme_defaults_are_the_thesis_firtree():
    prog = parse_programme({"type": "firtree"}, 0.01, "b.yaml")
    assert prog.t_s[-1] == pytest.approx(12 * 0.1 + 11 * 60.0)
    assert np.max(prog.e_m) == pytest.approx(3 * MM)


def test_a_sine_about_a_static_offset_ramps_there_rests_and_comes_back():
    """``static_mm``: a 1 mm/s ramp to the offset, 1 s at rest, the sine about the offset, a ramp back."""
    dt = 0.002
    prog = parse_programme({"type": "sine", "amplitude_mm": 0.5, "frequency_hz": 1.0, "cycles": 3, "static_mm": -2.0},
                           dt, "b.yaml")
    t, e = prog.t_s, prog.e_m
    assert np.all(np.diff(t) == pytest.approx(dt))
    ramp = t <= 2.0
    np.testing.assert_allclose(e[ramp], -1e-3 * t[ramp], atol=1e-15)                       # 1 mm/s to -2 mm
    rest = (t > 2.0 + dt / 2) & (t < 3.0 - dt / 2)
    np.testing.assert_allclose(e[rest], -2 * MM, atol=1e-15)
    sine_part = (t > 3.0 + dt / 2) & (t < 6.0 + dt / 2)
    assert e[sine_part].max() == pytest.approx(-1.5 * MM, abs=1e-9) and e[sine_part].min() == pytest.approx(-2.5 * MM, abs=1e-9)
    assert e[sine_part].mean() == pytest.approx(-2 * MM, abs=1e-6)
    assert e[-1] == 0.0 and t[-1] == pytest.approx(2.0 + 1.0 + dt + 3.0 + dt + 2.0)


def test_csv_record_is_resampled(tmp_path):
    path = tmp_path / "rec.csv"
    path.write_text("t_s,e_mm,F_N\n0,0,0\n1,2,5\n2,0,1\n")
    prog = parse_programme({"type": "csv", "path": "rec.csv"}, 0.25, "b.yaml", base_dir=tmp_path)
    np.testing.assert_allclose(prog.t_s, np.arange(9) * 0.25)
    assert prog.e_m[2] == pytest.approx(1 * MM) and prog.e_m[4] == pytest.approx(2 * MM)


@pytest.mark.parametrize("text, message", [
    ("t_s,e_mm\n0,0\n1,nan\n", "line 3, column e_mm: expected a finite number"),
    ("t_s,e_mm\n0,0\n1,1\n1,2\n", "line 4, column t_s: time must increase strictly"),
    ("t_s,e_mm\n0,0\n1,abc\n", "line 3, column e_mm: expected a number, got 'abc'"),
    ("time,e_mm\n0,0\n1,1\n", "line 1: missing column(s) t_s"),
    ("t_s,e_mm\n0,0\n", "too short: 1 samples, expected at least 2"),
])
def test_csv_errors_name_file_line_and_column(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        read_csv_record(path)
    assert str(path) in str(err.value) and message in str(err.value)


# --- bench validation -------------------------------------------------------------------------

GOOD = {"model": "stvs", "params": "fig5_9_caption", "dt_s": 0.001,
        "programme": {"type": "sine", "amplitude_mm": 0.5, "frequency_hz": 10, "cycles": 2}}
INLINE = {"K0": 508.2, "Kpa": 1076.7, "Kr": 2935, "Ff": 9, "Co": 32, "pw": 0.15}


def _with(**changes):
    data = {**GOOD, **changes}
    return {k: v for k, v in data.items() if v is not None}


@pytest.mark.parametrize("data, key, message", [
    (_with(model="stvx"), "model", "unknown model 'stvx'"),
    (_with(extra=1), "extra", "unknown key 'extra'"),
    (_with(params={**INLINE, "Kpb": 3}), "Kpb", "unknown parameter"),
    (_with(params={k: v for k, v in INLINE.items() if k != "Kr"}), "Kr", "missing parameter"),
    (_with(params={**INLINE, "K0": -5}), "K0", "non-negative"),
    (_with(params={**INLINE, "pw": 1.5}), "pw", "0.03 <= pw <= 1"),
    (_with(params={**INLINE, "pw": 0}), "pw", "0.03 <= pw <= 1"),
    (_with(params="nosuchset"), "params", "no parameter set 'nosuchset'"),
    (_with(dt_s=-1), "dt_s", "positive time step"),
    (_with(dt_s=None), "dt_s", "missing key"),
    (_with(programme={"type": "saw"}), "programme.type", "unknown programme type 'saw'"),
    (_with(programme={"type": "sine", "amplitude_mm": 1, "frequency_hz": 10, "phase": 1}), "programme.phase",
     "unknown key 'phase'"),
    (_with(programme={"type": "sine", "amplitude_mm": 1}), "programme.frequency_hz", "missing key"),
    (_with(programme={"type": "sine", "amplitude_mm": -1, "frequency_hz": 10}), "programme.amplitude_mm", "positive"),
    (_with(programme={"type": "sine", "amplitude_mm": 1, "frequency_hz": 100}), "programme.frequency_hz",
     "fewer than 20 points"),
    (_with(programme={"type": "triangle", "amplitude_mm": 1, "speed_mm_s": 1, "cycles": 1.5}), "programme.cycles",
     "whole number"),
    (_with(programme={"type": "bisine", "components": [{"amplitude_mm": 1}]}), "programme.components",
     "amplitude_mm and frequency_hz"),
    (_with(programme={"type": "bisine", "components": [{"amplitude_mm": 1, "frequency_hz": 1}], "cycles": 2,
                      "duration_s": 3}), "programme.duration_s", "not both"),
    (_with(programme={"type": "firtree", "step_mm": 0.7}), "programme.step_mm", "whole multiple"),
    (_with(programme={"type": "sweep", "amplitudes_mm": [], "frequencies_hz": [1]}), "programme.amplitudes_mm",
     "non-empty list"),
])
def test_bench_errors_name_file_and_key(data, key, message):
    with pytest.raises(InputError) as err:
        parse_bench(data, "bench.yaml")
    text = str(err.value)
    assert text.startswith("bench.yaml") and key in text and message in text, text


def test_inline_params_equal_the_named_set():
    named = parse_bench(GOOD, "a.yaml")
    inline = parse_bench(_with(params={**INLINE, "N": 15}), "b.yaml")
    assert named.channel == inline.channel
    assert parse_bench(_with(model="sts"), "c.yaml").channel.Co == 0.0  # the set read as another model


# --- the command ------------------------------------------------------------------------------

# Per example file, changes that keep the run short while exercising the same programme type.
SHORTEN = {
    "firtree.yaml": {"hold_s": 0.5, "cycles": 1},
    "relaxation.yaml": {"hold_s": 2.0},
    "triangle_slow.yaml": {"cycles": 1, "amplitude_mm": 0.5},
    "sweep.yaml": {"amplitudes_mm": [0.1, 1.0], "frequencies_hz": [1, 100], "points_per_cycle": 200},
}


@pytest.mark.parametrize("name", sorted(p.name for p in BENCH_DIR.glob("*.yaml")))
def test_every_example_bench_runs_and_writes_its_columns(tmp_path, name):
    data = yaml.safe_load((BENCH_DIR / name).read_text())
    data["programme"].update(SHORTEN.get(name, {}))
    bench = tmp_path / name
    bench.write_text(yaml.safe_dump(data))
    out = tmp_path / "out" / "result.csv"
    plot = name in ("relaxation.yaml", "sweep.yaml", "bisine.yaml")
    argv = ["bushing", "run", str(bench), "-o", str(out)] + (["--plot", str(tmp_path / "png")] if plot else [])
    assert main(argv) == 0
    with out.open() as handle:
        rows = list(csv.reader(handle))
    sweep = data["programme"]["type"] == "sweep"
    expected = ["amplitude_mm", "frequency_hz", "k_dyn_n_per_mm", "tan_delta"] if sweep else ["t_s", "e_mm", "F_N"]
    assert rows[0] == expected
    values = np.array(rows[1:], dtype=float)
    assert np.all(np.isfinite(values))
    if sweep:
        assert len(values) == 4 and np.all(values[:, 2] > 500)
    else:
        assert np.max(np.abs(values[:, 2])) > 10.0  # a force in N came out
    if plot:
        assert sorted(p.name for p in (tmp_path / "png").iterdir()) == (
            [f"{bench.stem}_sweep.png"] if sweep else [f"{bench.stem}_loop.png", f"{bench.stem}_time.png"])


def test_relaxation_bench_relaxes_and_sts_does_not(tmp_path):
    data = {**GOOD, "programme": {"type": "step", "amplitude_mm": 0.7, "rise_time_s": 0.1, "hold_s": 5.0}}
    table = run_bench(parse_bench(data, "b.yaml"))
    hold = table["F_N"][table["t_s"] >= 0.1 - 1e-9]
    assert np.all(np.diff(hold) <= 1e-9) and hold[-1] < 0.95 * hold[0]
    sts = run_bench(parse_bench({**data, "model": "sts"}, "b.yaml"))["F_N"][table["t_s"] >= 0.1 - 1e-9]
    np.testing.assert_allclose(sts, sts[0], rtol=1e-12)


def test_bad_input_exits_2_and_writes_nothing(tmp_path, capsys):
    bench = tmp_path / "bad.yaml"
    bench.write_text(yaml.safe_dump({**GOOD, "programme": {"type": "csv", "path": "missing.csv"}}))
    out = tmp_path / "out.csv"
    assert main(["bushing", "run", str(bench), "-o", str(out)]) == 2
    assert "missing.csv" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == [bench]


def test_atomic_output_keeps_the_old_file_on_failure(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_output(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("interrupted")
    assert target.read_text() == "old" and list(tmp_path.iterdir()) == [target]


def test_bushing_group_has_run_and_fit():
    args = build_parser().parse_args(["bushing", "run", "b.yaml", "-o", "o.csv"])
    assert args.bench == "b.yaml" and args.plot is None
    args = build_parser().parse_args(["bushing", "fit", "r.csv", "--bushing-model", "sts"])
    assert args.bushing_command == "fit" and args.records == [Path("r.csv")] and args.bushing_model == "sts"


def test_load_bench_reads_a_file(tmp_path):
    path = tmp_path / "b.yaml"
    path.write_text(yaml.safe_dump(GOOD))
    bench = load_bench(path)
    assert bench.programme.kind == "sine" and len(bench.programme.t_s) == 201
