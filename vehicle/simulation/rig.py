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

from vehicle.model.definition import CORNERS, SIDE_SIGN, VehicleDefinition
from vehicle.model.elements import BuildOptions
from vehicle.model.kinematics import wheel_orientation
from vehicle.simulation import stepping
from vehicle.simulation.mounted import MountedCar
from vehicle.simulation.outputs import RigOutputs, WheelOutputs

_NO_INPUTS = np.zeros((0, 17))
_INACTIVE = np.zeros(5, dtype=bool)
_ALL_ACTIVE = np.ones(5, dtype=bool)


class KCRig(MountedCar):
    """A vehicle on the K&C rig, stepped with its bushing coupling."""

    def __init__(self, vehicle: VehicleDefinition, options: BuildOptions = BuildOptions()):
        super().__init__(vehicle, dataclasses.replace(options, rig=True))
        m = self.model
        eq = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, n)
        body = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)
        self.pad_eq = np.array([eq(self.car.corners[c]["pad_drive"]) for c in CORNERS])
        self.pad_qpos = m.jnt_qposadr[[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, self.car.corners[c]["pad_z"])
                                       for c in CORNERS]]
        self.carriage_body = np.array([body(f"carriage_{c}") for c in CORNERS])
        self.centre_site = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, self.car.corners[c]["centre_site"])
                                     for c in CORNERS])
        self._run(0, _NO_INPUTS, _INACTIVE)
        self.stepping_s = 0.0

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
        """Set every rig input at once from ``u`` (SI, in the order of ``vehicle.scenarios.channels.INPUT_CHANNELS``,
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

    # -- running -----------------------------------------------------------------------------
    def step(self, n: int = 1) -> None:
        """Advance ``n`` time steps with the inputs held (compiled loop, the coupling called before each step)."""
        self._run(n, _NO_INPUTS, _INACTIVE)

    def play(self, inputs: np.ndarray) -> None:
        """Advance one time step per row of ``inputs`` (rig inputs in the order of
        ``vehicle.scenarios.channels.INPUT_CHANNELS``, SI), each row set before its step."""
        inputs = np.ascontiguousarray(inputs, dtype=float)
        if inputs.ndim != 2 or inputs.shape[1] != _NO_INPUTS.shape[1]:  # the compiled loop does not check
            raise ValueError(f"expected rig inputs of shape (steps, {_NO_INPUTS.shape[1]}), got {inputs.shape}")
        self._run(len(inputs), inputs, _ALL_ACTIVE)

    def _run(self, n: int, inputs: np.ndarray, active: np.ndarray) -> None:
        """``n`` compiled steps (vehicle.simulation.stepping.run) with ``inputs`` and ``active`` as it documents."""
        m, d = self.model, self.data
        self._timed(stepping.run, n, inputs, active, m.eq_data, self.pad_eq, self.rack_eq, d.xfrc_applied,
                    self.carriage_body, self.wheel_body, m._address, d._address, m.opt.timestep,
                    *self.coupling.kernel_arrays())

    def settle(self, duration: float = 1.0) -> None:
        """Run ``duration`` [s] with the inputs held."""
        self.step(int(round(duration / self.model.opt.timestep)))

    def pad_ramp(self, start, end, duration: float, samples: int = 0) -> list[RigOutputs]:
        """Move the pads linearly from ``start`` to ``end`` [m] in ``duration`` [s], sampling."""
        return self.ramp(duration, samples, pads=(start, end))

    def ramp(self, duration: float, samples: int = 0, pads=None, fx=None, fy=None, mz=None) -> list[RigOutputs]:
        """Move inputs linearly over ``duration`` [s], measuring every ⌊steps/samples⌋ steps.

        Each input given is a (start, end) pair of four values (order of ``CORNERS``): ``pads``
        contact-point displacements [m], ``fx``/``fy`` contact-point forces [N], ``mz`` aligning
        torques [N·m]; inputs not given are held.
        """
        h = self.model.opt.timestep
        n = max(1, int(round(duration / h)))
        every = max(1, n // samples) if samples else n + 1
        groups = (pads, fx, fy, mz)
        active = np.array([g is not None for g in groups] + [False])  # the rack is held
        start = np.concatenate([np.zeros(4) if g is None else np.asarray(g[0], float) for g in groups] + [[0.0]])
        end = np.concatenate([np.zeros(4) if g is None else np.asarray(g[1], float) for g in groups] + [[0.0]])
        out = []
        done = 0
        while done < n:
            k = min(every - done % every, n - done)
            f = (done + np.arange(1, k + 1)) / n
            self._run(k, start + (end - start) * f[:, None], active)
            done += k
            if done % every == 0:
                out.append(self.measure())
        return out

    # -- outputs -----------------------------------------------------------------------------
    def measure(self) -> RigOutputs:
        """The rig's outputs at the current state."""
        m, d = self.model, self.data
        mujoco.mj_forward(m, d)
        first_rows = self._eq_first_rows()
        fz = d.efc_force[first_rows[self.pad_eq]]
        wheels = {}
        for k, corner in enumerate(CORNERS):
            spin_left = d.xmat[self.wheel_body[k]].reshape(3, 3)[:, 1]
            toe, camber, steer = wheel_orientation(spin_left, SIDE_SIGN[corner])
            centre = d.site_xpos[self.centre_site[k]].copy()
            force = np.array([d.xfrc_applied[self.carriage_body[k], 0], d.xfrc_applied[self.carriage_body[k], 1], fz[k]])
            wheels[corner] = WheelOutputs(camber, toe, steer, abs(centre[1]), centre,
                                          force, float(d.qpos[self.pad_qpos[k]]),
                                          float(d.xfrc_applied[self.wheel_body[k], 5]))
        return RigOutputs(wheels=wheels, **self.suspension_outputs(first_rows))
