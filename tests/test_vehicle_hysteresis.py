"""STVS camber loops in pumping (issue 3): non-zero width that changes with speed; none when linear.

Pumping triangle 0 → +60 → −60 → +60 mm (vehicle.simulation.kc_triangles.run_triangle) at 1.5 and 15 mm/s and at
0.1 Hz (24 mm/s), the loop width taken at design height. The strut dampers are removed: their
viscous loop (1.3e-3 deg measured at 15 mm/s) is wider than the change the bushings' rate
dependence makes (4e-4 deg at the front) and would hide it. h = 5 ms: quasi-static, and the
branches move < 0.001 deg from h = 1 ms (measured).
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from vehicle.model.definition import Curve, Damper
from vehicle.model.elements import BuildOptions
from vehicle.model.vehicle_file import load_vehicle
from vehicle.scenarios.kc_tests import Triangle
from vehicle.simulation.kc_triangles import run_triangle
from vehicle.simulation.rig import KCRig
from vsim_analysis.kc_test import branches
from vsim_analysis.loops import loop_width

H = 5e-3
AMPLITUDE = 0.06


def camber_loop_widths(model: str, speeds) -> dict[float, dict[str, float]]:
    """Camber loop width at design [deg] of the front and rear left wheels, per pumping speed [m/s]."""
    v = load_vehicle()
    none = Damper(Curve((-1.0, 1.0), (0.0, 0.0)))
    v = dataclasses.replace(v, front=dataclasses.replace(v.front, damper=none),
                            rear=dataclasses.replace(v.rear, damper=none))
    rig = KCRig(v, BuildOptions(bushing_model=model, timestep=H))
    out = {}
    for speed in speeds:
        down, up = run_triangle(rig, Triangle("pumping", "pads", (1, 1, 1, 1), AMPLITUDE, speed))
        out[speed] = {c: loop_width(branches(down, up, lambda o: o.wheels[c].pad_height,
                                              lambda o: math.degrees(o.wheels[c].camber)), 0.8 * AMPLITUDE)[0]
                      for c in ("front_left", "rear_left")}
    return out


@pytest.fixture(scope="module")
def stvs():
    return camber_loop_widths("stvs", (1.5e-3, 15e-3, 24e-3))


@pytest.fixture(scope="module")
def sts():
    return camber_loop_widths("sts", (1.5e-3, 15e-3))


def speed_gain(widths: dict[float, dict[str, float]], corner: str) -> float:
    """Loop width at 15 mm/s over that at 1.5 mm/s."""
    return widths[15e-3][corner] / widths[1.5e-3][corner]


def test_stvs_camber_loop_is_open_at_every_speed(stvs):
    for corner in ("front_left", "rear_left"):
        assert min(w[corner] for w in stvs.values()) > 1e-4, (corner, stvs)


def test_rear_camber_loop_widens_with_speed_by_the_bushings_viscoelasticity(stvs, sts):
    """Rear: the E1 bushings turn with the trailing arms, so their deflection follows the wheel
    travel (thesis §4.4.1) and their viscous force adds to the loop: wider at 15 than at 1.5 mm/s
    (thesis fig. 4.30; +38 % measured), and by more than with rate-independent STS bushings (+14 %
    measured: velocity-dependent forces outside the bushing laws, the joints having no damping)."""
    assert speed_gain(stvs, "rear_left") > 1.02, stvs
    assert speed_gain(stvs, "rear_left") > speed_gain(sts, "rear_left") + 0.1, (stvs, sts)


def test_front_camber_loop_changes_with_speed_only_with_viscoelastic_bushings(stvs, sts):
    """Front: the STS loop is rate independent (0.07 % measured). The STVS loop narrows with speed
    (−9 % measured, as with the purely viscoelastic RT): the loads that set the front camber come
    from the spring, the same on both branches at design height, and under an imposed force a
    power-law Maxwell cell's deflection lags less the faster the load (its loss compliance
    falls with frequency), whereas an imposed deflection's force loop widens, as at the rear."""
    assert abs(speed_gain(sts, "front_left") - 1.0) < 0.01, sts
    assert speed_gain(stvs, "front_left") < 0.97, stvs


def test_linear_elastic_camber_loop_vanishes(stvs):
    linear = camber_loop_widths("linear", (15e-3,))[15e-3]
    for corner, width in linear.items():
        assert width < 0.05 * stvs[1.5e-3]["front_left"], (corner, width)
