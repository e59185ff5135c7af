"""The K&C tests played on the rig: one triangle from design with virgin bushings, sampled on its
down and up legs, and the contact-point base the roll metrics need."""

from __future__ import annotations

import mujoco
import numpy as np

from elastokin.vehicle.scenarios.channels import AXLES
from elastokin.vehicle.scenarios.kc_tests import SAMPLES_PER_LEG, SETTLE, Triangle
from elastokin.vehicle.simulation.outputs import RigOutputs
from elastokin.vehicle.simulation.rig import KCRig


def run_triangle(rig: KCRig, test: Triangle) -> tuple[list[RigOutputs], list[RigOutputs]]:
    """Run ``test`` from design with virgin bushings; returns the (down, up) legs' samples."""
    rig.reset()
    rig.settle(SETTLE)
    peak = test.amplitude * np.asarray(test.pattern, float)
    zero = np.zeros(4)
    if test.input == "rack":
        peak, zero = peak[0], 0.0
    leg = test.amplitude / test.rate
    rig.ramp(leg, 0, at=test.at, **{test.input: (zero, peak)})
    down = rig.ramp(2 * leg, SAMPLES_PER_LEG, at=test.at, **{test.input: (peak, -peak)})
    up = rig.ramp(2 * leg, SAMPLES_PER_LEG, at=test.at, **{test.input: (-peak, peak)})
    return down, up


def design_contact_base(rig: KCRig) -> dict[str, float]:
    """Lateral distance between the left and right contact points of each axle at design [m]."""
    rig.reset()
    mujoco.mj_forward(rig.model, rig.data)
    site = lambda c: mujoco.mj_name2id(rig.model, mujoco.mjtObj.mjOBJ_SITE, rig.car.corners[c]["contact_site"])
    return {a: float(rig.data.site_xpos[site(f"{a}_left"), 1] - rig.data.site_xpos[site(f"{a}_right"), 1])
            for a in AXLES}
