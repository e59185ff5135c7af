"""The thesis's car (models/vehicles/c_segment_thesis.yaml, written by tools/thesis_car.py):
Bourgeteau 2009, §4.4 puts STVS laws on the three principal directions of E1 and E2 front and E1
rear, both sides (18 models), at a high loss, tan δ 0.3 (§4.4.1); everything else is the default car."""

import dataclasses
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from elastokin.bushings.frequency import first_harmonic
from elastokin.core.shipped import DEFAULT_VEHICLE, VEHICLE_DIR
from elastokin.vehicle.model.builder import BuildOptions
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.simulation.rig import KCRig

ROOT = Path(__file__).resolve().parents[1]
#: PSA's specification point of tan δ: 15 Hz, 1 mm (Bourgeteau 2009, §2.1.1).
SPEC = (np.array([1e-3]), np.array([15.0]))


def test_the_thesis_car_has_lossy_stvs_on_its_18_principal_directions_and_is_the_default_car_otherwise():
    default, thesis = load_vehicle(DEFAULT_VEHICLE), load_vehicle("c_segment_thesis")
    assert thesis.path == VEHICLE_DIR / "c_segment_thesis.yaml"
    for field in ("tyre", "body", "front", "rear"):
        assert getattr(thesis, field) == getattr(default, field), field
    assert [b.name for b in thesis.bushings] == [b.name for b in default.bushings]
    models = KCRig(thesis, BuildOptions()).car.channels
    assert sum(ch.params.model == "stvs" for ch in models) == 18      # both sides
    for old, new in zip(default.bushings, thesis.bushings):
        assert dataclasses.replace(new, directions={}) == dataclasses.replace(old, directions={})
        for d, law in new.directions.items():
            if len(d) == 2:      # rotations: the default car's
                assert law.channel() == old.directions[d].channel()
                continue
            ours, read_as_stvs = first_harmonic(law.channel(), *SPEC), first_harmonic(old.directions[d].channel("stvs"), *SPEC)
            assert law.model == "stvs"
            assert ours.tan_delta[0] == pytest.approx(0.30, abs=2e-3), (new.name, d)
            assert ours.k_dyn_n_per_m[0] == pytest.approx(read_as_stvs.k_dyn_n_per_m[0], rel=2e-3), (new.name, d)
            assert ours.tan_delta[0] > 1.5 * read_as_stvs.tan_delta[0]


def test_the_shipped_thesis_car_is_what_its_tool_writes_from_the_default_car():
    done = subprocess.run([sys.executable, str(ROOT / "tools" / "thesis_car.py"), "--check"], capture_output=True,
                          text=True, cwd=ROOT)
    assert done.returncode == 0, done.stdout + done.stderr
