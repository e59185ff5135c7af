"""Recording a scenario run: played on the rig (:class:`elastokin.vehicle.simulation.runner.ScenarioRun`) or on
the road (:class:`elastokin.vehicle.simulation.road_runner.RoadRun`) and written block by block into one MCAP
run file by a thread of its own (:func:`run_scenario`, :mod:`elastokin.recordings.background`), or kept
in memory as the same :class:`elastokin.recordings.run_format.Run`, with or without the body poses
(:func:`simulate`; :func:`elastokin.recordings.run_writer.write_run` records it later, the same bytes).

The file is closed and marked incomplete when the run stops early: divergence, Ctrl-C or any other
exception (:class:`elastokin.recordings.run_writer.RunWriter`).
"""

from __future__ import annotations

import time
import warnings
from contextlib import closing
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable

import mujoco
import numpy as np

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.vehicle_file import as_filed, load_vehicle
from elastokin.vehicle.scenarios.road_scenario import RoadScenario
from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.vehicle.scenarios.schedule import Progress
from elastokin.vehicle.simulation.mounted import MountedCar
from elastokin.vehicle.simulation.road_runner import RoadRun
from elastokin.vehicle.simulation.runner import ScenarioRun
from elastokin.vehicle.simulation.unconverged import UnconvergedBushingSteps, UnconvergedSteps, summary
from elastokin.recordings.background import BackgroundWriter
from elastokin.recordings.road_signals import RoadSignalLayout
from elastokin.recordings.run_format import GeomSpec, Run, RunMetadata, rotation_matrix
from elastokin.recordings.run_signals import SignalLayout, road_facts, run_metadata
from elastokin.recordings.run_writer import RunWriter


@dataclass(frozen=True)
class RunResult:
    """A finished run: the file, its simulated and wall-clock durations, the time spent in the
    compiled stepping loop (first call excepted), and the run kept in memory, so that a summary
    needs no second reading: times, signals and body poses as the file holds them, bit for bit; the
    metadata as written (tuples and key order where the file, through JSON, has lists and sorted keys)."""

    path: Path
    simulated_s: float
    wall_s: float
    stepping_s: float
    run: Run


def default_output(scenario: Scenario) -> Path:
    """``out/<scenario name>.mcap`` in the working directory."""
    return Path("out") / f"{scenario.name}.mcap"


def _suspension(car: MountedCar) -> tuple[list[str], list[str], list[str]]:
    """The names of ``car``'s bushing directions, springs and dampers, as the layouts take them."""
    c = car.coupling
    return [ch.name for ch in car.car.channels], [e.name for e in c.springs], [e.name for e in c.dampers]


def _play(scenario: Scenario | RoadScenario, vehicle: VehicleDefinition, duration_scale: float,
          progress: Callable[[Progress], None] | None, timestep_s: float | None = None, poses: bool = True
          ) -> tuple[ScenarioRun | RoadRun, SignalLayout | RoadSignalLayout, RunMetadata]:
    """The run of ``scenario`` on ``vehicle`` (on the rig or on the road, as its type says; with the
    bodies' ``poses`` or not), the signals it records and its metadata."""
    if isinstance(scenario, RoadScenario):
        play = RoadRun(scenario, vehicle, duration_scale, progress, timestep_s, poses)
        layout = RoadSignalLayout(*_suspension(play.car))
        road = road_facts(play.car.steering_ratio, play.car.wheelbase, play.car.tyre_file)
    else:
        play = ScenarioRun(scenario, vehicle, duration_scale, progress, timestep_s, poses)
        layout, road = SignalLayout(scenario.x_quantity, *_suspension(play.car)), None
    metadata = run_metadata(scenario, play.plan, duration_scale, play.dt, play.car.car.channels, road, vehicle.text)
    return play, layout, replace(metadata, extra={**metadata.extra, "vehicle_file": _vehicle_file(vehicle)})


def _vehicle_file(vehicle: VehicleDefinition) -> str:
    """What a run's metadata names as its vehicle file: the file, or, for a vehicle changed in code,
    the file it was changed from (the recording carries the changed text itself)."""
    path = vehicle.path.resolve()   # one spelling of the file, however it was named
    return str(path) if as_filed(vehicle) else f"{path} (changed in code)"


def run_scenario(scenario: Scenario | RoadScenario, output: Path, *, bushing_model: str | None = None, overwrite: bool = False,
                 duration_scale: float = 1.0, progress: Callable[[Progress], None] | None = None,
                 vehicle: VehicleDefinition | None = None) -> RunResult:
    """Run every case of ``scenario`` on ``vehicle`` (default: the scenario's file) and record them in
    ``output`` (one MCAP file).

    ``bushing_model`` overrides the scenario's choice; ``duration_scale`` multiplies every duration
    (settle phases, periods, holds) for quick runs. Raises InputError if ``output`` exists and not
    ``overwrite``, DivergenceError when the simulation diverges (the file is kept, incomplete).
    """
    output = Path(output)
    if bushing_model is not None:
        scenario = replace(scenario, bushing_model=bushing_model)
    started = time.perf_counter()
    play, layout, metadata = _play(scenario, load_vehicle(scenario.vehicle) if vehicle is None else vehicle,
                                   duration_scale, progress)
    output.parent.mkdir(parents=True, exist_ok=True)
    bodies = play.bodies()
    geometry = geometry_from_model(play.car.model, bodies)
    with RunWriter(output, signals=layout.specs, bodies=bodies, geometry=geometry, metadata=metadata,
                   overwrite=overwrite) as writer:
        try:
            # the blocks are closed first (the rig's context left at once if writing fails), then the queue is written
            with BackgroundWriter(writer, layout) as sink, closing(play.blocks()) as blocks:
                for block in blocks:
                    sink.put(block)
        finally:   # a run stopped early keeps what it found too
            writer.unconverged = play.unconverged.steps()
    # the times as the file holds them: whole nanoseconds
    run = _in_memory(output, np.concatenate(sink.times_ns) / 1e9, sink.values, layout, metadata,
                     (bodies, sink.body_pos, sink.body_quat_wxyz, geometry), writer.unconverged)
    return RunResult(output, play.total_s, time.perf_counter() - started, play.stepping_s, run)


def simulate(scenario: Scenario | RoadScenario, vehicle: VehicleDefinition | None = None, *, duration_scale: float = 1.0,
             progress: Callable[[Progress], None] | None = None, timestep_s: float | None = None,
             poses: bool = False) -> Run:
    """Run every case of ``scenario`` on ``vehicle`` (default: the scenario's file) in memory.

    The result is the :class:`Run` that :func:`run_scenario` would record (the same signals, units
    and metadata); with the bodies' ``poses`` and geometry, or without them (faster); ``timestep_s``
    the car's time step (default the scenario's).
    """
    return play_in_memory(scenario, vehicle, duration_scale=duration_scale, progress=progress, timestep_s=timestep_s,
                          poses=poses).run


def play_in_memory(scenario: Scenario | RoadScenario, vehicle: VehicleDefinition | None = None, *,
                   duration_scale: float = 1.0, progress: Callable[[Progress], None] | None = None,
                   timestep_s: float | None = None, poses: bool = False) -> RunResult:
    """:func:`simulate`, with the durations of :class:`RunResult` (its path ``(in memory)``)."""
    started = time.perf_counter()
    play, layout, metadata = _play(scenario, load_vehicle(scenario.vehicle) if vehicle is None else vehicle,
                                   duration_scale, progress, timestep_s, poses=poses)
    times, rows, positions, quaternions = [], [], [], []
    with closing(play.blocks()) as blocks:
        for block in blocks:
            times.append(block.time_s)
            rows.append(layout.values(block))
            positions.append(block.body_pos)
            quaternions.append(block.body_quat_wxyz)
    path = Path("(in memory)")
    bodies = play.bodies() if poses else []
    kept = (bodies, positions, quaternions, geometry_from_model(play.car.model, bodies)) if poses else None
    run = _in_memory(path, np.concatenate(times), rows, layout, metadata, kept, play.unconverged.steps())
    return RunResult(path, play.total_s, time.perf_counter() - started, play.stepping_s, run)


def _in_memory(path: Path, t_s: np.ndarray, blocks: list[np.ndarray], layout: SignalLayout | RoadSignalLayout,
               metadata: RunMetadata,
               poses: tuple[list[str], list[np.ndarray], list[np.ndarray], list[GeomSpec]] | None = None,
               unconverged: tuple[UnconvergedSteps, ...] = ()) -> Run:
    """A complete :class:`Run` of the blocks of values ``blocks`` (one row per time in ``t_s``), with the
    bodies' ``poses`` (their names, blocks of positions and of quaternions, geometry), or none, and
    its ``unconverged`` bushing steps (said in a :class:`UnconvergedBushingSteps` warning)."""
    if unconverged:
        warnings.warn(UnconvergedBushingSteps(f"{path}: {summary(unconverged)}"), stacklevel=3)
    specs = layout.specs
    values = np.concatenate(blocks).reshape(len(t_s), len(specs))
    signals = {s.name: values[:, i] for i, s in enumerate(specs)}
    bodies, positions, quaternions, geometry = poses if poses is not None else ([], [], [], [])
    return Run(path=path, t_s=t_s, signals=signals, units={s.name: s.unit for s in specs},
               groups={s.name: s.group for s in specs}, specs=specs, body_names=bodies,
               body_pos=np.concatenate(positions) if bodies else np.empty((len(values), 0, 3)),
               body_quat_wxyz=np.concatenate(quaternions) if bodies else np.empty((len(values), 0, 4)),
               geometry=geometry, metadata=metadata, complete=True, reason="", unconverged=unconverged)


def geometry_from_model(model: mujoco.MjModel, bodies: list[str]) -> list[GeomSpec]:
    """The primitives of ``bodies`` in ``model``, in the body frames, for 3D replay.

    Meshes become their bounding box; planes, height fields and other non-solid geoms are left out.
    Raises ValueError naming a body that the model does not have.
    """
    kinds = {
        mujoco.mjtGeom.mjGEOM_BOX: "box",
        mujoco.mjtGeom.mjGEOM_SPHERE: "sphere",
        mujoco.mjtGeom.mjGEOM_CAPSULE: "capsule",
        mujoco.mjtGeom.mjGEOM_CYLINDER: "cylinder",
        mujoco.mjtGeom.mjGEOM_ELLIPSOID: "ellipsoid",
    }
    out: list[GeomSpec] = []
    for body in bodies:
        body_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
        if body_id < 0:
            raise ValueError(f"body {body!r} is not in the model")
        for g in np.flatnonzero(model.geom_bodyid == body_id):
            geom_type = int(model.geom_type[g])
            pos = model.geom_pos[g].astype(float)
            quat = model.geom_quat[g].astype(float)
            if geom_type == mujoco.mjtGeom.mjGEOM_MESH:
                centre, half = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]
                kind, size, pos = "box", half.astype(float), pos + rotation_matrix(quat) @ centre
            elif geom_type in kinds:
                kind, size = kinds[geom_type], model.geom_size[g].astype(float)
            else:
                continue
            out.append(
                GeomSpec(
                    body=body,
                    kind=kind,
                    size_m=tuple(float(v) for v in size),
                    pos_m=tuple(float(v) for v in pos),
                    quat_wxyz=tuple(float(v) for v in quat),
                    rgba=tuple(float(v) for v in model.geom_rgba[g]),
                )
            )
    return out
