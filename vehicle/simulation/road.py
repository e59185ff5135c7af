"""The car on a flat road: the same vehicle as on the K&C rig, mounted free, on Magic Formula tyres.

The body is free; the wheels spin on their hinges and stand on the road through their tyres
(:mod:`vsim_tyres.road_contact`, computed every step in the compiled loop with the bushings, see
:func:`vehicle.simulation.stepping.run_road`); the rack is driven (the steering) and each wheel
takes a drive torque and a brake (the spin joint's dry friction). Inputs per step: rack position
[m], four drive torques [N·m] (order of ``CORNERS``, positive driving), four brake torques [N·m].
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import mujoco
import numpy as np

from vehicle.model.builder import CarModel, build
from vehicle.model.definition import CORNERS, VehicleDefinition
from vehicle.model.elements import BuildOptions
from vehicle.model.statics import resolve_preloads
from vehicle.simulation import stepping
from vehicle.simulation.coupling import ForceCoupling
from vsim_core.shipped import DEFAULT_TYRE
from vsim_tyres import magic_formula
from vsim_tyres.road_contact import N_SIGNALS, N_STATE, SIGNALS, effective_rolling_radius, mirrored_wheels
from vsim_tyres.tir_file import read_tir

#: Columns of a row of road inputs: the rack, the four drive torques, the four brake torques.
N_INPUTS = 9
_NO_INPUTS = np.zeros((0, N_INPUTS))
_DEFLECTION = SIGNALS.index("deflection_m")


class RoadCar:
    """A vehicle on a flat road, stepped with its bushing coupling and its tyres."""

    def __init__(self, vehicle: VehicleDefinition, tyre_file: str | Path = DEFAULT_TYRE,
                 options: BuildOptions = BuildOptions()):
        options = dataclasses.replace(options, rig=False, clamped=False, road=True)
        self.vehicle = resolve_preloads(vehicle)
        self.car: CarModel = build(self.vehicle, options)
        m = self.model = self.car.model
        m.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
        self.data = mujoco.MjData(m)
        self.coupling = ForceCoupling(self.car, self.data)
        tir = read_tir(tyre_file)
        self.tyres = np.repeat(np.array([magic_formula.coefficients(tir)], dtype=magic_formula.DTYPE), len(CORNERS))
        self.mirrored = mirrored_wheels(tir.text("MODEL", "TYRESIDE", default="LEFT"),
                                        tuple(c.split("_")[1] for c in CORNERS))
        body = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)
        self.wheel_body = np.array([body(self.car.corners[c]["wheel"]) for c in CORNERS])
        spin = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"spin_{c}") for c in CORNERS]
        self.spin_dof = m.jnt_dofadr[spin].astype(np.int64)
        self.chassis_dof = m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "chassis_free")]
        self.rack_eq = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, "rack_drive")
        #: Lagged slips (κ', tan α') of each wheel and its signals (vsim_tyres.road_contact.SIGNALS).
        self.tyre_state = np.zeros((len(CORNERS), N_STATE))
        self.tyre_signals = np.zeros((len(CORNERS), N_SIGNALS))
        d = self.data   # views of MuJoCo's memory: the tyres' arguments hold for the car's life
        self._tyre_args = (self.tyres, self.mirrored, self.wheel_body, d.xipos, d.xmat, d.cvel, d.subtree_com,
                           m.body_rootid.astype(np.int64), self.tyre_state, d.xfrc_applied, self.tyre_signals)
        self.stepping_s = 0.0
        self._run(0, _NO_INPUTS)
        self.stepping_s = 0.0

    def _run(self, n: int, inputs: np.ndarray) -> None:
        m, d = self.model, self.data
        started = time.perf_counter()
        stepping.run_road(n, inputs, m.eq_data, self.rack_eq, self.spin_dof, m.dof_frictionloss, m._address, d._address,
                          m.opt.timestep, self.coupling.kernel_arrays(), self._tyre_args)
        self.stepping_s += time.perf_counter() - started
        b = self.coupling.bushings
        if b.bank is not None:
            b.bank_force = b.bank.force

    def step(self, n: int = 1) -> None:
        """Advance ``n`` time steps with the rack, drive and brakes held."""
        self._run(n, _NO_INPUTS)

    def play(self, inputs: np.ndarray) -> None:
        """Advance one step per row of ``inputs`` (rack [m], four drive torques, four brake torques
        [N·m]), each row set before its step."""
        inputs = np.ascontiguousarray(inputs, dtype=float)
        if inputs.ndim != 2 or inputs.shape[1] != N_INPUTS:  # the compiled loop does not check
            raise ValueError(f"expected road inputs of shape (steps, {N_INPUTS}), got {inputs.shape}")
        self._run(len(inputs), inputs)

    def set_brakes(self, torque: float) -> None:
        """Hold every wheel with a brake of ``torque`` [N·m] (0 releases them)."""
        self.model.dof_frictionloss[self.spin_dof] = torque

    def set_speed(self, speed: float) -> None:
        """Move the whole car forward at ``speed`` [m/s] (the wheels rolling at it, without slip)."""
        d = self.data
        d.qvel[self.chassis_dof] = speed
        for k, dof in enumerate(self.spin_dof):
            d.qvel[dof] = speed / effective_rolling_radius(self.tyres[k], self.tyre_signals[k, _DEFLECTION])

    def ride_height(self) -> float:
        """Height of the body's ride-height point above the road [m]."""
        return float(self.car.body_point(self.data, self.vehicle.body.ride_height_point)[2])

    def energy(self) -> float:
        """Kinetic energy of every body plus the potential energy of gravity and of the joints' and
        tendons' springs [J] (MuJoCo's; the tyres' and the bushing laws' explicit parts not included)."""
        mujoco.mj_forward(self.model, self.data)
        return float(self.data.energy.sum())
