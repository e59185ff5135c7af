"""Scenario files: the default set validates, inputs in SI follow the conventions, and every kind of
bad input is reported with file, line or key, value and what was expected."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np
import pytest

from elastokin.vehicle.model.definition import CORNERS
from elastokin.vehicle.scenarios.channels import CORNER_TAGS, INPUT_CHANNELS, csv_columns
from elastokin.vehicle.scenarios.scenario import MAX_TIMESTEP_S, MIN_TIMESTEP_S
from elastokin.vehicle.scenarios.scenario_file import load_scenario, parse_scenario, with_case_values
from elastokin.vehicle.scenarios.schedule import check_timestep, output_interval, timestep
from elastokin.core.errors import InputError
from elastokin.core.shipped import DEFAULT_VEHICLE

SCENARIO_DIR = Path(__file__).resolve().parent.parent / "scenarios"
DEFAULT_SET = ("pumping", "roll", "lateral_force", "pumping_speeds", "rack_step", "double_rack_step_same",
               "double_rack_step_opposite")


def write(tmp_path: Path, text: str, name: str = "s.yaml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def column(channel: str) -> int:
    return INPUT_CHANNELS.index(channel)


@pytest.mark.parametrize("name", DEFAULT_SET)
def test_every_default_scenario_validates(name: str) -> None:
    s = load_scenario(SCENARIO_DIR / f"{name}.yaml")
    assert s.name == name and s.cases and s.vehicle.resolve() == DEFAULT_VEHICLE.resolve()
    assert s.settle.before_bushings_s == 1.0 and s.settle.before_input_s == 1.0
    for case in s.cases:
        u = case.inputs(np.linspace(0.0, case.duration_s, 50))
        assert u.shape == (50, len(INPUT_CHANNELS)) and np.all(np.isfinite(u))
        np.testing.assert_array_equal(u[0], 0.0)  # every input starts from rest


def test_a_scenario_parses_from_text_as_if_read_from_its_path(tmp_path: Path) -> None:
    """parse_scenario needs no file: text held in memory (a recording's, an inline one) reads as the
    file it stands for, its relative paths from that file's folder."""
    path = SCENARIO_DIR / "pumping.yaml"
    from_file, from_text = load_scenario(path), parse_scenario(path.read_text(), path)
    assert from_text == from_file
    text = "type: rack_step\nvehicle: car.yaml\ncases: [{rack_mm: 5, hold_s: 2}]\n"
    (tmp_path / "car.yaml").write_text(DEFAULT_VEHICLE.read_text())
    s = parse_scenario(text, tmp_path / "step.yaml", source="inline")
    assert (s.name, s.vehicle, s.path) == ("step", tmp_path / "car.yaml", tmp_path / "step.yaml")
    with pytest.raises(InputError, match=r"^inline:3: cases\[0\]\.rack_mm: expected a non-zero number, got 0$"):
        parse_scenario(text.replace("rack_mm: 5", "rack_mm: 0"), tmp_path / "step.yaml", source="inline")


def test_default_set_matches_the_thesis_programme() -> None:
    def peaks(name: str, channel: str) -> list[float]:
        s = load_scenario(SCENARIO_DIR / f"{name}.yaml")
        return [round(float(np.abs(c.inputs(np.linspace(0, c.duration_s, 4001))[:, column(channel)]).max()), 9)
                for c in s.cases]

    assert peaks("pumping", "pad_z_rl") == [0.01, 0.02, 0.03, 0.04, 0.05, 0.06]       # m
    assert peaks("roll", "pad_z_fr") == [0.01, 0.02, 0.03, 0.04, 0.05, 0.06]
    assert peaks("lateral_force", "pad_fy_fl") == [500.0, 1000.0, 1500.0, 2000.0, 2500.0, 3000.0]  # N
    speeds = load_scenario(SCENARIO_DIR / "pumping_speeds.yaml")
    assert [c.duration_s for c in speeds.cases] == pytest.approx([320.0, 160.0, 32.0])  # 2 × 4·60 mm / speed
    assert load_scenario(SCENARIO_DIR / "pumping.yaml").cases[0].duration_s == pytest.approx(20.0)  # 2 × 0.1 Hz
    same = load_scenario(SCENARIO_DIR / "double_rack_step_same.yaml").cases[0]
    opposite = load_scenario(SCENARIO_DIR / "double_rack_step_opposite.yaml").cases[0]
    end = np.array([same.duration_s])
    assert same.inputs(end)[0, column("rack")] == pytest.approx(0.015)
    assert opposite.inputs(end)[0, column("rack")] == pytest.approx(0.005)


def test_corner_order_is_the_rigs() -> None:
    assert tuple(CORNER_TAGS) == CORNERS


def test_signal_shapes_patterns_and_units(tmp_path: Path) -> None:
    roll = load_scenario(write(tmp_path, """
        type: roll
        axles: [rear]
        defaults: {speed_mm_s: 10, cycles: 2}
        cases: [{amplitude_mm: 20}]
    """))
    case = roll.cases[0]
    assert case.duration_s == pytest.approx(16.0) and case.cycles == 2
    u = case.inputs(np.array([2.0, 6.0, 8.0, 10.0, 100.0]))
    np.testing.assert_allclose(u[:, column("pad_z_rl")], [0.02, -0.02, 0.0, 0.02, 0.0], atol=1e-12)
    np.testing.assert_allclose(u[:, column("pad_z_rr")], -u[:, column("pad_z_rl")])
    assert not u[:, [column("pad_z_fl"), column("pad_z_fr")]].any()  # front axle not selected
    assert roll.x_quantity == "wheel_travel"

    torque = load_scenario(write(tmp_path, """
        type: aligning_torque
        cases: [{amplitude_Nm: 100, shape: sine, frequency_hz: 2}]
    """))
    u = torque.cases[0].inputs(np.array([0.125]))
    assert u[0, column("pad_mz_fr")] == pytest.approx(100.0) and torque.x_quantity == "pad_mz"

    bisine = load_scenario(write(tmp_path, """
        type: bisine
        defaults: {input: longitudinal_force, cycles: 1}
        cases: [{components: [{amplitude_daN: 10, frequency_hz: 0.5}, {amplitude_daN: 2, frequency_hz: 5}]}]
    """))
    c = bisine.cases[0]
    t = np.array([0.3])
    expected = 100.0 * math.sin(math.pi * 0.3) + 20.0 * math.sin(10 * math.pi * 0.3)
    assert c.duration_s == pytest.approx(2.0) and c.inputs(t)[0, column("pad_fx_rl")] == pytest.approx(expected)

    step = load_scenario(write(tmp_path, """
        type: rack_step
        cases: [{rack_mm: -4, hold_s: 2, rise_time_s: 0.1}]
    """))
    u = step.cases[0].inputs(np.array([0.05, 0.1, 2.1]))[:, column("rack")]
    np.testing.assert_allclose(u, [-0.002, -0.004, -0.004])
    assert step.axles == ("front",) and step.x_quantity is None


def test_csv_time_series_in_si(tmp_path: Path) -> None:
    (tmp_path / "in.csv").write_text("t_s,pad_z_fl_mm,pad_fy_rr_daN,rack_mm\n0,0,0,0\n1,10,20,0\n2,10,20,4\n")
    s = load_scenario(write(tmp_path, "type: csv\ncases: [{path: in.csv}]\n"))
    u = s.cases[0].inputs(np.array([0.5, 1.5, 5.0]))
    np.testing.assert_allclose(u[:, column("pad_z_fl")], [0.005, 0.01, 0.01])
    np.testing.assert_allclose(u[:, column("pad_fy_rr")], [100.0, 200.0, 200.0])
    np.testing.assert_allclose(u[:, column("rack")], [0.0, 0.002, 0.004])
    assert s.cases[0].duration_s == 2.0 and len(csv_columns()) == len(INPUT_CHANNELS)


@pytest.mark.parametrize("seed", range(3))
def test_a_run_steps_at_the_longest_step_that_divides_its_outputs_and_resolves_its_input(tmp_path: Path,
                                                                                       seed: int) -> None:
    """Drawn output rates and sine or triangle frequencies: the step divides the output interval
    exactly, is at most 2 ms, 1/20 of a sine period and 1/5 of a triangle's quarter period, and
    is the longest that does (one step fewer per interval would break a bound)."""
    rng = np.random.default_rng(seed)
    for _ in range(20):
        rate, frequency = float(rng.choice([50, 100, 200, 250, 300, 333.3, 1000, 7.0])), float(rng.uniform(0.05, 50))
        shape = str(rng.choice(["sine", "triangle"]))
        s = load_scenario(write(tmp_path, f"type: pumping\noutput_rate_hz: {rate}\ncases:\n"
                                          f"  - {{amplitude_mm: 10, shape: {shape}, frequency_hz: {frequency}}}\n"))
        h, interval = timestep(s), 1.0 / rate
        steps = interval / h
        bound = min(MAX_TIMESTEP_S, 1.0 / (20 * frequency) if shape == "sine" else 1.0 / (4 * frequency) / 5)
        assert abs(steps - round(steps)) < 1e-9 and output_interval(s, h) == round(steps), (rate, h)
        assert h <= bound * (1 + 1e-12), (rate, frequency, shape, h)
        assert round(steps) == 1 or interval / (round(steps) - 1) > bound, (rate, frequency, shape, h)
    shipped = {name: timestep(load_scenario(name)) for name in ("pumping", "rack_step")}
    assert shipped == pytest.approx({"pumping": 2e-3, "rack_step": 5e-3 / 3}, rel=1e-12)   # 50 and 200 Hz


def test_the_step_resolves_a_table_and_a_fast_ramp_down_to_its_floor(tmp_path: Path) -> None:
    """A CSV input sampled every 0.5 ms steps at 0.5 ms (a one-sample spike is not stepped over);
    a 1 µs ramp steps at the floor MIN_TIMESTEP_S, not at 0.2 µs; a step that does not divide
    the output interval is refused."""
    times = np.arange(0.0, 0.02, 5e-4)
    rows = "\n".join(f"{t:.4f},{5.0 if abs(t - 0.0100) < 1e-9 else 0.0},0,0" for t in times)
    (tmp_path / "in.csv").write_text("t_s,pad_z_fl_mm,pad_fy_rr_daN,rack_mm\n" + rows + "\n")
    table = load_scenario(write(tmp_path, "type: csv\noutput_rate_hz: 100\ncases: [{path: in.csv}]\n"))
    assert timestep(table) == pytest.approx(5e-4, rel=1e-12)
    fast = load_scenario(write(tmp_path, "type: rack_step\ncases: [{rack_mm: 5, hold_s: 1, rise_time_s: 1.0e-6}]\n",
                               "fast.yaml"))
    assert timestep(fast) == pytest.approx(MIN_TIMESTEP_S, rel=1e-12)   # 100 Hz: 100 steps of the floor
    with pytest.raises(ValueError, match="does not divide"):
        check_timestep(table, 3e-3)


BASE = """\
type: pumping
defaults:
  frequency_hz: 0.1
cases:
  - amplitude_mm: 10
"""


@pytest.mark.parametrize("text, line, key, words", [
    # unknown keys, at the top and inside a case
    (BASE + "colour: red\n", 6, "colour", ["unknown key 'colour'", "expected one of"]),
    (BASE + "  - amplitude_mm: 20\n    amplitde_mm: 3\n", 7, "cases[1].amplitde_mm", ["unknown key", "amplitude_mm"]),
    # wrong types
    (BASE.replace("amplitude_mm: 10", "amplitude_mm: ten"), 5, "cases[0].amplitude_mm",
     ["expected a finite number", "'ten'"]),
    (BASE + "axles: front\n", 6, "axles", ["expected a list", "'front'"]),
    ("type: pumping\ncases: {amplitude_mm: 10}\n", 2, "cases", ["expected a non-empty list"]),
    # bad values
    (BASE.replace("amplitude_mm: 10", "amplitude_mm: -10"), 5, "cases[0].amplitude_mm",
     ["expected a positive number", "-10"]),
    (BASE.replace("type: pumping", "type: bouncing"), 1, "type", ["expected one of pumping", "'bouncing'"]),
    (BASE + "output_rate_hz: 3000\n", 6, "output_rate_hz", ["expected at most 1000 Hz", "3000"]),
    (BASE + "bushings: stv\n", 6, "bushings", ["expected one of linear, sts, rt, stvs", "'stv'"]),
    (BASE + "  - {amplitude_mm: 5, shape: sine, speed_mm_s: 3, frequency_hz: null}\n", 6, "cases[1]",
     ["exactly one of frequency_hz or speed_mm_s"]),
    ("type: rack_step\naxles: [front]\ncases: [{rack_mm: 5, hold_s: 1}]\n", 2, "axles", ["no axle selection"]),
    (BASE + "vehicle: nowhere.yaml\n", 6, "vehicle", ["no such vehicle file", "nowhere.yaml"]),
    (BASE + "type: roll\n", 6, "type", ["duplicate key 'type'"]),
    # missing keys
    (BASE.replace("amplitude_mm: 10", "cycles: 2"), 5, "cases[0].amplitude_mm", ["missing key"]),
    ("type: pumping\n", 1, "cases", ["missing key"]),
    ("type: rack_step\ncases:\n  - rack_mm: 5\n", 3, "cases[0].hold_s", ["missing key"]),
])
def test_validation_errors_name_file_line_key_and_value(tmp_path: Path, text: str, line: int, key: str,
                                                          words: list[str]) -> None:
    path = write(tmp_path, text)
    with pytest.raises(InputError) as err:
        load_scenario(path)
    message = str(err.value)
    assert message.startswith(f"{path}:{line}: {key}: "), message
    for word in words:
        assert word in message, message


def test_unknown_key_in_defaults_names_its_line(tmp_path: Path) -> None:
    path = write(tmp_path, BASE.replace("  frequency_hz: 0.1", "  frequency_hz: 0.1\n  hold_s: 3"))
    with pytest.raises(InputError, match=rf"^{path}:4: defaults.hold_s: unknown key 'hold_s'"):
        load_scenario(path)


def test_invalid_yaml_and_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="not valid YAML"):
        load_scenario(write(tmp_path, "type: [pumping\n"))
    with pytest.raises(InputError, match="no such scenario file"):
        load_scenario(tmp_path / "absent.yaml")


@pytest.mark.parametrize("content, where, words", [
    ("t_s,pad_z_fl_mm,speed\n0,0,0\n1,1,1\n", "line 1", ["unknown column 'speed'", "pad_z_fl_mm"]),
    ("t_s,pad_z_fl_mm\n0,0\n1,abc\n", "line 3, column pad_z_fl_mm", ["expected a number", "'abc'"]),
    ("t_s,pad_z_fl_mm\n0,0\n1,nan\n", "line 3, column pad_z_fl_mm", ["expected a finite number", "'nan'"]),
    ("t_s,pad_z_fl_mm\n0,0\n1,1\n1,2\n", "line 4, column t_s", ["time must increase strictly", "1.0 s"]),
    ("t_s,pad_z_fl_mm\n0.5,0\n1,1\n", "first data line, column t_s", ["expected the inputs to start at t_s = 0",
                                                                      "0.5"]),
    ("t_s,pad_z_fl_mm\n0,0\n1\n", "line 3, column pad_z_fl_mm", ["missing value"]),
    ("pad_z_fl_mm\n0\n1\n", "line 1", ["missing column(s) t_s"]),
    ("t_s\n0\n1\n", "line 1", ["expected t_s and at least one input column"]),
])
def test_bad_csv_names_file_line_and_column(tmp_path: Path, content: str, where: str, words: list[str]) -> None:
    csv_path = tmp_path / "in.csv"
    csv_path.write_text(content)
    with pytest.raises(InputError) as err:
        load_scenario(write(tmp_path, "type: csv\ncases: [{path: in.csv}]\n"))
    message = str(err.value)
    assert message.startswith(f"{csv_path}: {where}: "), message
    for word in words:
        assert word in message, message


def test_missing_csv_names_the_scenario_key(tmp_path: Path) -> None:
    path = write(tmp_path, "type: csv\ncases:\n  - path: gone.csv\n")
    with pytest.raises(InputError, match=rf"^{path}:3: cases\[0\].path: no such CSV file"):
        load_scenario(path)


def test_a_step_experiments_control_is_the_same_input_without_its_last_step() -> None:
    """Case.without_last_step: a double rack step's control holds the first level through the second
    hold (identical before the second ramp); a single step's control stays at rest; a sine has no step."""
    double = load_scenario("double_rack_step_same").cases[0]
    control = double.without_last_step()
    t = np.linspace(0.0, double.duration_s, 2001)
    first = double.parameters["first_mm"] * 1e-3
    before_second = t <= double.waveform.times_s[2]
    assert np.array_equal(control.inputs(t)[before_second], double.inputs(t)[before_second])
    rack = control.inputs(t)[:, INPUT_CHANNELS.index("rack")]
    assert np.allclose(rack[~before_second], first) and control.duration_s == double.duration_s
    single = load_scenario("rack_step").cases[0].without_last_step()
    assert not np.any(single.inputs(t))
    with pytest.raises(ValueError, match="no last ramp"):
        load_scenario("pumping").cases[0].without_last_step()


def test_a_value_set_in_every_case_ramps_each_step_over_it_and_a_key_the_cases_lack_is_refused() -> None:
    """with_case_values: each step of a double rack step ramped in 0.5 s instead of 0.05 (its level
    reached 0.5 s after each ramp starts, half of it a quarter of a second in: a linear ramp), the
    holds as they were; the changed text is the scenario's; a key its cases do not take names it."""
    shipped = load_scenario("double_rack_step_opposite")
    slow = with_case_values(shipped, {"rise_time_s": 0.5}, "slow steps")
    case, before = slow.cases[0], shipped.cases[0]
    np.testing.assert_allclose(np.diff(case.waveform.times_s)[1::2], np.diff(before.waveform.times_s)[1::2])
    assert case.waveform.values == before.waveform.values   # the same levels, reached more slowly
    rack = INPUT_CHANNELS.index("rack")
    for start, level, previous in ((0.0, case.waveform.values[1], 0.0),
                                   (case.waveform.times_s[2], case.waveform.values[3], case.waveform.values[1])):
        at = case.inputs(np.array([start + 0.25, start + 0.5]))[:, rack]
        np.testing.assert_allclose(at, [0.5 * (previous + level), level], rtol=1e-12)
    assert case.duration_s == pytest.approx(before.duration_s + 2 * 0.45)
    assert "rise_time_s: 0.5" in slow.text and slow.path == shipped.path
    with pytest.raises(InputError, match=r"^slow steps:\d+: .*amplitude_mm"):
        with_case_values(shipped, {"amplitude_mm": 1.0}, "slow steps")
