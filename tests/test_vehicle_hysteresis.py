"""STVS camber loops in pumping (issue 3): non-zero width that changes with speed; none when linear.

Pumping triangle 0 → +60 → −60 → +60 mm (elastokin.vehicle.simulation.kc_triangles.run_triangle) at 1.5 and 15 mm/s and at
0.1 Hz (24 mm/s), the loop width taken at design height. The strut dampers are removed: their
viscous loop (1.3e-3 deg measured at 15 mm/s) is wider than the change the bushings' rate
dependence makes (4e-4 deg at the front) and would hide it. At the default step (2 ms) the front
loops are within 0.2 % of h = 0.5 ms's. The rear loop is a few thousandths of the front's and
does not converge in the step (4.8e-6, 1.4e-5, 2.3e-5 deg at 1.5 mm/s and h = 2, 1, 0.5 ms) nor
keep its trend with the speed (at 5 ms it widened by 38 % from 1.5 to 15 mm/s, at 1 ms it
narrows fivefold): no test holds its trend; tools/thesis/report.md says why it is small (fig. 4.30).
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from elastokin.vehicle.model.definition import Curve, Damper
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.kc_tests import Triangle
from elastokin.vehicle.simulation.kc_triangles import run_triangle
from elastokin.vehicle.simulation.rig import KCRig
from elastokin.analysis.kc_test import branches
from elastokin.analysis.loops import loop_width

H = BuildOptions.timestep
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


@pytest.fixture(scope="module")
def linear():
    return camber_loop_widths("linear", (1.5e-3, 15e-3))


def test_stvs_front_camber_loop_is_open_at_every_speed(stvs, linear):
    """The front's is 4e-3 deg, 400 times the linear car's (the rig's and closures' damping, 1e-6
    and 9e-6 deg measured); the rear's is as small as the linear car's at some speeds."""
    assert min(w["front_left"] for w in stvs.values()) > 1e-3, stvs
    for speed, widths in linear.items():
        assert stvs[speed]["front_left"] > 20.0 * widths["front_left"], (speed, stvs, linear)


def test_rear_camber_loop_in_pumping_is_a_hundredth_of_the_front(stvs, sts):
    """In pumping both rear wheels move together: the beam carries the mirror moments of their
    loads between its arms, the pivot bushings hardly turn, and the rear loop stays under 1 % of
    the front's (0.6 % measured with STVS, 0.4 % with STS; tools/thesis/report.md, fig. 4.30)."""
    for widths in (*stvs.values(), *sts.values()):
        assert widths["rear_left"] < 0.02 * widths["front_left"], (stvs, sts)


def test_front_camber_loop_changes_with_speed_only_with_viscoelastic_bushings(stvs, sts):
    """Front: the STS loop is rate independent (+0.9 % measured, the closures' damping). The STVS loop narrows with speed
    (−9 % measured, as with the purely viscoelastic RT): the loads that set the front camber come
    from the spring, the same on both branches at design height, and under an imposed force a
    power-law Maxwell cell's deflection lags less the faster the load (its loss compliance
    falls with frequency), whereas an imposed deflection's force loop widens, as at the rear."""
    assert abs(speed_gain(sts, "front_left") - 1.0) < 0.02, sts
    assert speed_gain(stvs, "front_left") < 0.97, stvs


def test_linear_elastic_camber_loop_vanishes(stvs, linear):
    for corner, width in linear[15e-3].items():
        assert width < 0.05 * stvs[1.5e-3]["front_left"], (corner, width)
