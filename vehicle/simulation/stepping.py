"""Compiled stepping: the coupling of :mod:`elastokin.vehicle.simulation.coupling` and ``mj_step`` in one numba loop.

A numpy coupling called from a Python loop cost ~150–250 µs per step on the rig, more than
``mj_step``; here the rig inputs, the bushing bank step (the laws with their state extensions,
:func:`elastokin.bushings.extended_bank.step_extended`), the bushings' cross stiffnesses, the damper and spring
laws and ``mj_step`` (called through ctypes on the model's and data's addresses) all run in
compiled code, so a step costs ``mj_step`` plus the bank kernel. :func:`run` gives bit-identical
results to calling ``ForceCoupling.apply`` and ``mujoco.mj_step`` from Python (tests/test_vehicle_rig.py);
:func:`run_sampled` also measures the rig's outputs every so many steps (elastokin.vehicle.simulation.probes)
without coming back to Python.

Arrays of ``MjModel``/``MjData`` are numpy views of MuJoCo's memory, so the loop reads and writes
them in place.
"""

from __future__ import annotations

import ctypes
import math
from pathlib import Path

import mujoco
import numba as nb
import numpy as np

from elastokin.bushings import extended_bank as _xb
from elastokin.vehicle.simulation import probes
from elastokin.vehicle.simulation.probes import rig_sample, road_sample, segment
from elastokin.core.compiled_cache import follow
from elastokin.tyres import road_contact
from elastokin.tyres.road_contact import tyre_wrenches

# the loops compile the bushing kernels and the tyres into themselves: their cache follows those files
follow(__file__, *_xb.KERNEL_FILES, *road_contact.TYRE_FILES, probes.__file__, *probes.FOLLOWED)

_LIB = ctypes.CDLL(str(next(Path(mujoco.__file__).parent.glob("libmujoco.so*"))))
_mj_step = _LIB.mj_step
_mj_step.argtypes = (ctypes.c_size_t, ctypes.c_size_t)  # mjModel*, mjData* as addresses
_mj_step.restype = None
_mj_step1, _mj_step2 = _LIB.mj_step1, _LIB.mj_step2   # positions and velocities, then forces and integration
_mj_forward, _mj_rne_post_constraint = _LIB.mj_forward, _LIB.mj_rnePostConstraint
for _f in (_mj_step1, _mj_step2, _mj_forward, _mj_rne_post_constraint):
    _f.argtypes, _f.restype = (ctypes.c_size_t, ctypes.c_size_t), None
# (model, data, object type, object id, result as an address, flg_local)
_mj_object_velocity, _mj_object_acceleration = _LIB.mj_objectVelocity, _LIB.mj_objectAcceleration
for _f in (_mj_object_velocity, _mj_object_acceleration):
    _f.argtypes = (ctypes.c_size_t, ctypes.c_size_t, ctypes.c_int, ctypes.c_int, ctypes.c_size_t, ctypes.c_int)
    _f.restype = None
_BODY = int(mujoco.mjtObj.mjOBJ_BODY)


@nb.njit(cache=True)
def _push(qfrc, ten_J, ten_J_rowadr, ten_J_rownnz, ten_J_colind, joint, index, gen):
    """Add generalised forces ``gen`` along joint dofs or tendons (through their sparse Jacobian rows)."""
    for k in range(gen.shape[0]):
        if joint[k]:
            qfrc[index[k]] += gen[k]
        elif gen[k] != 0.0:
            a = ten_J_rowadr[index[k]]
            for p in range(a, a + ten_J_rownnz[index[k]]):
                qfrc[ten_J_colind[p]] += ten_J[p] * gen[k]


@nb.njit(cache=True)
def coupling_step(h, qpos, qvel, qfrc, ten_length, ten_velocity, ten_J, ten_J_rowadr, ten_J_rownnz, ten_J_colind,
                  jnt_stiffness, dof_damping, tendon_damping, bush, bank, cross, damp, spring):
    """Write the non-implicit forces for the next step of ``h`` [s] (see elastokin.vehicle.simulation.coupling).

    ``bush`` = (qpos adr, dof adr, joint ids, least K_ref, K_ref, saturating, e work) of the
    bank channels, ``bank`` = :meth:`elastokin.bushings.extended_bank.ExtendedBank.kernel_args`, ``cross`` = (qpos adr
    (P, 2), dof adr (P, 2), stiffness (P,)) of the cross stiffnesses, ``damp`` = (is joint, dof or
    tendon index, sign, xs, ys, intercept out [N], work), ``spring`` = (is joint, index, qpos adr,
    design, sign, xs, ys, rate, y0, nonlinear?, remainder work).
    """
    qfrc[:] = 0.0
    bq, bd, bj, kbase, kref, sat, e = bush
    if bq.shape[0]:
        for c in range(bq.shape[0]):
            e[c] = qpos[bq[c]]
        _xb.step_extended(e, h, *bank)
        force, tangent = bank[3], bank[4]
        for c in range(bq.shape[0]):
            if sat[c]:
                kref[c] = max(kbase[c], tangent[c])
                jnt_stiffness[bj[c]] = kref[c]
            qfrc[bd[c]] += kref[c] * e[c] - force[c]
    xq, xd, xk = cross
    for p in range(xk.shape[0]):
        qfrc[xd[p, 0]] -= xk[p] * qpos[xq[p, 1]]
        qfrc[xd[p, 1]] -= xk[p] * qpos[xq[p, 0]]
    joint, index, sign, xs, ys, offset, gen = damp
    for k in range(joint.shape[0]):
        v = qvel[index[k]] if joint[k] else ten_velocity[index[k]]
        slope, offset[k] = segment(sign[k] * v, xs[k], ys[k])
        if joint[k]:
            dof_damping[index[k]] = slope
        else:
            tendon_damping[index[k]] = slope
        gen[k] = -sign[k] * offset[k]  # compression = sign·Δq: a force pushing apart acts along −sign
    _push(qfrc, ten_J, ten_J_rowadr, ten_J_rownnz, ten_J_colind, joint, index, gen)
    sjoint, sindex, sqadr, design, ssign, sxs, sys_, rate, y0, nonlinear, rem = spring
    if nonlinear:
        for k in range(sjoint.shape[0]):
            coord = qpos[sqadr[k]] if sjoint[k] else ten_length[sindex[k]]
            x = ssign[k] * (coord - design[k])
            slope, icpt = segment(x, sxs[k], sys_[k])
            rem[k] = -ssign[k] * (slope * x + icpt - y0[k] - rate[k] * x)
        _push(qfrc, ten_J, ten_J_rowadr, ten_J_rownnz, ten_J_colind, sjoint, sindex, rem)


@nb.njit(cache=True)
def _run(mj_step, n, inputs, active, eq_data, pad_eq, rack_eq, xfrc, force_body, wheel, efc_force, pad_row, pad_force,
         m_addr, d_addr, h, qpos, qvel, qfrc, ten_length, ten_velocity, ten_J, ten_J_rowadr, ten_J_rownnz, ten_J_colind,
         jnt_stiffness, dof_damping, tendon_damping, bush, bank, cross, damp, spring):
    """Advance ``n`` steps, row i of ``inputs`` set before step i (none if ``inputs`` has no rows).

    A row holds the rig inputs in the order of ``elastokin.vehicle.scenarios.channels.INPUT_CHANNELS`` (17 values):
    pad heights [m], Fx, Fy [N] on ``force_body`` (the carriages: at the contact points; or the
    wheels: at their centres), Mz [N·m] at the wheels, four corners each, then
    the rack [m]; ``active[g]`` says whether group g (pads, Fx, Fy, Mz, rack) is driven (else left
    as is). After each step ``pad_force`` holds the force of each pad's drive row (``pad_row``) in
    that step, the force that moved the car to the new state: a later ``mj_forward`` recomputes the
    rows with the step's target held, i.e. the force of a rig stopping now, which carries the
    deceleration of the mass on the pad (a pad-force loop 2·m·k·V·h/(1 + h·b + h²·k) wide, m ≈ 34 kg:
    84 N at 2 ms and 10 mm/s). ``mj_step`` is MuJoCo's, passed as a ctypes function so that the compiled code
    can be cached.
    """
    for i in range(n):
        if inputs.shape[0]:
            u = inputs[i]
            for c in range(4):
                if active[0]:
                    eq_data[pad_eq[c], 0] = u[c]
                if active[1]:
                    xfrc[force_body[c], 0] = u[4 + c]
                if active[2]:
                    xfrc[force_body[c], 1] = u[8 + c]
                if active[3]:
                    xfrc[wheel[c], 5] = u[12 + c]
            if active[4]:
                eq_data[rack_eq, 0] = u[16]
        coupling_step(h, qpos, qvel, qfrc, ten_length, ten_velocity, ten_J, ten_J_rowadr, ten_J_rownnz, ten_J_colind,
                      jnt_stiffness, dof_damping, tendon_damping, bush, bank, cross, damp, spring)
        mj_step(m_addr, d_addr)
        for c in range(pad_row.shape[0]):
            pad_force[c] = efc_force[pad_row[c]]


def run(*args) -> None:
    """:func:`_run` with MuJoCo's ``mj_step``; ``args`` are the rest of its arguments, from ``n``."""
    _run(_mj_step, *args)


@nb.njit(cache=True)
def _kept(s, bodies, xpos, xquat, body_pos, body_quat, warnings, resets, counts) -> bool:
    """Copy the poses of ``bodies`` into row ``s`` of ``body_pos``, ``body_quat``; whether one of
    MuJoCo's warning counters ``warnings[resets]`` rose from ``counts`` (MuJoCo reset the state)."""
    for b in range(bodies.shape[0]):
        body_pos[s, b, :] = xpos[bodies[b]]
        body_quat[s, b, :] = xquat[bodies[b]]
    for k in range(resets.shape[0]):
        if warnings[resets[k]] != counts[k]:
            return True
    return False


@nb.njit(cache=True, nogil=True)   # a recording's writer thread runs meanwhile (elastokin.recordings.background)
def _run_sampled(mj_step, mj_forward, every, inputs, active, rig, m_addr, d_addr, h, coupling, probe, bodies, xpos,
                 xquat, measured, body_pos, body_quat, warnings, resets):
    """One sample every ``every`` steps for each row of ``measured``: :func:`_run` of ``every`` steps
    (their rows of ``inputs``, none if it has no rows; ``rig`` = its arguments from ``eq_data`` to
    ``pad_force``), ``mj_forward``, the rig's measured vector into the row
    (:func:`elastokin.vehicle.simulation.probes.rig_sample`, ``probe`` its arguments after ``out``) and the
    poses of ``bodies`` into ``body_pos``, ``body_quat``. Stops after the first sample at which one
    of MuJoCo's warning counters ``warnings[resets]`` rose (MuJoCo reset the state); returns the
    number of samples taken."""
    counts = warnings[resets].copy()
    for s in range(measured.shape[0]):
        _run(mj_step, every, inputs[s * every:(s + 1) * every], active, *rig, m_addr, d_addr, h, *coupling)
        mj_forward(m_addr, d_addr)
        rig_sample(measured[s], *probe)
        if _kept(s, bodies, xpos, xquat, body_pos, body_quat, warnings, resets, counts):
            return s + 1
    return measured.shape[0]


def run_sampled(*args) -> int:
    """:func:`_run_sampled` with MuJoCo's ``mj_step`` and ``mj_forward``; ``args`` from ``every``."""
    return _run_sampled(_mj_step, _mj_forward, *args)


@nb.njit(cache=True)
def _run_road(mj_step1, mj_step2, n, inputs, eq_data, rack_eq, spin_dof, frictionloss, m_addr, d_addr, h, coupling,
              tyres, driver):
    """Advance the car on the road ``n`` steps, row i of ``inputs`` set before step i (none if it has
    no rows): the rack [m]; the target speed [m/s] of the driver's speed controller, or NaN to hold
    its last drive force (a fixed throttle); four extra drive torques [N·m] (order of CORNERS,
    positive driving, reacting on the knuckle) and four brake torques [N·m] (the spin joints' dry
    friction: it holds a wheel still up to that torque). Each step: the coupling's forces, the
    driver, ``mj_step1`` (positions and velocities), the tyres' wrenches from them (``tyres`` = the
    arguments of :func:`elastokin.tyres.road_contact.tyre_wrenches` after ``h``), ``mj_step2``: MuJoCo's
    split step, bit-identical to ``mj_step``, so that the tyres see this step's state and not the
    last one's.

    ``driver`` = (qvel, xmat, chassis dof, chassis body, each wheel's share of the drive force,
    (gain [N·s/m], integral gain [N/m], wheel radius [m]), state (integral of the speed error [m],
    drive force [N])): a PI controller of the body's forward speed."""
    qfrc = coupling[2]
    qvel, xmat, dof, body, share, gains, state = driver
    for i in range(n):
        coupling_step(h, *coupling)
        if inputs.shape[0]:
            u = inputs[i]
            eq_data[rack_eq, 0] = u[0]
            if not math.isnan(u[1]):
                forward = qvel[dof] * xmat[body, 0] + qvel[dof + 1] * xmat[body, 3] + qvel[dof + 2] * xmat[body, 6]
                error = u[1] - forward
                state[0] += error * h
                state[1] = gains[0] * error + gains[1] * state[0]
            for c in range(4):
                qfrc[spin_dof[c]] += u[2 + c] + share[c] * state[1] * gains[2]
                frictionloss[spin_dof[c]] = u[6 + c]
        mj_step1(m_addr, d_addr)
        tyre_wrenches(tyres[0], tyres[1], h, *tyres[2:])
        mj_step2(m_addr, d_addr)


def run_road(*args) -> None:
    """:func:`_run_road` with MuJoCo's ``mj_step1`` and ``mj_step2``; ``args`` from ``n``."""
    _run_road(_mj_step1, _mj_step2, *args)


@nb.njit(cache=True, nogil=True)
def _run_road_sampled(mj_step1, mj_step2, mj_forward, mj_rne_post_constraint, mj_object_velocity,
                      mj_object_acceleration, every, inputs, road, m_addr, d_addr, h, coupling, tyres, driver, chassis,
                      probe, bodies, xpos, xquat, measured, body_pos, body_quat, warnings, resets):
    """:func:`_run_sampled` on the road: :func:`_run_road` of ``every`` steps (``road`` = its
    arguments from ``eq_data`` to ``frictionloss``), ``mj_forward``, the bodies' accelerations
    (``mj_rnePostConstraint``) and the velocity and acceleration of the body ``chassis``, then
    :func:`elastokin.vehicle.simulation.probes.road_sample` (``probe`` its arguments after ``acceleration``)."""
    counts = warnings[resets].copy()
    motion, acceleration = np.zeros(6), np.zeros(6)
    for s in range(measured.shape[0]):
        _run_road(mj_step1, mj_step2, every, inputs[s * every:(s + 1) * every], *road, m_addr, d_addr, h, coupling,
                  tyres, driver)
        mj_forward(m_addr, d_addr)
        mj_rne_post_constraint(m_addr, d_addr)
        mj_object_velocity(m_addr, d_addr, _BODY, chassis, motion.ctypes.data, 0)
        mj_object_acceleration(m_addr, d_addr, _BODY, chassis, acceleration.ctypes.data, 0)
        road_sample(measured[s], motion, acceleration, *probe)
        if _kept(s, bodies, xpos, xquat, body_pos, body_quat, warnings, resets, counts):
            return s + 1
    return measured.shape[0]


def run_road_sampled(*args) -> int:
    """:func:`_run_road_sampled` with MuJoCo's functions; ``args`` from ``every``."""
    return _run_road_sampled(_mj_step1, _mj_step2, _mj_forward, _mj_rne_post_constraint, _mj_object_velocity,
                             _mj_object_acceleration, *args)


def coupling_arrays(coupling) -> tuple:
    """The (bush, bank, cross, damp, spring) tuples of :func:`coupling_step` for a ForceCoupling."""
    b = coupling.bushings
    on = b.bank is not None  # None: laws off, every direction linear in its joint
    idx = b.bank_idx if on else np.zeros(0, np.int64)
    bush = (b.qpos[idx].astype(np.int64), b.dof[idx].astype(np.int64), b.jnt[idx].astype(np.int64),
            b.K_floor if on else np.zeros(0), b.K_ref if on else np.zeros(0),
            b.saturating if on else np.zeros(0, np.bool_), np.zeros(idx.size))
    bank = (b.bank if on else _xb.ExtendedBank([])).kernel_args()
    # the cross stiffnesses are linear and stay on when the laws are off
    cross = (b.qpos[b.cross_channels].astype(np.int64), b.dof[b.cross_channels].astype(np.int64), b.cross_k)
    c = coupling
    damp = (c.dp_joint, c.dp_index.astype(np.int64), c.dp_sign.astype(float), c.dp_xs, c.dp_ys, c.dp_offset,
            np.zeros(len(c.dp_offset)))
    spring = (c.sp_joint, c.sp_index.astype(np.int64), c.sp_qadr.astype(np.int64), c.sp_design, c.sp_sign.astype(float),
              c.sp_xs, c.sp_ys, c.sp_rate, c.sp_y0, bool(c.sp_nonlinear), np.zeros(len(c.sp_rate)))
    return bush, bank, cross, damp, spring
