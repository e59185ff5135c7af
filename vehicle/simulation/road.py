"""The car on a flat road: the same vehicle as on the K&C rig, mounted free, on Magic Formula tyres.

The body is free; the wheels spin on their hinges and stand on the road through their tyres
(:mod:`elastokin.tyres.road_contact`, computed every step in the compiled loop with the bushings, see
:func:`elastokin.vehicle.simulation.stepping.run_road`); the steering wheel drives the rack through the car's
``front.steering.rack_travel_per_rev``; a driver holds the speed with a PI controller of the front
wheels' drive torque (front-wheel drive), or holds its last torque (a fixed throttle); each wheel
also takes an extra drive torque and a brake (the spin joint's dry friction). Inputs per step
(:data:`N_INPUTS` columns): rack [m], target speed [m/s] (NaN: the throttle held), four drive
torques [N·m] (order of ``CORNERS``, positive driving), four brake torques [N·m].

Outputs (:meth:`RoadCar.sampled`, measured in the compiled loop by elastokin.vehicle.simulation.probes; the
columns of elastokin.vehicle.simulation.outputs.ROAD_BODY and ROAD_WHEEL) follow ISO 8855: the body's motion
in the intermediate axis system (x forward and y left in the road's plane, turned by the yaw
angle), at the body's centre of mass; wheel angles relative to the body as on the rig (toe-in,
camber top-out, steer to the left positive).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import mujoco
import numpy as np

from elastokin.vehicle.model.builder import CarModel
from elastokin.vehicle.model.definition import CORNERS, SIDE_SIGN, VehicleDefinition
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.kinematics import steering_ratio
from elastokin.vehicle.simulation import stepping
from elastokin.vehicle.simulation.mounted import RESET_WARNINGS, MountedCar
from elastokin.vehicle.simulation.outputs import ROAD_BODY, ROAD_WHEEL
from elastokin.core.errors import InputError
from elastokin.tyres import magic_formula
from elastokin.tyres.road_contact import N_SIGNALS, N_STATE, SIGNALS, effective_rolling_radius, mirrored_wheels
from elastokin.tyres.tir_file import read_tir

#: Columns of a row of road inputs: the rack, the target speed, four drive torques, four brake torques.
N_INPUTS = 10
_NO_INPUTS = np.zeros((0, N_INPUTS))
_DEFLECTION = SIGNALS.index("deflection_m")
#: The driver's speed loop: natural frequency [Hz] and damping ratio of the car's speed under the PI
#: controller (slow beside the handling, which it must not steer; fast beside the speed ramps).
SPEED_LOOP_HZ, SPEED_LOOP_DAMPING = 0.5, 1.0
#: Below this speed [m/s] the body's sideslip is reported as 0 (at rest its direction is noise).
SIDESLIP_MIN_SPEED_MPS = 0.5


class RoadCar(MountedCar):
    """A vehicle on a flat road with a driver, stepped with its bushing coupling and its tyres."""

    def __init__(self, vehicle: VehicleDefinition, tyre_file: str | Path | None = None,
                 options: BuildOptions = BuildOptions(), built: CarModel | None = None):
        """``tyre_file``: the .tir of all four tyres (default: the vehicle file's ``tyre.property_file``).
        InputError naming the vehicle file when neither names one. ``built``: see
        :class:`~elastokin.vehicle.simulation.mounted.MountedCar`."""
        tyre_file = tyre_file or vehicle.tyre.property_file
        if tyre_file is None:
            raise InputError("the car on the road needs a tyre: give tyre.property_file (a .tir file)",
                             source=str(vehicle.path), key="tyre.property_file")
        tir = read_tir(tyre_file)
        super().__init__(vehicle, dataclasses.replace(options, rig=False, clamped=False, road=True), built)
        m, d = self.model, self.data
        m.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
        self.tyre_file = Path(tyre_file)
        self.tyres = np.repeat(np.array([magic_formula.coefficients(tir)], dtype=magic_formula.DTYPE), len(CORNERS))
        self.mirrored = mirrored_wheels(tir.text("MODEL", "TYRESIDE", default="LEFT"),
                                        tuple(c.split("_")[1] for c in CORNERS))
        spin = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"spin_{c}") for c in CORNERS]
        self.spin_dof = m.jnt_dofadr[spin].astype(np.int64)
        self.chassis = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "chassis")
        self.rack_qpos = int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "rack")])
        self.chassis_dof = int(m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "chassis_free")])
        #: Lagged slips (κ', tan α') of each wheel and its signals (elastokin.tyres.road_contact.SIGNALS).
        self.tyre_state = np.zeros((len(CORNERS), N_STATE))
        self.tyre_signals = np.zeros((len(CORNERS), N_SIGNALS))
        # the steering wheel turned left steers left: the rack moves towards the steering arms' side
        hp = self.vehicle.front.hardpoints
        ahead = 1.0 if hp["tie_rod_outer"][0] > hp["wheel_centre"][0] else -1.0
        #: Rack travel per radian of steering-wheel angle [m/rad], signed so that + steers left.
        self.rack_per_rad = ahead * self.vehicle.front.rack_travel_per_rev / (2.0 * math.pi)
        # MuJoCo's soft equality pulls the rack's velocity to zero: a ramped target is followed
        # b/k = 2·d·timeconst·dampratio² late (4 ms: the response times would be that late); the
        # target is taken that much ahead instead (continuous,
        # unlike a lead of that time times the rate, which jumps at a ramp's corners).
        (timeconst, damping), impedance = m.eq_solref[self.rack_eq], m.eq_solimp[self.rack_eq, 1]
        #: How far ahead the rack's target is taken from the steering wheel [s] (the constraint's ramp lag).
        self.rack_lead_s = 2.0 * impedance * timeconst * damping ** 2   # no refsafe floor: see builder
        #: The overall steering ratio at straight ahead (kinematic) and the wheelbase [m].
        self.steering_ratio = steering_ratio(self.vehicle)
        self.wheelbase = float(hp["wheel_centre"][0] - self.vehicle.rear.hardpoints["wheel_centre"][0])
        mass = float(m.body_mass.sum())
        w = 2.0 * math.pi * SPEED_LOOP_HZ
        #: Integral of the speed error [m] and the drive force [N] of the driver's controller.
        self.driver_state = np.zeros(2)
        front = np.array([c.startswith("front") for c in CORNERS], dtype=float)
        d = self.data   # views of MuJoCo's memory: the loop's arguments hold for the car's life
        self._driver = (d.qvel, d.xmat, self.chassis_dof, self.chassis, front / front.sum(),
                        np.array([2.0 * SPEED_LOOP_DAMPING * w * mass, w * w * mass, self.vehicle.tyre.radius]),
                        self.driver_state)
        self._tyre_args = (self.tyres, self.mirrored, self.wheel_body, d.xipos, d.xmat, d.cvel, d.subtree_com,
                           m.body_rootid.astype(np.int64), self.tyre_state, d.xfrc_applied, self.tyre_signals)
        self._design_z = np.array([getattr(self.vehicle, c.split("_")[0]).hardpoints["wheel_centre"][2]
                                   for c in CORNERS])
        self._run(0, _NO_INPUTS)
        #: Where each quantity sits in the car's measured vector (:meth:`sampled`, :meth:`measure`).
        self.columns = self.measured_columns(ROAD_BODY, ROAD_WHEEL + tuple(SIGNALS))
        self._sign = np.array([SIDE_SIGN[c] for c in CORNERS], dtype=float)
        # the measurement reads the constraint rows through views taken before each call: valid
        # while their number cannot change within it (checked)
        self.require_fixed_rows()
        self.sampled(1, 0)   # compiles the sampling loop or loads it from numba's cache: no steps, no change
        self.stepping_s = 0.0

    def _run(self, n: int, inputs: np.ndarray) -> None:
        m, d = self.model, self.data
        self._timed(stepping.run_road, n, inputs, m.eq_data, self.rack_eq, self.spin_dof, m.dof_frictionloss,
                    m._address, d._address, m.opt.timestep, self.coupling.kernel_arrays(), self._tyre_args,
                    self._driver)

    def step(self, n: int = 1) -> None:
        """Advance ``n`` time steps with the rack, drive and brakes held (the speed controller idle)."""
        self._run(n, _NO_INPUTS)

    def play(self, inputs: np.ndarray) -> None:
        """Advance one step per row of ``inputs`` (:data:`N_INPUTS` columns, see the module), each row
        set before its step."""
        inputs = np.ascontiguousarray(inputs, dtype=float)
        if inputs.ndim != 2 or inputs.shape[1] != N_INPUTS:  # the compiled loop does not check
            raise ValueError(f"expected road inputs of shape (steps, {N_INPUTS}), got {inputs.shape}")
        self._run(len(inputs), inputs)

    def drive_inputs(self, steering_wheel_rad: np.ndarray, speed_mps: np.ndarray) -> np.ndarray:
        """Rows of inputs for steering-wheel angles [rad] (+ to the left) and target speeds [m/s] (NaN:
        the throttle held), without extra torques or brakes. For the rack to follow a moving
        steering wheel without the constraint's lag, give the angles :attr:`rack_lead_s` ahead."""
        u = np.zeros((len(steering_wheel_rad), N_INPUTS))
        u[:, 0] = self.rack_per_rad * np.asarray(steering_wheel_rad, float)
        u[:, 1] = speed_mps
        return u

    def set_brakes(self, torque: float) -> None:
        """Hold every wheel with a brake of ``torque`` [N·m] (0 releases them)."""
        self.model.dof_frictionloss[self.spin_dof] = torque

    def set_speed(self, speed: float) -> None:
        """Move the whole car forward at ``speed`` [m/s] (the wheels rolling at it, without slip), the
        driver's controller from rest."""
        d = self.data
        d.qvel[self.chassis_dof] = speed
        for k, dof in enumerate(self.spin_dof):
            d.qvel[dof] = speed / effective_rolling_radius(self.tyres[k], self.tyre_signals[k, _DEFLECTION])
        self.driver_state[:] = 0.0

    def energy(self) -> float:
        """Kinetic energy of every body plus the potential energy of gravity and of the joints' and
        tendons' springs [J] (MuJoCo's; the tyres' and the bushing laws' explicit parts not included)."""
        mujoco.mj_forward(self.model, self.data)
        return float(self.data.energy.sum())

    def sampled(self, samples: int, every: int, inputs: np.ndarray = _NO_INPUTS,
                bodies: np.ndarray = np.zeros(0, np.int64)) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance ``samples × every`` steps, measuring after every ``every`` steps, without coming
        back to Python: the measured vectors (samples, columns) (:attr:`columns`) and the world poses
        of the bodies ``bodies`` (ids) (samples, bodies, 3) and (samples, bodies, 4). ``inputs``:
        one row per step as :meth:`play` takes them, or none (held, the speed controller idle).
        Fewer samples when MuJoCo reset the state (:meth:`was_reset`): up to the first that follows
        the reset."""
        inputs, measured, pos, quat = self._sampling(samples, every, inputs, N_INPUTS, bodies, "road")
        m, d = self.model, self.data
        # the constraint rows as they are now (the brakes add or remove some between calls)
        mujoco.mj_forward(m, d)
        rows, efc = self.equality_rows(), (d.nefc, d.efc_pos.ctypes.data)
        body = (d.xmat, d.xipos, d.qpos, self.chassis, self.rack_qpos, self.driver_state, m.opt.gravity,
                SIDESLIP_MIN_SPEED_MPS)
        wheels = (d.xmat, d.xipos, d.xpos, self.wheel_body.astype(np.int64), self.chassis, self._sign, self._design_z,
                  self.tyre_signals)
        probe = (body, wheels, self.suspension_data(), self.suspension_args(rows))
        done = self._timed(stepping.run_road_sampled, every, inputs, (m.eq_data, self.rack_eq, self.spin_dof,
                           m.dof_frictionloss), m._address, d._address, m.opt.timestep, self.coupling.kernel_arrays(),
                           self._tyre_args, self._driver, self.chassis, probe, bodies.astype(np.int64), d.xpos,
                           d.xquat, measured, pos, quat, d.warning.number, RESET_WARNINGS)
        if (d.nefc, d.efc_pos.ctypes.data) != efc:
            raise RuntimeError("the road car's constraint rows moved: its last measurement read stale memory")
        return measured[:done], pos[:done], quat[:done]

    def measure(self) -> np.ndarray:
        """The car's measured vector at the current state (:attr:`columns`; ISO 8855, see the module)."""
        return self.sampled(1, 0)[0][0]
