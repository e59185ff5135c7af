"""The road car's roll predicted from the K&C rig (issue 26): what the rig measures of each axle's
roll (roll stiffness, lateral-force roll-centre height, the share of an overturning moment at the
wheels that the pads take, the braked wheels' pitch in roll) and the steady-state roll gradient and
lateral load transfer that these, the masses and the tyres' vertical stiffness give.

Conventions: ISO 8855; roll positive with the right side down (a left turn's), a couple positive
when it loads the right wheels: ``C = (b/2)(Fz_R − Fz_L)`` with ``b`` the axle's contact-point base.

The estimate (per unit lateral acceleration ``a_y``, steady state, linear; the sprung body rolls by
``φ`` relative to the road, each axle's suspension by ``φ_s,i`` and its tyres by ``φ_t,i = φ − φ_s,i``):

* each axle, as the rig sees it: ``C_i = K_i φ_s,i + h_i F_i + μ_i M_i``, with ``F_i`` the lateral
  force at its contact points net of its unsprung masses' (the sprung body's share, carried at the
  roll centre ``h_i``) and ``M_i`` the moments about x on its wheel carriers (unsprung inertia at
  the wheel-centre height, the spinning wheels' gyroscopic moment ``I_s·Ω·r = I_s·a_y/R``);
* in the body's frame every lateral load scales with ``a_y + g·φ`` (gravity tilts with the body);
* the sprung body: ``Σ K_i φ_s,i = m_s (h_s − h_ra)(a_y + gφ) + Σ (1 − μ_i) M_i``, ``h_ra`` the roll
  axis height at the sprung centre of mass;
* the tyres in series: ``C_i = K_t,i φ_t,i``, ``K_t,i = k_t b_i²/2`` at the static load;
* the rig's pads hold a material point of a braked wheel, which swings fore and aft as the wheel
  pitches with its travel (a trailing arm's rotation); a rolling wheel's load stays under its
  centre, so on the road each wheel is stiffer by ``W R θ'²`` (``W`` its static load, ``R`` the
  rig's contact radius, ``θ'`` its pitch per travel in roll): ``K_i`` of the road = the rig's +
  ``(W_i/2) R θ'_i² b_i²/2``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from elastokin.vehicle.model.definition import CORNERS, VehicleDefinition
from elastokin.vehicle.scenarios.channels import AXLES
from elastokin.vehicle.scenarios.kc_tests import TEST
from elastokin.vehicle.simulation.kc_triangles import design_contact_base, run_triangle
from elastokin.vehicle.simulation.outputs import RigOutputs
from elastokin.vehicle.simulation.rig import KCRig
from elastokin.analysis.kc_metrics import fit_window
from elastokin.analysis.loops import Branches, centre_slope
from elastokin.analysis.road_metrics import G
from elastokin.tyres import magic_formula as mf

#: Rest on the rig before and after a static load [s] (the shares and pitches move < 0.5 % from 0.5 s to 3 s).
SETTLE_S = 1.0
#: The overturning moment put on each wheel [N·m] and the pads' roll travel [m] of the static tests.
MOMENT_NM, TRAVEL_M = 100.0, 0.01


@dataclass(frozen=True)
class AxleRoll:
    """What the rig measures of one axle's roll (SI)."""

    stiffness: float        #: roll stiffness [N·m/rad]: couple per suspension roll, the triangle's centre line
    centre_height: float    #: lateral-force roll-centre height [m]: couple per lateral force on both wheels
    moment_share: float     #: share of moments about x on the wheels that the pads take (the rest rolls the body)
    pitch_per_travel: float  #: the braked wheels' pitch per travel in roll [rad/m]
    load: float             #: static axle load [N]
    base: float             #: contact-point base [m]


def _couple(o: RigOutputs, axle: str, base: float) -> float:
    return 0.5 * base * (o.wheels[f"{axle}_right"].pad_force[2] - o.wheels[f"{axle}_left"].pad_force[2])


def _static(rig: KCRig, load) -> tuple[RigOutputs, RigOutputs, np.ndarray]:
    """The rig at rest, then with ``load(rig)`` applied and rested: both samples and the wheels' pitch
    change [rad] (rotation about y, order of CORNERS)."""
    pitch = lambda: -np.arcsin(rig.data.xmat[rig.wheel_body, 6])     # −(z component of the wheel's x axis)
    rig.reset()
    rig.settle(SETTLE_S)
    before, p0 = rig.measure(), pitch()
    load(rig)
    rig.settle(SETTLE_S)
    return before, rig.measure(), pitch() - p0


def _overturn(rig: KCRig) -> None:
    # a moment the real rig's pads cannot apply: about x on every wheel (xfrc_applied, as set_pad_loads does Mz)
    rig.data.xfrc_applied[rig.wheel_body, 3] = MOMENT_NM


def rig_roll(rig: KCRig) -> dict[str, AxleRoll]:
    """Each axle's :class:`AxleRoll` measured on ``rig`` (the standard roll and lateral-force
    triangles, a static overturning moment and a static roll); leaves the rig reset."""
    base = design_contact_base(rig)
    roll, lateral = run_triangle(rig, TEST["roll"]), run_triangle(rig, TEST["lateral"])
    at_rest, turned, _ = _static(rig, _overturn)
    rolled_from, rolled, pitch = _static(rig, lambda r: r.set_pads(TRAVEL_M * np.array([-1.0, 1.0, -1.0, 1.0])))
    rig.reset()
    out = {}
    for axle in AXLES:
        b = base[axle]
        L, R = f"{axle}_left", f"{axle}_right"
        couple = lambda legs: [np.array([_couple(o, axle, b) for o in leg]) for leg in legs]
        angle = lambda legs: [np.array([(o.wheels[R].pad_height - o.wheels[L].pad_height) / b for o in leg])
                              for leg in legs]
        force = lambda legs: [np.array([o.wheels[L].pad_force[1] + o.wheels[R].pad_force[1] for o in leg])
                              for leg in legs]
        (x0, x1), (y0, y1) = angle(roll), couple(roll)
        window = math.radians(fit_window("roll", TEST["roll"].amplitude, b))
        stiffness = centre_slope(Branches(x0, y0, x1, y1), window)
        (f0, f1), (c0, c1) = force(lateral), couple(lateral)
        height = centre_slope(Branches(f0, c0, f1, c1), 2.0 * fit_window("lateral", TEST["lateral"].amplitude, b))
        share = (_couple(turned, axle, b) - _couple(at_rest, axle, b)) / (2.0 * MOMENT_NM)
        # the mean of the two wheels' pitch per travel (one goes down, the other up)
        travel = lambda c: rolled.wheels[c].pad_height - rolled_from.wheels[c].pad_height
        theta = float(np.mean([pitch[CORNERS.index(c)] / travel(c) for c in (L, R)]))
        out[axle] = AxleRoll(stiffness, height, share, theta,
                             at_rest.wheels[L].pad_force[2] + at_rest.wheels[R].pad_force[2], b)
    return out


def tyre_vertical_stiffness(tyre: np.record, load: float) -> float:
    """The tyre's vertical stiffness [N/m] at the deflection that carries ``load`` [N] (its vertical law)."""
    rho = np.linspace(0.0, 0.05, 5001)
    fz = np.array([mf.vertical_force(tyre, r, 0.0) for r in rho])
    at = float(np.interp(load, fz, rho))
    return (mf.vertical_force(tyre, at + 1e-5, 0.0) - mf.vertical_force(tyre, at - 1e-5, 0.0)) / 2e-5


@dataclass(frozen=True)
class RollEstimate:
    """The steady-state roll the rig predicts, per unit lateral acceleration (SI)."""

    roll_per_ay: float               #: body roll relative to the road [rad per m/s²]
    couple_per_ay: dict[str, float]  #: each axle's lateral load-transfer couple [N·m per m/s²]


def roll_estimate(vehicle: VehicleDefinition, axles: dict[str, AxleRoll], tyre: np.record) -> RollEstimate:
    """The module's estimate for ``vehicle`` from the rig's ``axles`` and the ``tyre`` record of all four wheels."""
    body, r = vehicle.body, vehicle.tyre.radius
    x_front = vehicle.front.hardpoints["wheel_centre"][0]
    x_rear = vehicle.rear.hardpoints["wheel_centre"][0]
    wheelbase = x_front - x_rear
    share = {"front": (body.cg[0] - x_rear) / wheelbase, "rear": (x_front - body.cg[0]) / wheelbase}
    sprung = {a: body.mass * share[a] for a in AXLES}
    carrier = {a: (axles[a].load / G - sprung[a]) * r for a in AXLES}      # unsprung inertia, per a_y + gφ
    gyro = 2.0 * vehicle.tyre.wheel_inertia[0] / r                         # two wheels, per a_y
    arm = body.cg[2] - sum(share[a] * axles[a].centre_height for a in AXLES)    # sprung CG above the roll axis
    spring, series, to_springs = {}, {}, {}
    for a in AXLES:
        x = axles[a]
        spring[a] = x.stiffness + 0.5 * x.load * r * x.pitch_per_travel ** 2 * x.base ** 2 / 2.0
        tyres = tyre_vertical_stiffness(tyre, x.load / 2.0) * x.base ** 2 / 2.0
        series[a] = spring[a] * tyres / (spring[a] + tyres)
        to_springs[a] = spring[a] / (spring[a] + tyres)   # the part of a non-spring couple the tyres' roll adds
    # each axle's couple besides its springs, per a' = a_y + gφ and per a_y: c_i = h_i·m_s,i·a' + μ_i·M_i
    other_tilt = {a: axles[a].centre_height * sprung[a] + axles[a].moment_share * carrier[a] for a in AXLES}
    other_ay = {a: axles[a].moment_share * gyro for a in AXLES}
    # the body: φ·Σ K'_i = m_s·arm·a' + Σ (1 − μ_i)·M_i + Σ c_i·K_i/(K_i + K_t,i)
    total = sum(series.values())
    per_tilt = (body.mass * arm + sum((1 - axles[a].moment_share) * carrier[a] + to_springs[a] * other_tilt[a]
                                      for a in AXLES)) / total
    per_ay = sum((1 - axles[a].moment_share) * gyro + to_springs[a] * other_ay[a] for a in AXLES) / total
    roll = (per_tilt + per_ay) / (1.0 - G * per_tilt)
    tilt = 1.0 + G * roll                       # a' per a_y
    couple = {a: (spring[a] * roll + other_tilt[a] * tilt + other_ay[a]) * (1.0 - to_springs[a]) for a in AXLES}
    return RollEstimate(roll, couple)
