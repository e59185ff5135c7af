"""Compiled measurement of the car at one instant, into one vector of SI values (the columns of
:class:`elastokin.vehicle.simulation.outputs.MeasuredColumns`): what the suspension's parts carry (springs,
dampers, bushing directions, loop closures) and what the K&C rig reads at its wheels.

The stepping loops call :func:`rig_sample` and :func:`road_sample` at every output sample without
coming back to Python (:mod:`elastokin.vehicle.simulation.stepping`); the coupling's readers
(``BushingForces.forces``) call the same functions from Python, so that there is one formula for
every measured quantity. All of them read MuJoCo's arrays after ``mj_forward``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from elastokin.vehicle.model import kinematics
from elastokin.vehicle.model.kinematics import wheel_orientation
from elastokin.vehicle.simulation.outputs import RIG_WHEEL, ROAD_BODY, ROAD_WHEEL
from elastokin.core.compiled_cache import follow

#: Files the probes compile into themselves (the wheel angles): their cache follows them.
FOLLOWED = (kinematics.__file__,)
follow(__file__, *FOLLOWED)

#: Columns per wheel of the rig's measured vector.
RIG_WHEEL_SIZE = len(RIG_WHEEL)


@nb.njit(cache=True)
def segment(x, xs, ys):
    """Slope and intercept of the padded curve (xs, ys) at x (linear extrapolation at the ends)."""
    n = xs.shape[0]
    i = 0
    while i < n - 2 and xs[i + 1] <= x:
        i += 1
    slope = (ys[i + 1] - ys[i]) / (xs[i + 1] - xs[i])
    return slope, ys[i] - slope * xs[i]


@nb.njit(cache=True)
def bushings(deflection, force, qpos, qvel, qadr, dof, K, C, laws_on, bank_idx, bank_force, cross_ch, cross_k):
    """Each bushing direction's deflection [m or rad] and force resisting it [N or N·m]: the joint's
    stiffness ``K`` and damping ``C``, or (``laws_on``) the bank's force plus the joint's damping
    for the bank's channels ``bank_idx``, plus the cross stiffnesses ``cross_k`` between the
    channel pairs ``cross_ch``."""
    n = qadr.shape[0]
    cross = np.zeros(n)
    for p in range(cross_k.shape[0]):
        a, b = cross_ch[p, 0], cross_ch[p, 1]
        cross[a] += cross_k[p] * qpos[qadr[b]]
        cross[b] += cross_k[p] * qpos[qadr[a]]
    for i in range(n):
        deflection[i] = qpos[qadr[i]]
        force[i] = K[i] * qpos[qadr[i]] + C[i] * qvel[dof[i]]
    if laws_on:
        for j in range(bank_idx.shape[0]):
            i = bank_idx[j]
            force[i] = bank_force[j] + C[i] * qvel[dof[i]]
    for i in range(n):
        force[i] = force[i] + cross[i]


@nb.njit(cache=True)
def springs(force, qpos, ten_length, joint, qadr, index, design, sign, xs, ys, preload, y0):
    """Each spring's force [N], pushing apart: its curve at its compression from design (a joint's
    coordinate or a tendon's length), with its preload."""
    for k in range(force.shape[0]):
        coord = qpos[qadr[k]] if joint[k] else ten_length[index[k]]
        x = sign[k] * (coord - design[k])
        slope, icpt = segment(x, xs[k], ys[k])
        force[k] = preload[k] + slope * x + icpt - y0[k]


@nb.njit(cache=True)
def dampers(force, qvel, ten_velocity, joint, index, sign, xs, ys):
    """Each damper's force [N], pushing apart (positive in compression): its curve at its speed."""
    for k in range(force.shape[0]):
        v = qvel[index[k]] if joint[k] else ten_velocity[index[k]]
        speed = sign[k] * v
        slope, icpt = segment(speed, xs[k], ys[k])
        force[k] = slope * speed + icpt


@nb.njit(cache=True)
def first_rows(efc_type, efc_id, nefc, neq, equality_type):
    """Index in ``efc_*`` of the first row of every equality, -1 where inactive (an equality's rows
    are consecutive)."""
    first = np.full(neq, -1, dtype=np.int64)
    for r in range(nefc):
        if efc_type[r] == equality_type and first[efc_id[r]] < 0:
            first[efc_id[r]] = r
    return first


@nb.njit(cache=True)
def closure_error(efc_pos, rows, used):
    """Largest position error of the loop closures [m]: the length of each one's first ``used``
    (3 for a connect or weld's position, 1 for a tendon length) constraint rows from ``rows``."""
    worst = 0.0
    for c in range(rows.shape[0]):
        if rows[c] < 0:
            continue
        s = 0.0
        for r in range(used[c]):
            p = efc_pos[rows[c] + r]
            s += p * p
        worst = max(worst, math.sqrt(s))
    return worst


@nb.njit(cache=True)
def suspension(out, qpos, qvel, ten_length, ten_velocity, efc_pos, bush, spring, damp, closure):
    """The suspension's part of a measured vector into ``out``: spring forces, damper forces,
    bushing deflections, bushing forces, loop-closure error (``bush``, ``spring``, ``damp`` and
    ``closure`` are the other arguments of :func:`bushings`, :func:`springs`, :func:`dampers` and
    :func:`closure_error`)."""
    ns, nd, nb_ = spring[0].shape[0], damp[0].shape[0], bush[0].shape[0]
    springs(out[:ns], qpos, ten_length, *spring)
    dampers(out[ns:ns + nd], qvel, ten_velocity, *damp)
    start = ns + nd
    bushings(out[start:start + nb_], out[start + nb_:start + 2 * nb_], qpos, qvel, *bush)
    out[start + 2 * nb_] = closure_error(efc_pos, *closure)


@nb.njit(cache=True)
def rig_wheels(out, xmat, site_xpos, xfrc, qpos, pad_force, wheel, centre_site, carriage, pad_qpos, sign, design_z):
    """What the rig reads at its four wheels into ``out`` (the columns of
    elastokin.vehicle.simulation.outputs.RIG_WHEEL, in its order, for each wheel): wheel angles, half-track,
    travel (centre height from ``design_z``) and centre from the wheel's pose; the pad's commanded
    Fx, Fy, its Fz (``pad_force``: the drive equality's force in the last step, see
    elastokin.vehicle.simulation.stepping._run), its height and aligning torque."""
    for k in range(wheel.shape[0]):
        base = RIG_WHEEL_SIZE * k
        w, s, c = wheel[k], centre_site[k], carriage[k]
        toe, camber, steer = wheel_orientation(xmat[w, 1], xmat[w, 4], xmat[w, 7], sign[k])
        out[base] = camber
        out[base + 1] = toe
        out[base + 2] = steer
        out[base + 3] = abs(site_xpos[s, 1])
        out[base + 4] = site_xpos[s, 2] - design_z[k]
        out[base + 5] = site_xpos[s, 0]
        out[base + 6] = site_xpos[s, 1]
        out[base + 7] = site_xpos[s, 2]
        out[base + 8] = xfrc[c, 0]
        out[base + 9] = xfrc[c, 1]
        out[base + 10] = pad_force[k]
        out[base + 11] = qpos[pad_qpos[k]]
        out[base + 12] = xfrc[w, 5]


@nb.njit(cache=True)
def rig_sample(out, wheels, data, suspension_args):
    """One measured vector of the rig into ``out``: the wheels (``wheels`` the arguments of
    :func:`rig_wheels` after ``out``), then the suspension (``data`` = qpos, qvel, ten_length,
    ten_velocity, efc_pos; ``suspension_args`` the rest of :func:`suspension`'s)."""
    rig_wheels(out, *wheels)
    suspension(out[RIG_WHEEL_SIZE * wheels[5].shape[0]:], *data, *suspension_args)   # after the wheels


@nb.njit(cache=True)
def road_body(out, motion, acceleration, xmat, xipos, qpos, chassis, rack_qpos, driver_state, gravity, min_speed):
    """What the car on the road measures of its body and driver into ``out`` (the columns of
    elastokin.vehicle.simulation.outputs.ROAD_BODY): ``motion`` and ``acceleration`` are MuJoCo's
    (rotational, linear) velocity and acceleration of the body at its centre of mass, world axes
    (``mj_objectVelocity``, ``mj_objectAcceleration``), the acceleration carrying −g."""
    r = xmat[chassis]
    yaw = math.atan2(r[3], r[0])
    c, s = math.cos(yaw), math.sin(yaw)
    vx, vy = c * motion[3] + s * motion[4], -s * motion[3] + c * motion[4]
    ax, ay = acceleration[3] + gravity[0], acceleration[4] + gravity[1]   # an accelerometer's reading
    out[0] = xipos[chassis, 0]
    out[1] = xipos[chassis, 1]
    out[2] = yaw
    out[3] = math.atan2(r[7], r[8])
    out[4] = -math.asin(max(-1.0, min(1.0, r[6])))
    out[5] = vx
    out[6] = vy
    out[7] = motion[2]
    out[8] = c * ax + s * ay
    out[9] = -s * ax + c * ay
    out[10] = math.atan2(vy, vx) if math.hypot(vx, vy) > min_speed else 0.0
    out[11] = qpos[rack_qpos]
    out[12] = driver_state[1]


@nb.njit(cache=True)
def road_wheels(out, xmat, xipos, xpos, wheel, chassis, sign, design_z, tyre_signals):
    """What the car on the road measures at its four wheels into ``out`` (the columns of
    elastokin.vehicle.simulation.outputs.ROAD_WHEEL, then the tyre's ``tyre_signals``, for each wheel):
    angles relative to the body, travel (wheel-centre height in the body frame from ``design_z``)."""
    r = xmat[chassis]
    size = len(ROAD_WHEEL) + tyre_signals.shape[1]
    for k in range(wheel.shape[0]):
        w = xmat[wheel[k]]
        # the spin axis (the wheel's y axis) and the centre of mass in the body's frame: rᵀ·v
        lx = r[0] * w[1] + r[3] * w[4] + r[6] * w[7]
        ly = r[1] * w[1] + r[4] * w[4] + r[7] * w[7]
        lz = r[2] * w[1] + r[5] * w[4] + r[8] * w[7]
        toe, camber, steer = wheel_orientation(lx, ly, lz, sign[k])
        dx, dy, dz = (xipos[wheel[k], 0] - xpos[chassis, 0], xipos[wheel[k], 1] - xpos[chassis, 1],
                      xipos[wheel[k], 2] - xpos[chassis, 2])
        base = k * size
        out[base] = camber
        out[base + 1] = toe
        out[base + 2] = steer
        out[base + 3] = r[2] * dx + r[5] * dy + r[8] * dz - design_z[k]
        out[base + len(ROAD_WHEEL):base + size] = tyre_signals[k]


@nb.njit(cache=True)
def road_sample(out, motion, acceleration, body, wheels, data, suspension_args):
    """One measured vector of the car on the road into ``out``: the body (``body`` the arguments of
    :func:`road_body` after ``acceleration``), the wheels (``wheels`` those of :func:`road_wheels`
    after ``out``), then the suspension (as in :func:`rig_sample`)."""
    road_body(out, motion, acceleration, *body)
    start = len(ROAD_BODY)
    stop = start + wheels[3].shape[0] * (len(ROAD_WHEEL) + wheels[7].shape[1])
    road_wheels(out[start:stop], *wheels)
    suspension(out[stop:], *data, *suspension_args)
