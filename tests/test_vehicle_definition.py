"""Vehicle YAML loading: the default car, and errors that name file, key and value."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from elastokin.bushings import load_parameter_set
from elastokin.vehicle.model.geometry import mirror_axes
from elastokin.vehicle.model.statics import axle_loads, resolve_preloads
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.core.errors import InputError
from elastokin.core.shipped import DEFAULT_VEHICLE


def test_default_car_is_plausible():
    v = load_vehicle()
    assert v.rear.hardpoints["wheel_centre"][0] == pytest.approx(-2.608)  # public 307 wheelbase
    assert 2 * v.front.hardpoints["wheel_centre"][1] == pytest.approx(1.49, abs=0.02)
    assert {b.name for b in v.bushings} == {"e1_front", "e2_front", "e1_rear"}
    weight, front, rear = axle_loads(v)
    assert front / weight == pytest.approx(0.60, abs=0.01)  # spec §1: ≈ 60 % front
    r = resolve_preloads(v)
    assert 2000.0 < r.front.spring.preload < 5000.0 and 1500.0 < r.rear.spring.preload < 5000.0
    for b in v.bushings:
        for sign in (1.0, -1.0):
            axes = mirror_axes(b.axes, sign)
            assert np.allclose(axes @ axes.T, np.eye(3), atol=1e-9)
            assert np.linalg.det(axes) == pytest.approx(1.0)


def _write(tmp_path: Path, edit) -> Path:
    data = yaml.safe_load(DEFAULT_VEHICLE.read_text())
    edit(data)
    path = tmp_path / "car.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize("edit, key, words", [
    (lambda d: d["body"].update(colour="red"), "body.colour", "unknown key"),
    (lambda d: d["tyre"].update(radius=-0.3), "tyre.radius", "positive"),
    (lambda d: d["front"]["hardpoints"].update(strut_top=[0, 0.5]), "front.hardpoints.strut_top", "3 numbers"),
    (lambda d: d["bushings"][0]["directions"].update(y={"set": "nope"}), "bushings[0].directions.y", "nope"),
    (lambda d: d["bushings"][0]["directions"].update(rx={"set": "fig5_9"}), "bushings[0].directions.rx", "rotation"),
    (lambda d: d["bushings"][1]["directions"]["x"].update(model="magic"), "bushings[1].directions.x", "magic"),
    (lambda d: d["front"]["damper"].update(curve=[[1, 0], [0, 1]]), "front.damper.curve", "increasing"),
    (lambda d: d["rear"].update(beam_bending_stiffness=-5e4), "rear.beam_bending_stiffness", "positive"),
    # inline parameters short of their own model's: an error, not the family set (which recursed)
    (lambda d: d["bushings"][0]["directions"].update(y={"model": "stvs", "params": {"K0": 500}}),
     "bushings[0].directions.y", "missing parameter"),
])
def test_bad_input_names_file_key_and_value(tmp_path, edit, key, words):
    path = _write(tmp_path, edit)
    with pytest.raises(InputError) as err:
        load_vehicle(path)
    assert str(path) in str(err.value)
    assert key in str(err.value)
    assert words in str(err.value)


def test_bushing_model_override_reads_sets_as_another_model():
    v = load_vehicle()
    e2 = next(b for b in v.bushings if b.name == "e2_front")
    assert e2.directions["x"].channel().model == "stvs"
    assert e2.directions["x"].channel("sts").model == "sts"
    assert e2.directions["rx"].channel().K0 == pytest.approx(1.0 * 180 / math.pi)  # N·m/deg -> N·m/rad
    assert e2.directions["rx"].channel("linear").model == "linear"


@pytest.mark.parametrize("model", ["sts", "rt", "stvs"])
def test_override_uses_the_family_set_scaled_to_the_direction(model):
    """An STS-only set read as rt/stvs and an inline linear rotation take the vehicle's family set,
    scaled to their own K0 (models/vehicles/README.md)."""
    v = load_vehicle()
    e1 = next(b for b in v.bushings if b.name == "e1_front")
    for d in ("y", "rx"):
        own, read = e1.directions[d].channel(), e1.directions[d].channel(model)
        assert read.model == model and read.quantity == own.quantity
        assert read.K0 == pytest.approx(own.K0)
        assert read.n_cells == 15 and read.Kpa > 0
    ref = load_parameter_set(v.bushings[0].directions["y"].families.sets[model]).channel(model)
    rot = e1.directions["rx"].channel(model)
    lever = v.bushings[0].directions["rx"].families.rotation_lever_arm
    assert rot.Kpa / rot.K0 == pytest.approx(ref.Kpa / ref.K0)
    # the slider slip angle is the reference's slip deflection over the lever arm
    assert rot.Ff / rot.Kr == pytest.approx(ref.Ff / ref.Kr / lever)


def test_the_override_on_the_translations_alone_gives_the_theses_18_stvs_models():
    """Bourgeteau 2009 §6.3's configuration: STVS on the three principal directions of E1 and E2
    front and E1 rear, both sides (18 models), every rotation as the vehicle file has it."""
    from elastokin.vehicle.model.builder import build
    from elastokin.vehicle.model.elements import BuildOptions

    v = load_vehicle()
    filed = {c.name: c.params for c in build(v, BuildOptions()).channels}
    channels = build(v, BuildOptions(bushing_model="stvs", bushing_model_directions=("x", "y", "z"))).channels
    stvs = sorted(c.name for c in channels if c.params.model == "stvs")
    assert stvs == sorted(f"{b}_{side}.{d}" for b in ("e1_front", "e2_front", "e1_rear") for side in ("left", "right")
                          for d in "xyz")
    for c in channels:
        if c.name.split(".")[1].startswith("r"):
            assert c.params == filed[c.name], c.name
    with pytest.raises(ValueError, match="unknown bushing direction.*w"):
        BuildOptions(bushing_model="stvs", bushing_model_directions=("x", "w"))
