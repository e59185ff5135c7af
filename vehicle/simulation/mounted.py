"""What every mounting of the car shares (the K&C rig, :mod:`elastokin.vehicle.simulation.rig`; the road,
:mod:`elastokin.vehicle.simulation.road`): the vehicle built with its springs' preloads, its MuJoCo state,
the bushing coupling, the wheels, the columns of its measured vector and the suspension's part of
it, MuJoCo's resets, the body's ride height, switching the bushing laws off while the car
settles, its state copied out and back (:class:`CarState`), and the time spent in the compiled
stepping loop."""

from __future__ import annotations

import copy
import time
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Callable, Iterator

import mujoco
import numpy as np

from elastokin.vehicle.model.builder import CarModel, build
from elastokin.vehicle.model.definition import CORNERS, VehicleDefinition
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.statics import resolve_preloads
from elastokin.vehicle.simulation import probes
from elastokin.vehicle.simulation.coupling import ForceCoupling
from elastokin.vehicle.simulation.outputs import MeasuredColumns

# a plain int: comparing an array with the pybind enum goes element by element through Python (100 µs)
_EQUALITY_ROW = int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
#: MuJoCo's warnings that come with a reset of the state (a non-finite or huge position, velocity or acceleration).
RESET_WARNINGS = np.array([int(w) for w in (mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL,
                                            mujoco.mjtWarning.mjWARN_BADQACC)], dtype=np.int64)


@dataclass(frozen=True)
class CarState:
    """A copy of everything a mounted car's stepping reads and writes (:meth:`MountedCar.snapshot`)."""

    data: mujoco.MjData            #: MuJoCo's state
    arrays: tuple[np.ndarray, ...]  #: the arrays of :meth:`MountedCar.stepped_arrays`, in their order


def _arrays(items) -> Iterator[np.ndarray]:
    """The numpy arrays in ``items``, nested tuples walked in order (scalars are no state)."""
    for item in items:
        if isinstance(item, np.ndarray):
            yield item
        elif isinstance(item, tuple):
            yield from _arrays(item)


class MountedCar:
    """A vehicle built for one mounting (``options``), with its bushing coupling."""

    def __init__(self, vehicle: VehicleDefinition, options: BuildOptions, built: CarModel | None = None):
        """``built``: this vehicle already compiled with these options (a scenario's first case's car,
        :meth:`CarModel.copy` of it before it ran), used instead of compiling again."""
        self.vehicle = resolve_preloads(vehicle)
        if built is not None and (built.definition is not self.vehicle or built.options != options):
            raise ValueError("a car built for another vehicle or other build options")
        self.car: CarModel = build(self.vehicle, options) if built is None else built.copy()
        m = self.model = self.car.model
        self.data = mujoco.MjData(m)
        self.coupling = ForceCoupling(self.car, self.data)
        body = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)
        self.wheel_body = np.array([body(self.car.corners[c]["wheel"]) for c in CORNERS])
        eq = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, n)
        self.rack_eq = eq("rack_drive")
        self.closure_eq = np.array([eq(n) for n in self.car.closures])
        self.closure_rows = np.array([3 if m.eq_type[i] != mujoco.mjtEq.mjEQ_TENDON else 1 for i in self.closure_eq])
        #: Wall time spent in the compiled stepping loops so far [s] (the end-to-end benchmark's reference),
        #: without the mounting's first, empty calls, which compile the loops or load them from numba's cache.
        self.stepping_s = 0.0

    def _timed(self, loop: Callable[..., Any], *args) -> Any:
        """Call the compiled ``loop`` with ``args``, adding its wall time to :attr:`stepping_s`; its result."""
        started = time.perf_counter()
        result = loop(*args)
        self.stepping_s += time.perf_counter() - started
        return result

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

    def stepped_arrays(self) -> tuple:
        """The arrays beside MuJoCo's data that the stepping reads and writes: the model's driven
        targets (``eq_data``) and the bushings' tangents it holds (joints' stiffness and damping,
        tendons' damping), and every array of the coupling's compiled step (the bushing bank's
        states, its effects' states, the reference stiffnesses; the views of MuJoCo's data among
        them too), with the bushing laws as they are now."""
        m = self.model
        return (m.eq_data, m.jnt_stiffness, m.dof_damping, m.tendon_damping, *self.coupling.kernel_arrays())

    def snapshot(self) -> CarState:
        """A copy of the car's state (MuJoCo's and :meth:`stepped_arrays`), for :meth:`restore`."""
        return CarState(copy.copy(self.data), tuple(a.copy() for a in _arrays(self.stepped_arrays())))

    def restore(self, state: CarState) -> None:
        """Put back a state :meth:`snapshot` took of this car or of another built alike (a copy of its
        model), with the bushing laws on as then: its steps from there are the same bits as the
        snapshot's car's. In place: the compiled loops keep views of these arrays."""
        mujoco.mj_copyData(self.data, self.model, state.data)
        arrays = list(_arrays(self.stepped_arrays()))
        if [a.shape for a in arrays] != [a.shape for a in state.arrays]:
            raise ValueError("a state taken of a car built otherwise, or with its bushing laws otherwise")
        for target, saved in zip(arrays, state.arrays):
            target[...] = saved

    def _sampling(self, samples: int, every: int, inputs: np.ndarray, width: int, bodies: np.ndarray, what: str
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """For a subclass's ``sampled``: its ``inputs`` checked (``width`` columns, one row per step
        or none; ValueError naming ``what`` else) and the buffers its compiled loop fills: measured
        vectors (samples, columns), body positions (samples, bodies, 3) and orientations (samples,
        bodies, 4)."""
        inputs = np.ascontiguousarray(inputs, dtype=float)
        if inputs.shape[0] not in (0, samples * every) or inputs.shape[1:] != (width,):
            raise ValueError(f"expected {what} inputs of shape ({samples * every}, {width}), got {inputs.shape}")
        return (inputs, np.empty((samples, self.columns.size)), np.empty((samples, bodies.size, 3)),
                np.empty((samples, bodies.size, 4)))

    def require_fixed_rows(self) -> None:
        """ValueError unless the number of MuJoCo's constraint rows cannot change within a run of
        steps (no contacts, no limits): the compiled measurement reads the rows through views."""
        m = self.model
        if not (m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONTACT) or m.jnt_limited.any() or m.tendon_limited.any():
            raise ValueError("the car's measurement needs a model without MuJoCo contacts or limits")

    def was_reset(self) -> bool:
        """Whether MuJoCo has reset the state since the car was built (see :data:`RESET_WARNINGS`)."""
        return bool(self.data.warning.number[RESET_WARNINGS].any())

    def ride_height(self) -> float:
        """Height of the body's ride-height point above the ground [m]."""
        return float(self.car.body_point(self.data, self.vehicle.body.ride_height_point)[2])

    def measured_columns(self, head: tuple[str, ...], wheel: tuple[str, ...]) -> MeasuredColumns:
        """The columns of this car's measured vector with the mounting's ``head`` and ``wheel`` quantities."""
        return MeasuredColumns(head, wheel, len(self.coupling.springs), len(self.coupling.dampers),
                               len(self.car.channels))

    def equality_rows(self) -> np.ndarray:
        """Index in ``efc_*`` of the first row of every equality, -1 where inactive (after ``mj_forward``)."""
        d = self.data
        return probes.first_rows(d.efc_type, d.efc_id, d.nefc, self.model.neq, _EQUALITY_ROW)

    def suspension_args(self, rows: np.ndarray) -> tuple:
        """The arguments of :func:`elastokin.vehicle.simulation.probes.suspension` after its data (bushings,
        springs, dampers, closures), ``rows`` from :meth:`equality_rows`."""
        closure = (rows[self.closure_eq].astype(np.int64), self.closure_rows.astype(np.int64))
        return (*self.coupling.probe_args(), closure)

    def suspension_data(self) -> tuple:
        """The data arguments of :func:`elastokin.vehicle.simulation.probes.suspension` (views of MuJoCo's memory)."""
        d = self.data
        return d.qpos, d.qvel, d.ten_length, d.ten_velocity, d.efc_pos
