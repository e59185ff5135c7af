"""What every mounting of the car shares (the K&C rig, :mod:`vehicle.simulation.rig`; the road,
:mod:`vehicle.simulation.road`): the vehicle built with its springs' preloads, its MuJoCo state,
the bushing coupling, the wheels, the loop closures' errors, the body's ride height, switching the
bushing laws off while the car settles, and the time spent in the compiled stepping loop."""

from __future__ import annotations

import time
from contextlib import contextmanager
from typing import Any, Callable, Iterator

import mujoco
import numpy as np

from vehicle.model.builder import CarModel, build
from vehicle.model.definition import CORNERS, VehicleDefinition
from vehicle.model.elements import BuildOptions
from vehicle.model.statics import resolve_preloads
from vehicle.simulation.coupling import ForceCoupling

# a plain int: comparing an array with the pybind enum goes element by element through Python (100 µs)
_EQUALITY_ROW = int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)


class MountedCar:
    """A vehicle built for one mounting (``options``), with its bushing coupling."""

    def __init__(self, vehicle: VehicleDefinition, options: BuildOptions):
        self.vehicle = resolve_preloads(vehicle)
        self.car: CarModel = build(self.vehicle, options)
        m = self.model = self.car.model
        self.data = mujoco.MjData(m)
        self.coupling = ForceCoupling(self.car, self.data)
        body = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)
        self.wheel_body = np.array([body(self.car.corners[c]["wheel"]) for c in CORNERS])
        eq = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, n)
        self.rack_eq = eq("rack_drive")
        self.closure_eq = np.array([eq(n) for n in self.car.closures])
        self.closure_rows = np.array([3 if m.eq_type[i] != mujoco.mjtEq.mjEQ_TENDON else 1 for i in self.closure_eq])
        #: Wall time spent in the compiled stepping loop so far [s] (the end-to-end benchmark's reference),
        #: without the mounting's first, empty call, which compiles the loop or loads it from numba's cache.
        self.stepping_s = 0.0

    def _timed(self, loop: Callable[..., None], *args) -> None:
        """Call the compiled ``loop`` with ``args``, adding its wall time to :attr:`stepping_s`."""
        started = time.perf_counter()
        loop(*args)
        self.stepping_s += time.perf_counter() - started
        b = self.coupling.bushings
        if b.bank is not None:
            b.bank_force = b.bank.force

    @contextmanager
    def bushing_laws_off(self) -> Iterator[None]:
        """Within the block every bushing direction is linear, with the stiffness and damping held
        in its joint (the reference tangent); on leaving, the laws are back, from their virgin state
        (the thesis settles the car this way before switching the bushing models on)."""
        # The coupling skips a bank it does not have and then reports the joint forces of every channel.
        forces = self.coupling.bushings
        laws, forces.bank = forces.bank, None
        try:
            yield
        finally:
            forces.bank = laws
            self.coupling.reset()

    def ride_height(self) -> float:
        """Height of the body's ride-height point above the ground [m]."""
        return float(self.car.body_point(self.data, self.vehicle.body.ride_height_point)[2])

    def suspension_outputs(self, first_rows: np.ndarray) -> dict[str, Any]:
        """The fields of :class:`~vehicle.simulation.outputs.SuspensionOutputs` at the current state
        (``mj_forward`` done; ``first_rows`` from :meth:`_eq_first_rows`)."""
        c = self.coupling
        return dict(time=float(self.data.time), bushing_names=tuple(ch.name for ch in self.car.channels),
                    bushing_deflection=c.bushings.deflections(), bushing_force=c.bushings.forces(),
                    spring_force=dict(zip((e.name for e in c.springs), c.spring_forces().tolist())),
                    damper_force=dict(zip((e.name for e in c.dampers), c.damper_forces().tolist())),
                    closure_error=self._closure_error(first_rows))

    def _eq_first_rows(self) -> np.ndarray:
        """Index in ``efc_*`` of the first row of every equality, -1 where inactive (an equality's
        rows are consecutive)."""
        d = self.data
        rows = np.flatnonzero(d.efc_type[: d.nefc] == _EQUALITY_ROW)
        first = np.full(self.model.neq, -1)
        eq, at = np.unique(d.efc_id[rows], return_index=True)
        first[eq] = rows[at]
        return first

    def _closure_error(self, first_rows: np.ndarray) -> float:
        """Largest position error of the loop closures [m] (connect, weld position, tie-rod length),
        from the equalities' first rows (:meth:`_eq_first_rows`)."""
        d = self.data
        rows = first_rows[self.closure_eq][:, None] + np.arange(3)
        used = np.arange(3) < self.closure_rows[:, None]  # 3 position rows, 1 for a tendon length
        pos = np.where(used, d.efc_pos[np.minimum(rows, d.nefc - 1)], 0.0)
        return float(np.sqrt((pos * pos).sum(axis=1)).max())
