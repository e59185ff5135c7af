"""Parameter sets: unit conversion at the boundary, provenance, and clear errors on bad input."""

from __future__ import annotations

import math

import pytest

from elastokin.bushings import available_parameter_sets, load_parameter_set, to_si
from elastokin.core.errors import InputError


def test_shipped_sets_load_with_their_source():
    names = available_parameter_sets()
    assert {"fig3_14", "fig5_6", "fig5_7_lowloss", "fig5_8", "fig5_9", "fig5_8_caption", "fig5_9_caption", "table3_2"} <= set(names)
    for name in names:
        pset = load_parameter_set(name)
        assert "Bourgeteau 2009" in pset.source
        pset.channel()


def test_thesis_units_convert_to_si_once():
    ch = load_parameter_set("fig5_9_caption").channel()
    assert ch.K0 == pytest.approx(508.2e3) and ch.Kpa == pytest.approx(1076.7e3) and ch.Kr == pytest.approx(2935e3)
    assert ch.Ff == 9.0 and ch.n_cells == 15 and ch.pw == 0.15
    # D = Co·|v|^pw: 32 N at 1 mm/s is 32 N at 1e-3 m/s.
    assert ch.Co * (1e-3) ** ch.pw == pytest.approx(32.0)
    el = load_parameter_set("table3_2").channel()
    assert (el.N_sup, el.S_inf, el.P_sup) == pytest.approx((2e-3, -8.4e-3, 156.0))


def test_rotational_sets_use_newton_metres_and_degrees():
    ch = to_si("stvs", {"K0": 10.0, "Kpa": 20.0, "Kr": 40.0, "Ff": 0.5, "Co": 1.0, "pw": 0.2}, "rotation")
    deg = math.pi / 180
    assert ch.K0 == pytest.approx(10.0 / deg)
    assert ch.Co * deg ** 0.2 == pytest.approx(1.0)


def test_reading_a_set_as_another_model():
    stvs = load_parameter_set("fig5_9_caption")
    assert stvs.channel("sts").Co == 0.0 and stvs.channel("sts").Ff == 9.0
    cont = load_parameter_set("fig3_14").channel("sts_continuous")
    assert cont.Ct == pytest.approx(2 * 30.0 * 990e3)
    with pytest.raises(InputError, match=r"fig3_14\.yaml: Co: missing parameter"):
        load_parameter_set("fig3_14").channel("rt")


@pytest.mark.parametrize("model,values,key,expected", [
    ("stvs_x", {"K0": 1.0}, "model", "unknown model"),
    ("sts", {"K0": 1.0, "Kpa": 1.0, "Kr": 1.0, "Ff": 1.0, "Kx": 2.0}, "Kx", "unknown parameter"),
    ("sts", {"K0": 1.0, "Kpa": 1.0, "Kr": 1.0}, "Ff", "missing parameter"),
    ("sts", {"K0": -5.0, "Kpa": 1.0, "Kr": 1.0, "Ff": 1.0}, "K0", "non-negative"),
    ("rt", {"K0": 1.0, "Kpa": 1.0, "Kr": 1.0, "Co": 1.0, "pw": 1.5}, "pw", r"0.03 <= pw <= 1"),
    ("rt", {"K0": 1.0, "Kpa": 1.0, "Kr": 1.0, "Co": 1.0, "pw": 0.0}, "pw", r"0.03 <= pw <= 1"),
    ("sts", {"K0": 1.0, "Kpa": 1.0, "Kr": 1.0, "Ff": 1.0, "N": 2.5}, "N", "whole number"),
    ("sts", {"K0": "stiff", "Kpa": 1.0, "Kr": 1.0, "Ff": 1.0}, "K0", "expected a number"),
    ("elastic", {"K0": 1.0, "N_sup": 2.0, "N_inf": -2.0, "S_sup": 1.0, "S_inf": -8.0, "P_sup": 1.0, "P_inf": 1.0},
     "N_sup", "S_inf < N_inf"),
])
def test_bad_parameters_name_the_file_key_and_expectation(model, values, key, expected):
    with pytest.raises(InputError, match=rf"bench\.yaml: {key}: .*{expected}"):
        to_si(model, values, "translation", source="bench.yaml")


def test_bad_set_files(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("model: sts\nparams: {K0: 1, Kpa: 1, Kr: 1, Ff: 1}\ncolour: red\n")
    with pytest.raises(InputError, match=r"bad\.yaml: colour: unknown key"):
        load_parameter_set(bad)
    bad.write_text("model: sts\nparams: [1, 2]\n")
    with pytest.raises(InputError, match=r"bad\.yaml: params: expected a mapping"):
        load_parameter_set(bad)
    with pytest.raises(InputError, match="no parameter set 'nope'; known sets: .*fig5_9"):
        load_parameter_set("nope")


def test_a_set_file_edited_between_loads_is_read_again_and_loads_do_not_share_state(tmp_path):
    path = tmp_path / "edited.yaml"
    path.write_text("model: sts\nparams: {K0: 1, Kpa: 1, Kr: 1, Ff: 1}\n")
    first = load_parameter_set(path)
    first.values["K0"] = 99.0                      # a caller's change stays with its copy
    assert load_parameter_set(path).values["K0"] == 1
    path.write_text("model: sts\nparams: {K0: 2, Kpa: 1, Kr: 1, Ff: 1}\n")  # same size, same instant
    assert load_parameter_set(path).values["K0"] == 2
