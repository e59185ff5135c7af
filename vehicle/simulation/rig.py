"""The virtual K&C rig: body clamped, each wheel on a pad, rack displacement input.

Pads impose the vertical displacement of each wheel's contact point (bump positive) and apply
longitudinal and lateral forces at it and an aligning torque about the vertical; the wheels are
braked. Outputs follow ISO 8855: toe-in positive, camber positive when the wheel top leans
outward, steer angle positive to the left, half-track = |y| of the wheel centre.
"""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np

from elastokin.vehicle.model.builder import CarModel
from elastokin.vehicle.model.definition import CORNERS, SIDE_SIGN, VehicleDefinition
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.simulation import stepping
from elastokin.vehicle.simulation.mounted import RESET_WARNINGS, MountedCar
from elastokin.vehicle.simulation.outputs import RIG_WHEEL, RigOutputs, WheelOutputs

_NO_INPUTS = np.zeros((0, 17))
_INACTIVE = np.zeros(5, dtype=bool)
_ALL_ACTIVE = np.ones(5, dtype=bool)


class KCRig(MountedCar):
    """A vehicle on the K&C rig, stepped with its bushing coupling."""

    def __init__(self, vehicle: VehicleDefinition, options: BuildOptions = BuildOptions(),
                 built: CarModel | None = None):
        """``built``: see :class:`~elastokin.vehicle.simulation.mounted.MountedCar`."""
        super().__init__(vehicle, dataclasses.replace(options, rig=True), built)
        m = self.model
        eq = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, n)
        body = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)
        self.pad_eq = np.array([eq(self.car.corners[c]["pad_drive"]) for c in CORNERS])
        self.pad_qpos = m.jnt_qposadr[[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, self.car.corners[c]["pad_z"])
                                       for c in CORNERS]]
        self.carriage_body = np.array([body(f"carriage_{c}") for c in CORNERS])
        self.centre_site = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, self.car.corners[c]["centre_site"])
                                     for c in CORNERS])
        #: Where each quantity sits in the rig's measured vector (:meth:`sampled`, :meth:`measure`).
        self.columns = self.measured_columns((), RIG_WHEEL)
        # The compiled measurement reads the constraint rows through views taken here: valid while
        # MuJoCo allocates them alike every step, which holds when their number cannot change
        # (checked) and is verified after every measurement.
        self.require_fixed_rows()
        mujoco.mj_forward(m, self.data)
        self._rows = self.equality_rows()
        self._efc_force, self._efc_pos = self.data.efc_force, self.data.efc_pos   # the views the probe reads
        self._efc = (self.data.nefc, self._efc_force.ctypes.data, self._efc_pos.ctypes.data)
        self._pad_row = self._rows[self.pad_eq].astype(np.int64)
        #: Each pad drive's force [N] in the last step (at rest, before any step: held target).
        self.pad_force = self._efc_force[self._pad_row].copy()
        self._run(0, _NO_INPUTS, _INACTIVE)   # compiles the stepping loop or loads it from numba's cache
        #: Wheel-centre heights at design [m] (order of CORNERS): the reference of the wheel travel.
        self.design_centre_z = self.data.site_xpos[self.centre_site, 2].copy()
        self._probe_bank: object = False   # the bank the probe's arguments were built for
        self._probe: tuple = ()
        self.sampled(1, 0)   # compiles the sampling loop or loads it from numba's cache: no steps, no change
        self.stepping_s = 0.0

    def stepped_arrays(self) -> tuple:
        """:meth:`MountedCar.stepped_arrays` and the pads' forces of the last step."""
        return (*super().stepped_arrays(), self.pad_force)

    # -- inputs ------------------------------------------------------------------------------
    def set_pads(self, heights) -> None:
        """Contact-point displacements [m] of the four pads (order of ``CORNERS``), bump positive."""
        self.model.eq_data[self.pad_eq, 0] = np.asarray(heights, float)

    def set_rack(self, displacement: float) -> None:
        """Rack displacement [m], positive to the left (+y)."""
        self.model.eq_data[self.rack_eq, 0] = displacement

    def set_pad_loads(self, fx=(0, 0, 0, 0), fy=(0, 0, 0, 0), mz=(0, 0, 0, 0)) -> None:
        """Longitudinal and lateral forces [N] at the contact points and aligning torques [N·m]."""
        d = self.data
        d.xfrc_applied[self.carriage_body, 0] = fx
        d.xfrc_applied[self.carriage_body, 1] = fy
        d.xfrc_applied[self.wheel_body, 5] = mz

    def set_inputs(self, u: np.ndarray) -> None:
        """Set every rig input at once from ``u`` (SI, in the order of ``elastokin.vehicle.scenarios.channels.INPUT_CHANNELS``,
        as :meth:`play` reads its rows)."""
        self.set_pads(u[0:4])
        self.set_pad_loads(fx=u[4:8], fy=u[8:12], mz=u[12:16])
        self.set_rack(u[16])

    def reset(self) -> None:
        """Back to the design pose at rest: virgin bushings, pads and rack at zero, no loads."""
        mujoco.mj_resetData(self.model, self.data)
        self.coupling.reset()
        self.set_pads([0.0] * 4)
        self.set_rack(0.0)
        mujoco.mj_forward(self.model, self.data)   # the pads' forces at rest (no step yet)
        self.pad_force[:] = self._efc_force[self._pad_row]

    # -- running -----------------------------------------------------------------------------
    def step(self, n: int = 1) -> None:
        """Advance ``n`` time steps with the inputs held (compiled loop, the coupling called before each step)."""
        self._run(n, _NO_INPUTS, _INACTIVE)

    def play(self, inputs: np.ndarray) -> None:
        """Advance one time step per row of ``inputs`` (rig inputs in the order of
        ``elastokin.vehicle.scenarios.channels.INPUT_CHANNELS``, SI), each row set before its step."""
        inputs = np.ascontiguousarray(inputs, dtype=float)
        if inputs.ndim != 2 or inputs.shape[1] != _NO_INPUTS.shape[1]:  # the compiled loop does not check
            raise ValueError(f"expected rig inputs of shape (steps, {_NO_INPUTS.shape[1]}), got {inputs.shape}")
        self._run(len(inputs), inputs, _ALL_ACTIVE)

    def _run(self, n: int, inputs: np.ndarray, active: np.ndarray, force_body: np.ndarray | None = None) -> None:
        """``n`` compiled steps (elastokin.vehicle.simulation.stepping.run) with ``inputs`` and ``active`` as it
        documents, Fx and Fy pushing ``force_body`` (default: the pads' carriages, at the contact points)."""
        m, d = self.model, self.data
        self._timed(stepping.run, n, inputs, active, m.eq_data, self.pad_eq, self.rack_eq, d.xfrc_applied,
                    self.carriage_body if force_body is None else force_body, self.wheel_body, self._efc_force, self._pad_row, self.pad_force, m._address,
                    d._address, m.opt.timestep,
                    *self.coupling.kernel_arrays())

    def settle(self, duration: float = 1.0) -> None:
        """Run ``duration`` [s] with the inputs held."""
        self.step(int(round(duration / self.model.opt.timestep)))

    def pad_ramp(self, start, end, duration: float, samples: int = 0) -> list[RigOutputs]:
        """Move the pads linearly from ``start`` to ``end`` [m] in ``duration`` [s], sampling."""
        return self.ramp(duration, samples, pads=(start, end))

    def ramp(self, duration: float, samples: int = 0, pads=None, fx=None, fy=None, mz=None,
             rack=None, at: str = "contact") -> list[RigOutputs]:
        """Move inputs linearly over ``duration`` [s], measuring every ⌊steps/samples⌋ steps.

        Each input given is a (start, end) pair of four values (order of ``CORNERS``): ``pads``
        contact-point displacements [m], ``fx``/``fy`` forces [N] at the contact points (``at``
        ``"contact"``: the pads' carriages) or at the wheel centres (``"centre"``: the wheels, the
        carriages free, as a drive shaft pushes), ``mz`` aligning torques [N·m]; ``rack`` a (start,
        end) pair of rack displacements [m, to the left]; inputs not given are held. Raises
        ValueError for another ``at``.
        """
        bodies = {"contact": self.carriage_body, "centre": self.wheel_body}
        if at not in bodies:
            raise ValueError(f"forces at {at!r}; expected one of {', '.join(bodies)}")
        h = self.model.opt.timestep
        n = max(1, int(round(duration / h)))
        every = max(1, n // samples) if samples else n + 1
        groups = (pads, fx, fy, mz)
        active = np.array([g is not None for g in groups] + [rack is not None])
        rack_ends = (0.0, 0.0) if rack is None else (float(rack[0]), float(rack[1]))
        start = np.concatenate([np.zeros(4) if g is None else np.asarray(g[0], float) for g in groups] + [[rack_ends[0]]])
        end = np.concatenate([np.zeros(4) if g is None else np.asarray(g[1], float) for g in groups] + [[rack_ends[1]]])
        out = []
        done = 0
        while done < n:
            k = min(every - done % every, n - done)
            f = (done + np.arange(1, k + 1)) / n
            self._run(k, start + (end - start) * f[:, None], active, bodies[at])
            done += k
            if done % every == 0:
                out.append(self.measure())
        return out

    def sampled(self, samples: int, every: int, inputs: np.ndarray = _NO_INPUTS,
                bodies: np.ndarray = np.zeros(0, np.int64)) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance ``samples × every`` steps, measuring after every ``every`` steps, without coming
        back to Python: the measured vectors (samples, columns) (:attr:`columns`) and the world poses
        of the bodies ``bodies`` (ids) (samples, bodies, 3) and (samples, bodies, 4). ``inputs``:
        one row per step as :meth:`play` takes them, or none (held). Fewer samples when MuJoCo
        reset the state (:meth:`was_reset`): up to the first that follows the reset."""
        inputs, measured, pos, quat = self._sampling(samples, every, inputs, _NO_INPUTS.shape[1], bodies, "rig")
        m, d = self.model, self.data
        rig = (m.eq_data, self.pad_eq, self.rack_eq, d.xfrc_applied, self.carriage_body, self.wheel_body,
               self._efc_force, self._pad_row, self.pad_force)
        done = self._timed(stepping.run_sampled, every, inputs, _ALL_ACTIVE if inputs.shape[0] else _INACTIVE, rig,
                           m._address, d._address, m.opt.timestep, self.coupling.kernel_arrays(), self._probe_args(),
                           bodies.astype(np.int64), d.xpos, d.xquat, measured, pos, quat, d.warning.number,
                           RESET_WARNINGS)
        self._check_rows()
        return measured[:done], pos[:done], quat[:done]

    # -- outputs -----------------------------------------------------------------------------
    def measure(self) -> RigOutputs:
        """The rig's outputs at the current state (one sample without steps): the pads' Fz are those
        of the last step (:attr:`pad_force`), so inputs set since without a step show in Fx, Fy and
        Mz (commands) but not yet in Fz."""
        return self.outputs(self.sampled(1, 0)[0][0])

    def outputs(self, v: np.ndarray) -> RigOutputs:
        """The :class:`RigOutputs` of one measured vector ``v`` (:attr:`columns`)."""
        cols, c = self.columns, self.coupling
        wheels = {}
        for k, corner in enumerate(CORNERS):
            w = dict(zip(RIG_WHEEL, v[cols.wheels_start + k * len(RIG_WHEEL):][:len(RIG_WHEEL)].tolist()))
            wheels[corner] = WheelOutputs(w["camber"], w["toe"], w["steer"], w["half_track"], w["travel"],
                                          np.array([w["centre_x"], w["centre_y"], w["centre_z"]]),
                                          np.array([w["pad_fx"], w["pad_fy"], w["pad_fz"]]), w["pad_height"],
                                          w["pad_torque"])
        return RigOutputs(time=float(self.data.time), bushing_names=tuple(ch.name for ch in self.car.channels),
                          bushing_deflection=v[cols.deflection].copy(), bushing_force=v[cols.force].copy(),
                          spring_force=dict(zip((e.name for e in c.springs), v[cols.springs].tolist())),
                          damper_force=dict(zip((e.name for e in c.dampers), v[cols.dampers].tolist())),
                          closure_error=float(v[cols.closure_error]), wheels=wheels)

    def _probe_args(self) -> tuple:
        """The arguments of :func:`elastokin.vehicle.simulation.probes.rig_sample` after ``out`` (rebuilt when
        the bushing laws are switched, see MountedCar.bushing_laws_off)."""
        bank = self.coupling.bushings.bank
        if self._probe_bank is not bank:
            self._probe_bank = bank
            d = self.data
            wheels = (d.xmat, d.site_xpos, d.xfrc_applied, d.qpos, self.pad_force, self.wheel_body.astype(np.int64),
                      self.centre_site.astype(np.int64), self.carriage_body.astype(np.int64),
                      self.pad_qpos.astype(np.int64),
                      np.array([SIDE_SIGN[c] for c in CORNERS], dtype=float), self.design_centre_z)
            data = (d.qpos, d.qvel, d.ten_length, d.ten_velocity, self._efc_pos)
            self._probe = (wheels, data, self.suspension_args(self._rows))
        return self._probe

    def _check_rows(self) -> None:
        """Raise RuntimeError if MuJoCo moved the constraint rows from where the compiled measurement
        reads them (the views taken at construction)."""
        d = self.data
        if (d.nefc, d.efc_force.ctypes.data, d.efc_pos.ctypes.data) != self._efc:
            raise RuntimeError("the rig's constraint rows moved: its last measurement read stale memory")
