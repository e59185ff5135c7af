"""Adams bushing property files (issue 51, item 1): a hand-written ``.bus`` read in any of Adams's
units, run on the bench and in a vehicle, its errors at their line; laws of ours exported and read
back, with what the export loses measured."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st
from scipy.interpolate import PchipInterpolator

import elastokin
from elastokin.bushings.adams_bus import read_bus
from elastokin.bushings.bench.bench_file import load_bench, run_bench
from elastokin.bushings.bench.bus_export import compare, export, law_of
from elastokin.bushings.parameter_sets import load_parameter_set
from elastokin.cli.main import main
from elastokin.core.errors import InputError
from elastokin.core.shipped import PARAMETER_SET_DIR

ROOT = Path(__file__).resolve().parents[1]
#: A hand-written file in mm, N, degrees: six curves (one without its {disp force} line), damping.
HAND = """$---------------------------------------------------------------------MDI_HEADER
[MDI_HEADER]
 FILE_TYPE     =  'bus'
 FILE_VERSION  =  4.0
 FILE_FORMAT   =  'ASCII'
(COMMENTS)
{comment_string}
'hand-written: a lower arm front bushing'
[UNITS]
 LENGTH = 'mm'
 ANGLE  = 'degrees'
 FORCE  = 'newton'
 MASS   = 'kg'
 TIME   = 'second'
[SHAPE]
{radius width}
 45.0  0.0
 45.0 30.0
[DAMPING]
 FX_DAMPING = 0.5   $ N.s/mm
 FY_DAMPING = 0.5
 FZ_DAMPING = 0.3
 TX_DAMPING = 20.0  $ N.mm.s/deg
 TY_DAMPING = 20.0
 TZ_DAMPING = 10.0
[FX_CURVE]
{ disp force }
 -10.0 -12000.0
  -6.0  -5200.0
  -3.0  -2300.0
   0.0      0.0
   3.0   2300.0
   6.0   5200.0
  10.0  12000.0
[FY_CURVE]
 -10.0 -12000.0
  -6.0  -5200.0
  -3.0  -2300.0
   0.0      0.0
   3.0   2300.0
   6.0   5200.0
  10.0  12000.0
[FZ_CURVE]
{ disp force }
 -8.0 -6000.0
  0.0     0.0
  8.0  6000.0
[TX_CURVE]
{ angle torque }
 -20.0 -40000.0
   0.0      0.0
  20.0  40000.0
[TY_CURVE]
{ angle torque }
 -10.0 -60000.0
   0.0      0.0
  10.0  60000.0
[TZ_CURVE]
{ angle torque }
 -10.0 -60000.0
   0.0      0.0
  10.0  60000.0
"""
FX = np.array([[-10.0, -12000.0], [-6.0, -5200.0], [-3.0, -2300.0], [0.0, 0.0], [3.0, 2300.0], [6.0, 5200.0],
               [10.0, 12000.0]])


def _write(folder: Path, text: str = HAND, name: str = "hand.bus") -> Path:
    (folder / name).write_text(text)
    return folder / name


def _bench(folder: Path, programme: str, direction: str = "x") -> dict[str, np.ndarray]:
    (folder / "bench.yaml").write_text(f"params: hand.bus\ndirection: {direction}\ndt_s: 0.001\nprogramme: {programme}\n")
    return run_bench(load_bench(folder / "bench.yaml"))


def test_a_hand_written_file_on_the_bench_gives_its_curve_and_its_damping(tmp_path: Path) -> None:
    _write(tmp_path)
    slow = _bench(tmp_path, "{type: triangle, amplitude_mm: 10.0, speed_mm_s: 1.0, cycles: 1}")
    e, force = slow["e_mm"], slow["F_N"]
    for x, f in FX:   # at the curve's points, less the dashpot's 0.5 N.s/mm at 1 mm/s
        at = np.flatnonzero(np.isclose(e, x, atol=1e-9))
        assert at.size, x
        moving = np.sign(e[at] - e[at - 1])
        assert np.all(np.abs(force[at] - 0.5 * moving - f) <= 0.005 * abs(f) + 1e-6), (x, force[at], f)
    # the damping: two speeds at one deflection differ by c·Δv
    fast = _bench(tmp_path, "{type: triangle, amplitude_mm: 10.0, speed_mm_s: 20.0, cycles: 1}")
    for x in (1.5, 4.5, 7.0):   # on the first rise, 0 to +10 mm
        rising = [np.interp(x, r["e_mm"][1:np.argmax(r["e_mm"]) + 1], r["F_N"][1:np.argmax(r["e_mm"]) + 1])
                  for r in (slow, fast)]
        assert rising[1] - rising[0] == pytest.approx(0.5 * (20.0 - 1.0), rel=1e-6)
    # between the points: the monotone cubic through them (PCHIP; its end slopes are the end segments' here,
    # scipy's another's: compared from 0 to 6 mm, between interior points)
    x = np.linspace(0.1, 5.9, 25)
    up = slice(1, np.argmax(e) + 1)
    np.testing.assert_allclose(np.interp(x, e[up], force[up]) - 0.5, PchipInterpolator(*FX.T)(x), rtol=1e-6, atol=1e-6)


def test_the_same_law_in_any_of_adams_units_and_with_or_without_table_headers(tmp_path: Path) -> None:
    base = read_bus(_write(tmp_path))
    converted = (HAND.replace("LENGTH = 'mm'", "LENGTH = 'meter'").replace("FORCE  = 'newton'", "FORCE  = 'kilonewton'")
                 .replace("ANGLE  = 'degrees'", "ANGLE  = 'radians'"))
    lines = []
    section = ""
    for line in converted.splitlines():
        section = line.strip("[]") if line.startswith("[") else section
        cells = line.split()
        if section.endswith("_CURVE") and len(cells) == 2 and not line.startswith("{"):
            x, f = float(cells[0]), float(cells[1])
            rotation = section.startswith("T")
            # m and kN; radians and kN·m
            line = f" {x * math.pi / 180 if rotation else x / 1e3!r} {f / 1e6 if rotation else f / 1e3!r}"
        if section == "DAMPING" and "=" in line:
            key, value = line.split("=")[0], float(line.split("=")[1].split("$")[0])
            rotation = key.strip().startswith("T")
            # N·s/mm → kN·s/m; N·mm·s/deg → kN·m·s/rad
            line = f"{key}= {value * 180 / math.pi / 1e6 if rotation else value!r}"
        lines.append(line)
    other = read_bus(_write(tmp_path, "\n".join(lines).replace("{ disp force }", "").replace("{ angle torque }", ""),
                            "other.bus"))
    for d in ("x", "y", "z", "rx", "ry", "rz"):
        a, b = base.parameter_set(d).channel(), other.parameter_set(d).channel()
        np.testing.assert_allclose(np.array(a.curve), np.array(b.curve), rtol=1e-12, atol=1e-12)
        assert a.C == pytest.approx(b.C, rel=1e-12) and a.K0 == pytest.approx(b.K0, rel=1e-12)
    ry = base.parameter_set("ry").channel()
    assert ry.K0 == pytest.approx(6.0 * 180 / math.pi) and ry.C == pytest.approx(0.02 * 180 / math.pi)   # N·m/rad


@pytest.mark.parametrize("old, new, expected", [
    ("  -3.0  -2300.0\n   0.0      0.0\n   3.0   2300.0\n   6.0   5200.0", "  -3.0  -2300.0\n   0.0      0.0\n   3.0   "
     "2300.0\n   6.0   2200.0", r"hand\.bus:33: \[FX_CURVE\] row 6: force falls from 2300 to 2200"),
    ("LENGTH = 'mm'", "LENGTH = 'furlong'", r"hand\.bus:10: \[UNITS\] LENGTH: unknown unit 'furlong'; expected one of mm"),
    (" FZ_DAMPING = 0.3", " FZ_DAMPING = -0.3", r"hand\.bus:22: \[DAMPING\] FZ_DAMPING: -0\.3: expected a damping of at "
                                                r"least 0"),
    (" FZ_DAMPING = 0.3", " FZ_DAMP = 0.3", r"hand\.bus:22: \[DAMPING\] FZ_DAMP: unknown key; expected FX_DAMPING"),
    ("FILE_TYPE     =  'bus'", "FILE_TYPE     =  'tir'", r"hand\.bus:3: \[MDI_HEADER\] FILE_TYPE: 'tir'; expected 'bus'"),
    ("[SHAPE]", "[SHAPES]", r"hand\.bus:15: unknown section \[SHAPES\]"),
    (" 0.0     0.0\n  8.0  6000.0", " 0.0     30.0\n  8.0  6000.0",
     r"hand\.bus:46: \[FZ_CURVE\] row 2: force 30 at zero deflection; expected the point \(0, 0\)"),
    (" 0.0     0.0\n  8.0  6000.0", " 0.5     0.0\n  8.0  6000.0",
     r"hand\.bus:43: \[FZ_CURVE\]: no point at zero deflection; expected the point \(0, 0\)"),
    ("  -3.0  -2300.0\n   0.0      0.0\n   3.0   2300.0", "  -3.0  0.0\n   0.0      0.0\n   3.0   2300.0",
     r"hand\.bus:31: \[FX_CURVE\] row 4: force stays from 0 to 0; expected a force that rises \(a falling or flat "
     r"stretch has no stiffness: a dead band is the backlash effect\)"),   # zero stiffness at design: refused
    ("   0.0      0.0\n   3.0   2300.0\n   6.0   5200.0", "   0.0      0.0\n(COMMENTS)\n   3.0   2300.0\n   6.0   5200.0",
     r"hand\.bus:33: \[FX_CURVE\]: a row of numbers after the table of \[FX_CURVE\] ended"),
    ("  -3.0  -2300.0\n   0.0      0.0", "  -1e-300  -2300.0\n   0.0      0.0",
     r"hand\.bus:31: \[FX_CURVE\] row 4: a slope of 2\.3e\+303 to this point; expected at most 1e\+09"),
    (" -10.0 -12000.0\n  -6.0  -5200.0", " -10.0 -12000.0 1.0\n  -6.0  -5200.0",
     r"hand\.bus:28: \[FX_CURVE\]: expected a row of 2 numbers"),
])
def test_a_bad_file_is_refused_at_its_line(tmp_path: Path, old: str, new: str, expected: str) -> None:
    assert old in HAND
    with pytest.raises(InputError, match=expected):
        read_bus(_write(tmp_path, HAND.replace(old, new, 1)))


def test_errors_quote_the_files_numbers_and_a_vehicle_names_the_row(tmp_path: Path) -> None:
    metres = HAND.replace("LENGTH = 'mm'", "LENGTH = 'meter'").replace("  -6.0  -5200.0", "  -0.002  -5200.0", 1)
    with pytest.raises(InputError, match=r"hand\.bus:30: \[FX_CURVE\] row 3: deflection -3 does not follow -0\.002"):
        read_bus(_write(tmp_path, metres))
    _write(tmp_path, HAND.replace("   6.0   5200.0", "   6.0   2200.0", 1))
    (tmp_path / "car.yaml").write_text((ROOT / "models/vehicles/c_segment.yaml").read_text().replace(
        "      y:  {set: fig5_7_lowloss}                                  # radial (Bourgeteau fig. 5.7)",
        "      y:  {property_file: hand.bus}", 1))
    with pytest.raises(InputError, match=r"car\.yaml:\d+: bushings\[0\]\.directions\.y\.property_file: .*hand\.bus:33: "
                                         r"\[FX_CURVE\] row 6: force falls from 2300 to 2200"):
        elastokin.load_vehicle(tmp_path / "car.yaml")


def test_time_units_and_the_other_damping_keys(tmp_path: Path) -> None:
    """TDX ... RDZ read as FX_DAMPING ... TZ_DAMPING; a damping in N·ms/mm is a thousandth of one in N·s/mm."""
    base = read_bus(_write(tmp_path))
    other = HAND.replace("TIME   = 'second'", "TIME   = 'millisecond'").replace("MASS   = 'kg'", "MASS   = 'tonne'")
    for new, old in zip(("TDX", "TDY", "TDZ", "RDX", "RDY", "RDZ"), ("FX", "FY", "FZ", "TX", "TY", "TZ")):
        other = other.replace(f" {old}_DAMPING =", f" {new} =")
    other = read_bus(_write(tmp_path, other, "other.bus"))
    for d in ("x", "y", "z", "rx", "ry", "rz"):
        assert other.directions[d].damping == pytest.approx(base.directions[d].damping / 1e3, rel=1e-12)
        assert other.directions[d].curve == base.directions[d].curve
    twice = HAND.replace(" FX_DAMPING = 0.5   $ N.s/mm", " FX_DAMPING = 0.5\n TDX = 0.5")
    with pytest.raises(InputError, match=r"\[DAMPING\] TDX: direction x already has its damping"):
        read_bus(_write(tmp_path, twice, "twice.bus"))


@pytest.mark.parametrize("option, value", [("--range", "0"), ("--range", "nan"), ("--damping-hz", "0"),
                                           ("--damping-at", "-1")])
def test_export_refuses_options_that_are_not_positive(tmp_path: Path, capsys, option: str, value: str) -> None:
    assert main(["bushing", "export", "fig5_9", "-o", str(tmp_path / "f.bus"), option, value]) == 2
    assert f"{option}: expected a positive number" in capsys.readouterr().err and not (tmp_path / "f.bus").exists()


def test_a_vehicle_takes_a_property_file_per_bushing_or_per_direction(tmp_path: Path) -> None:
    bus = _write(tmp_path)
    text = (ROOT / "models/vehicles/c_segment.yaml").read_text()
    text = text.replace("property_file: 195_65R15", f"property_file: {ROOT / 'models/tyres/195_65R15.tir'}")
    per_direction = text.replace("      y:  {set: fig5_7_lowloss}                                  # radial "
                                 "(Bourgeteau fig. 5.7)", "      y:  {property_file: hand.bus}", 1)
    assert per_direction != text
    (tmp_path / "car.yaml").write_text(per_direction)
    car = elastokin.load_vehicle(tmp_path / "car.yaml")
    e1 = next(b for b in car.definition.bushings if b.name == "e1_front")
    assert e1.directions["y"].channel() == read_bus(bus).parameter_set("y").channel()
    assert e1.directions["z"].set_name == "fig5_7_lowloss"
    # the whole bushing from the file: no directions given
    start = text.index("  - name: e1_front")
    block = text[start:text.index("  - name: e2_front")]
    whole = text.replace(block, block[:block.index("    directions:")] + "    property_file: hand.bus\n")
    (tmp_path / "whole.yaml").write_text(whole)
    e1 = next(b for b in elastokin.load_vehicle(tmp_path / "whole.yaml").definition.bushings if b.name == "e1_front")
    assert {d: e1.directions[d].channel().K0 for d in ("x", "rz")} == pytest.approx(
        {"x": 2300.0 / 3.0 * 1e3, "rz": 6.0 * 180 / math.pi}, rel=1e-9)   # the curves' slopes at zero [N/m, N·m/rad]
    run = elastokin.Simulation(car, "pumping", duration_scale=0.05).run()
    deflection, force = run["e1_front_left_y_deflection"] * 1e3, run["e1_front_left_y_force"]   # mm, N
    assert np.abs(deflection).max() > 1.0   # the bushing moved
    # with the laws on (the car settles on linear bushings first) and where it moves slowly (below 2 mm/s:
    # the dashpot's 1 N and the coupling's step of lag aside), its force is the file's curve
    slow = (run["phase"] >= 1) & (np.abs(np.gradient(deflection, run.t_s)) < 2.0)
    curve = PchipInterpolator(*np.array(read_bus(bus).directions["y"].curve).T)
    assert slow.sum() > 50 and np.abs(force - curve(deflection))[slow].max() <= 0.01 * np.abs(force).max()

def test_an_exported_law_reads_back_and_keeps_its_loss_at_the_matched_point(tmp_path: Path, capsys) -> None:
    law = load_parameter_set("fig5_9").channel()
    made = export(law, "x", 2.0, damping_hz=1.0, damping_amplitude=1.0)
    assert main(["bushing", "export", "fig5_9", "-o", str(tmp_path / "f.bus")]) == 0
    back = read_bus(tmp_path / "f.bus")
    assert set(back.directions) == {"x", "y", "z"}
    np.testing.assert_allclose(np.array(back.directions["z"].curve), np.array(made.direction.curve), rtol=1e-7)
    assert back.directions["z"].damping == pytest.approx(made.direction.damping, rel=1e-7)
    text = (tmp_path / "f.bus").read_text()
    assert "not carried: hysteresis at vanishing rates, relaxation, the Payne effect" in text and "law tan delta" in text
    side = compare(law, made)
    matched = (side.frequencies_hz.index(1.0), side.amplitudes.index(1.0))
    loss = {k: side.k_dyn[k][matched] * side.tan_delta[k][matched] / math.hypot(1.0, side.tan_delta[k][matched])
            for k in ("law", "export")}
    assert loss["export"] == pytest.approx(loss["law"], rel=0.01)   # Im K* matched at 1 Hz, 1 mm
    assert side.loop_width["law"] > 10 * side.loop_width["export"] > 0   # the slow loop's hysteresis is lost
    assert main(["bushing", "import", str(tmp_path / "f.bus"), "-o", str(tmp_path / "sets")]) == 0
    assert load_parameter_set(tmp_path / "sets" / "f_x.yaml").channel() == law_of(back.directions["x"])
    assert main(["bushing", "import", str(tmp_path / "f.bus"), "-o", str(tmp_path / "sets")]) == 2
    assert "pass --overwrite to replace it" in capsys.readouterr().err

@pytest.mark.parametrize("name", sorted(p.name for p in PARAMETER_SET_DIR.glob("*.bus")))
def test_the_shipped_property_files_read(name: str) -> None:
    bus = read_bus(PARAMETER_SET_DIR / name)
    assert set(bus.directions) == {"x", "y", "z"} and bus.comments[0].startswith("written by vsim")


SHIPPED = (PARAMETER_SET_DIR / "fig5_9.bus").read_text().splitlines() + HAND.splitlines()
_TOKENS = st.sampled_from(["", "nan", "inf", "1e400", "-1e300", "abc", "'x'", "{a b c}", "[FX_CURVE]", "(COMMENTS)",
                           "0", "-0", "1D+03", "$", "!", "=", "FX_DAMPING =", "\ufeff", "'", "{", "}"])


@given(st.lists(st.tuples(st.sampled_from(["drop", "repeat", "replace", "insert", "swap"]), st.integers(0, 10 ** 6),
                          _TOKENS), min_size=1, max_size=4),
       st.integers(0, 10 ** 6))
@settings(max_examples=300, deadline=None, database=None, suppress_health_check=list(HealthCheck))
@seed(20261202)
def test_a_damaged_or_hostile_file_is_refused_or_read_never_a_traceback(tmp_path_factory, edits, cut) -> None:
    """Lines of the shipped and the hand-written files dropped, repeated, swapped, replaced or
    joined by hostile tokens, and the file cut anywhere: an InputError or a law that loads."""
    lines = list(SHIPPED)
    for action, at, token in edits:
        i = at % len(lines)
        if action == "drop" and len(lines) > 1:
            del lines[i]
        elif action == "repeat":
            lines.insert(i, lines[i])
        elif action == "replace":
            cells = lines[i].split()
            lines[i] = " ".join(cells[:1] + [token] + cells[2:]) if cells else token
        elif action == "insert":
            lines.insert(i, token)
        else:
            j = (at // 7) % len(lines)
            lines[i], lines[j] = lines[j], lines[i]
    text = "\n".join(lines)
    path = tmp_path_factory.mktemp("fuzz") / "f.bus"
    path.write_text(text[:cut % (len(text) + 1)], encoding="utf-8", errors="surrogatepass")
    try:
        bus = read_bus(path)
    except InputError as error:
        assert str(error).strip()
        return
    for d in bus.directions:
        channel = bus.parameter_set(d).channel()
        assert np.all(np.isfinite(np.array(channel.curve))) and channel.K0 > 0.0


def test_a_fit_keeps_a_property_files_curve_as_its_elastic_law(tmp_path: Path, capsys) -> None:
    """`vsim bushing fit --elastic F.bus`: the ladder fitted beside the file's curve, held, to records
    of an STVS whose elastic law is that curve (fig5_9's ladder), recovers the ladder."""
    from elastokin.bushings.bench.records import simulate_record
    from elastokin.bushings.bench.programmes import sine, triangle
    from elastokin.bushings.parameters import to_si
    from elastokin.core.tables import write_csv_columns

    bus = read_bus(_write(tmp_path))
    ladder = {"N": 15, "Kpa": 1051.0, "Kr": 2951.0, "Ff": 9.0, "Co": 32.0, "pw": 0.15}
    truth = to_si("stvs", {**ladder, "curve": bus.parameter_set("y").values["curve"]})
    for name, (t, e) in {"tri": triangle(2e-3, 0.333e-3, 2, 0.01), "sin": sine(1e-3, 1.0, 3, 0.005)}.items():
        write_csv_columns(tmp_path / f"{name}.csv", {"t_s": t, "e_mm": e * 1e3,
                                                     "F_N": simulate_record([truth], t, e)[:, 0]})
    assert main(["bushing", "fit", str(tmp_path / "tri.csv"), str(tmp_path / "sin.csv"), "--elastic",
                 str(tmp_path / "hand.bus"), "--direction", "y", "-o", str(tmp_path / "fitted.yaml")]) == 0
    assert "elastic law: the curve of 7 points from -10 to 10 mm (held)" in capsys.readouterr().out
    fitted = load_parameter_set(tmp_path / "fitted.yaml")
    assert fitted.values["curve"] == [list(p) for p in bus.directions["y"].curve] and "K0" not in fitted.values
    assert fitted.values["Kpa"] == pytest.approx(ladder["Kpa"], rel=0.01)
    assert fitted.values["Kr"] == pytest.approx(ladder["Kr"], rel=0.01)
    with pytest.raises(InputError, match="give the elastic law as K0 .* or as a curve, not both"):
        to_si("stvs", {**ladder, "K0": 500.0, "curve": [[0.0, 0.0], [1.0, 100.0]]})


def test_a_whole_bushings_curve_as_the_elastic_law_leaves_no_ladder_and_says_so(tmp_path: Path, capsys) -> None:
    """The shipped fig5_9.bus is the centre line of fig5_9's whole slow loop (725 N/mm at 1 mm against
    its K0 of 508): held as the parallel spring beside a ladder fitted to fig5_9's own records, it
    already holds the ladder's stiffness (thesis eq. 5.9), so the fit drives the ladder's Kr towards
    nothing; the fit ends (its logs bounded, no parameter reaches 0) and the report says why."""
    from elastokin.bushings.bench.programmes import sine, triangle
    from elastokin.bushings.bench.records import simulate_record
    from elastokin.core.tables import write_csv_columns

    truth = load_parameter_set("fig5_9")
    for name, (t, e) in {"tri": triangle(2e-3, 0.333e-3, 2, 0.01), "sin": sine(1e-3, 1.0, 3, 0.005)}.items():
        write_csv_columns(tmp_path / f"{name}.csv", {"t_s": t, "e_mm": e * 1e3,
                                                     "F_N": simulate_record([truth.channel()], t, e)[:, 0]})
    assert main(["bushing", "fit", str(tmp_path / "tri.csv"), str(tmp_path / "sin.csv"), "--elastic",
                 str(PARAMETER_SET_DIR / "fig5_9.bus"), "-o", str(tmp_path / "fitted.yaml")]) == 0
    assert "the held curve likely holds the ladder's stiffness already" in capsys.readouterr().out
    fitted = load_parameter_set(tmp_path / "fitted.yaml").values
    assert 0.0 < fitted["Kr"] < 1e-3 * truth.values["Kr"]


def test_a_set_with_both_elastic_laws_is_refused_read_as_another_model_too(tmp_path: Path) -> None:
    """K0 and a curve in one STVS set: refused from its file, and a set built so in code refused as
    STVS and as STS alike (reading as another model keeps one law only after the check, never
    silently the curve's slope for K0)."""
    import yaml

    from elastokin.bushings.parameter_sets import ParameterSet

    values = {"N": 15, "K0": 5000.0, "Kpa": 1051.0, "Kr": 2951.0, "Ff": 9.0, "Co": 32.0, "pw": 0.15,
              "curve": [[0.0, 0.0], [1.0, 500.0]]}
    path = tmp_path / "both.yaml"
    path.write_text(yaml.safe_dump({"model": "stvs", "source": "test", "params": values}))
    with pytest.raises(InputError, match="both.yaml: curve: .*not both"):
        load_parameter_set(path)
    both = ParameterSet("both", "stvs", "translation", values, "test")
    for model in (None, "sts"):
        with pytest.raises(InputError, match="not both"):
            both.channel(model)
