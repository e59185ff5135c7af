"""Per-step forces computed outside MuJoCo: bushing laws, spring and damper characteristics.

Scheme (stable at any step, see the engineering notes): MuJoCo's ``discrete`` integrator treats
joint stiffness and damping implicitly, forces written to ``qfrc_applied`` explicitly. So

* a linear bushing direction lives entirely in its joint (stiffness K0, damping C);
* any other direction keeps a reference stiffness K_ref = K0 + Kpa (its tangent at small
  amplitude, the largest tangent of the ladder family) and its damping C in the joint; before each
  step ONE compiled call of the bushing bank (:func:`elastokin.bushings.extended_bank.step_extended`: the law with
  its state extensions, if any) gives F(e) at the current deflections and only F(e) − K_ref·e is
  applied explicitly. That remainder's stiffness lies in [−Kpa, 0] ⊂ (−K_ref, 0], so the explicit
  part can never destabilise the implicit one (laws that may stiffen beyond K_ref, the nonlinear
  elastic saturation and any law with effects, get K_ref raised to their current tangent each step,
  never below K0 + Kpa plus the stiffness of a slipping interface, which comes back at every reversal);
* a bushing's directional coupling (cross stiffness k between two of its directions) is applied
  explicitly; k² < K0_a·K0_b (checked on loading) keeps the coupled tangent positive definite,
  which is also what keeps that explicit term below the implicit diagonal;
* springs: rate and preload in the joint or tendon; a curve's departure from its rate explicit;
* dampers: the slope of the active curve segment set as the joint/tendon damping each step
  (implicit), the segment's intercept applied explicitly.

:meth:`ForceCoupling.apply` does all of it in one compiled call (:mod:`elastokin.vehicle.simulation.stepping`, which
also runs whole stretches of steps with ``mj_step`` inside the compiled loop).
"""

from __future__ import annotations

import math
from typing import Sequence

import mujoco
import numpy as np

from elastokin.bushings.extended_bank import ExtendedBank
from elastokin.vehicle.model.builder import CarModel
from elastokin.vehicle.model.elements import CrossTerm
from elastokin.vehicle.simulation import probes, stepping


def _pad_curves(curves) -> tuple[np.ndarray, np.ndarray]:
    """Curves as (E, P) arrays, padded by extending each last segment (for a batched lookup)."""
    n = max(len(c.x) for c in curves)
    xs, ys = np.zeros((len(curves), n)), np.zeros((len(curves), n))
    for i, c in enumerate(curves):
        x, y = list(c.x), list(c.y)
        slope = (y[-1] - y[-2]) / (x[-1] - x[-2])
        while len(x) < n:
            x.append(x[-1] + 1e3)
            y.append(y[-1] + 1e3 * slope)
        xs[i], ys[i] = x, y
    return xs, ys


class BushingForces:
    """The bushing directions of a model: one bank call per step, remainder into ``qfrc_applied``.

    Each channel's joint must carry its reference stiffness (K0 for linear laws, K0 + Kpa
    otherwise, see :func:`elastokin.vehicle.model.elements.joint_stiffness`). The parallel damping C is taken where
    the model put it: in the joint if the joint has damping (implicit), else in the bank (explicit).
    The bank is an :class:`elastokin.bushings.extended_bank.ExtendedBank`: a channel with a preload is mounted at
    the design position (deflection 0) on every reset, with zero force there. ``cross`` are the
    bushings' cross stiffnesses between channels (:class:`elastokin.vehicle.model.elements.CrossTerm`).
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, channels, cross: Sequence[CrossTerm] = ()):
        self.model, self.data = model, data
        ids = np.array([mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, c.joint) for c in channels], dtype=np.int64)
        self.jnt = ids
        self.qpos = model.jnt_qposadr[ids]
        self.dof = model.jnt_dofadr[ids]
        self.K = model.jnt_stiffness[ids].copy()
        self.C = model.dof_damping[self.dof].copy()
        self.bank_idx = np.flatnonzero([not c.linear for c in channels])
        params = [channels[i].params for i in self.bank_idx]
        params = [p.replace(C=0.0) if self.C[i] > 0 else p for p, i in zip(params, self.bank_idx)]
        effects = [channels[i].effects for i in self.bank_idx]
        #: possibly empty (all laws linear, in the joints); None = laws off, joints only (KCRig.bushing_laws_off)
        self.bank: ExtendedBank | None = ExtendedBank(params, effects)
        self.bank_jnt, self.bank_qpos = ids[self.bank_idx], self.qpos[self.bank_idx]
        self.bank_dof = self.dof[self.bank_idx]
        self.K_ref = self.K[self.bank_idx].copy()
        self.saturating = np.array([math.isfinite(p.S_sup) or math.isfinite(p.S_inf) or fx.active
                                    for p, fx in zip(params, effects)], dtype=np.bool_)
        #: the least K_ref of each bank channel [N/m or N·m/rad]: its joint's, and a slipping interface's
        #: stiffness on top (its tangent comes back at every reversal, a step before K_ref would follow)
        self.K_floor = self.K[self.bank_idx] + np.array([fx.slip_stiffness * p.K0 if fx.slip_force > 0.0 else 0.0
                                                         for p, fx in zip(params, effects)])
        index = {c.joint: i for i, c in enumerate(channels)}
        #: (P, 2) channel indices of each cross term's two directions, and its stiffness k (P,)
        self.cross_channels = np.array([[index[t.joint_a], index[t.joint_b]] for t in cross],
                                       dtype=np.int64).reshape(-1, 2)
        self.cross_k = np.array([t.stiffness for t in cross], dtype=float)

    def apply(self, dt: float) -> None:
        """Step the bank to the current deflections and add F(e) − K_ref·e, and the cross
        stiffnesses' forces, to ``qfrc_applied``."""
        d = self.data
        if self.bank is not None and self.bank.size:
            e = d.qpos[self.bank_qpos]
            force, tangent = self.bank.step(e, dt)
            if self.saturating.any():
                self.K_ref[:] = np.where(self.saturating, np.maximum(self.K_floor, tangent), self.K_ref)
                self.model.jnt_stiffness[self.bank_jnt] = self.K_ref
            d.qfrc_applied[self.bank_dof] += self.K_ref * e - force
        if self.cross_k.size:
            d.qfrc_applied[self.dof] -= self.cross_forces()

    def probe_args(self) -> tuple:
        """Arguments of :func:`elastokin.vehicle.simulation.probes.bushings` after (qpos, qvel)."""
        on = self.bank is not None
        return (self.qpos.astype(np.int64), self.dof.astype(np.int64), self.K, self.C, on,
                self.bank_idx.astype(np.int64) if on else np.zeros(0, np.int64),
                self.bank.force if on else np.zeros(0), self.cross_channels, self.cross_k)

    def deflections(self) -> np.ndarray:
        """Deflection of every direction [m or rad], in the bushing's frame."""
        return self._read()[0]

    def cross_forces(self) -> np.ndarray:
        """Force of the cross stiffnesses on every direction [N or N·m], resisting deflection."""
        q = self.data.qpos[self.qpos]
        a, b = self.cross_channels.T
        force = np.zeros(self.qpos.size)
        np.add.at(force, a, self.cross_k * q[b])
        np.add.at(force, b, self.cross_k * q[a])
        return force

    def forces(self) -> np.ndarray:
        """Force of every direction [N or N·m], resisting its deflection (joint damping included)."""
        return self._read()[1]

    def _read(self) -> tuple[np.ndarray, np.ndarray]:
        deflection, force = np.zeros(self.qpos.size), np.zeros(self.qpos.size)
        probes.bushings(deflection, force, self.data.qpos, self.data.qvel, *self.probe_args())
        return deflection, force

    def reset(self) -> None:
        """Forget the bushings' history (virgin state)."""
        if self.bank is not None:
            self.bank.reset()
            self.bank.force[:] = 0.0   # what the measurement reads before the next step (the kernel only writes it)


class ForceCoupling:
    """Writes the non-implicit forces of a :class:`CarModel` into ``MjData`` before every step.

    It owns ``qfrc_applied`` (rewritten every step); inputs from outside go to ``xfrc_applied``.
    """

    def __init__(self, car: CarModel, data: mujoco.MjData):
        self.model, self.car, self.data = car.model, car, data
        self.bushings = BushingForces(car.model, data, car.channels, car.cross)
        self._init_elements()
        self._kernel_bank: object = False  # the bank the compiled-kernel arrays were built for
        self._kernel: tuple = ()

    def _init_elements(self) -> None:
        m = self.model
        springs = [e for e in self.car.elements if e.spring is not None]
        dampers = [e for e in self.car.elements if e.damper_curve is not None]
        jid = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n)
        tid = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_TENDON, n)
        d0 = mujoco.MjData(m)
        mujoco.mj_forward(m, d0)

        def coords(elements):
            joint = np.array([e.kind == "joint" for e in elements])
            index = np.array([m.jnt_dofadr[jid(e.target)] if e.kind == "joint" else tid(e.target)
                              for e in elements])
            qadr = np.array([m.jnt_qposadr[jid(e.target)] if e.kind == "joint" else -1 for e in elements])
            design = np.array([0.0 if e.kind == "joint" else d0.ten_length[tid(e.target)] for e in elements])
            return joint, index, qadr, design, np.array([e.sign for e in elements])

        self.springs = springs
        self.sp_joint, self.sp_index, self.sp_qadr, self.sp_design, self.sp_sign = coords(springs)
        self.sp_xs, self.sp_ys = _pad_curves([e.spring.curve for e in springs])
        self.sp_rate = np.array([e.spring.rate for e in springs])
        self.sp_preload = np.array([e.preload for e in springs])
        self.sp_y0 = np.array([e.spring.curve(0.0) for e in springs])
        self.sp_nonlinear = any(len(e.spring.curve.x) > 2 for e in springs)
        self.dampers = dampers
        self.dp_joint, self.dp_index, self.dp_qadr, _, self.dp_sign = coords(dampers)
        self.dp_xs, self.dp_ys = _pad_curves([e.damper_curve for e in dampers])
        self.dp_offset = np.zeros(len(dampers))

    # -- every step --------------------------------------------------------------------------
    def kernel_arrays(self) -> tuple:
        """Arguments of :func:`elastokin.vehicle.simulation.stepping.coupling_step` after ``h`` (views of the model and
        data, and this coupling's tables), rebuilt when the bank is swapped (see BushingForces.bank)."""
        b = self.bushings
        if self._kernel_bank is not b.bank:
            self._kernel_bank = b.bank
            m, d = self.model, self.data
            self._kernel = (d.qpos, d.qvel, d.qfrc_applied, d.ten_length, d.ten_velocity, d.ten_J, m.ten_J_rowadr,
                            m.ten_J_rownnz, m.ten_J_colind, m.jnt_stiffness, m.dof_damping,
                            m.tendon_damping) + stepping.coupling_arrays(self)
        return self._kernel

    def apply(self, dt: float) -> None:
        """Compute and write the forces for the next step of length ``dt`` [s] (one compiled call)."""
        stepping.coupling_step(dt, *self.kernel_arrays())

    # -- outputs -----------------------------------------------------------------------------
    def probe_args(self) -> tuple:
        """(bushings, springs, dampers): the arguments of :func:`elastokin.vehicle.simulation.probes.bushings`
        after (qpos, qvel), of :func:`~elastokin.vehicle.simulation.probes.springs` after (qpos, ten_length)
        and of :func:`~elastokin.vehicle.simulation.probes.dampers` after (qvel, ten_velocity)."""
        spring = (np.asarray(self.sp_joint, bool), self.sp_qadr.astype(np.int64), self.sp_index.astype(np.int64),
                  self.sp_design, self.sp_sign.astype(float), self.sp_xs, self.sp_ys, self.sp_preload, self.sp_y0)
        damp = (np.asarray(self.dp_joint, bool), self.dp_index.astype(np.int64), self.dp_sign.astype(float),
                self.dp_xs, self.dp_ys)
        return self.bushings.probe_args(), spring, damp

    def reset(self) -> None:
        """Forget the bushings' history (virgin state)."""
        self.bushings.reset()
