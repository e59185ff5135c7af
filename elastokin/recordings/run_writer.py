"""Writing one run into one MCAP file (:mod:`elastokin.recordings.run_format`): ``<path>.partial`` while it
is written, renamed to ``<path>`` when closed, so that a file under the final name is always a
finished MCAP; a run stopped by an exception or Ctrl-C inside the ``with`` block is closed and
marked incomplete."""

from __future__ import annotations

import os
from dataclasses import asdict
from pathlib import Path
from types import TracebackType

import foxglove
import numpy as np
from foxglove.channels import SceneUpdateChannel
from foxglove.mcap import MCAPCompression, MCAPWriteOptions
from foxglove.messages import (Color, CubePrimitive, CylinderPrimitive, Pose, Quaternion, SceneEntity, SceneUpdate,
                               SpherePrimitive, Vector3)

from elastokin.core.errors import InputError
from elastokin.core.files import check_output
from elastokin.vehicle.simulation.unconverged import UnconvergedSteps
from elastokin.recordings.message_layouts import (JOINT_STATE_SCHEMA, FrameTransformsLayout, JointStateLayout,
                                               PlotLayout, timestamp_field)
from elastokin.recordings.run_format import (FORMAT_VERSION, GEOM_KINDS, GEOMETRY_TOPIC, MEASURED_SOURCES, NAME_PATTERN,
                                        PARTIAL_SUFFIX, PLOT_TOPIC, RUN_RECORD, SIGNAL_TOPIC_PREFIX, SOURCES, STATUS_RECORD,
                                        TF_TOPIC, GeomSpec, Run, RunMetadata, SignalSpec, rotation_matrix, signal_label,
                                        to_json)


#: Uncompressed size of a chunk [bytes]: the writer writes each chunk when it is full, so a killed
#: run's file holds all but its last chunk (read back by :func:`elastokin.recordings.run_reader.load_run`).
CHUNK_BYTES = 1 << 20


def _check_specs(signals: list[SignalSpec], bodies: list[str], geometry: list[GeomSpec]) -> None:
    names = [s.name for s in signals]
    for name in [*names, *(s.group for s in signals), *bodies]:
        if not NAME_PATTERN.fullmatch(name):
            raise ValueError(f"name {name!r}: use letters, digits, '_', '.' or '-' only")
    if len(set(names)) != len(names):
        dupes = sorted({n for n in names if names.count(n) > 1})
        raise ValueError(f"signal names must be unique; repeated: {dupes}")
    for s in signals:
        if s.x_axis is not None and s.x_axis not in names:
            raise ValueError(f"signal {s.name!r}: x_axis {s.x_axis!r} is not a recorded signal")
    if len(set(bodies)) != len(bodies):
        raise ValueError(f"body names must be unique: {bodies}")
    for g in geometry:
        if g.body not in bodies:
            raise ValueError(f"geometry on body {g.body!r}, which is not recorded")
        if g.kind not in GEOM_KINDS:
            raise ValueError(f"geometry kind {g.kind!r}; expected one of {GEOM_KINDS}")


def _scene_entity(body: str, geoms: list[GeomSpec]) -> SceneEntity:
    """Foxglove primitives of one body; a capsule is drawn as a cylinder with two spheres."""
    cubes, spheres, cylinders = [], [], []

    def pose(pos: tuple[float, float, float], q: tuple[float, float, float, float]) -> Pose:
        return Pose(
            position=Vector3(x=pos[0], y=pos[1], z=pos[2]),
            orientation=Quaternion(x=q[1], y=q[2], z=q[3], w=q[0]),
        )

    for g in geoms:
        color = Color(r=g.rgba[0], g=g.rgba[1], b=g.rgba[2], a=g.rgba[3])
        sx, sy, sz = g.size_m
        p = pose(g.pos_m, g.quat_wxyz)
        if g.kind == "box":
            cubes.append(CubePrimitive(pose=p, size=Vector3(x=2 * sx, y=2 * sy, z=2 * sz), color=color))
        elif g.kind == "ellipsoid":  # a Foxglove sphere with unequal sizes is an ellipsoid
            spheres.append(SpherePrimitive(pose=p, size=Vector3(x=2 * sx, y=2 * sy, z=2 * sz), color=color))
        elif g.kind == "sphere":
            spheres.append(SpherePrimitive(pose=p, size=Vector3(x=2 * sx, y=2 * sx, z=2 * sx), color=color))
        else:  # capsule or cylinder: radius sx, half-length sy along local z
            cylinders.append(
                CylinderPrimitive(
                    pose=p, size=Vector3(x=2 * sx, y=2 * sx, z=2 * sy), bottom_scale=1.0, top_scale=1.0, color=color
                )
            )
            if g.kind == "capsule":
                axis = rotation_matrix(g.quat_wxyz)[:, 2] * sy
                for sign in (-1.0, 1.0):
                    centre = tuple(np.asarray(g.pos_m) + sign * axis)
                    spheres.append(
                        SpherePrimitive(
                            pose=pose(centre, g.quat_wxyz), size=Vector3(x=2 * sx, y=2 * sx, z=2 * sx), color=color
                        )
                    )
    return SceneEntity(frame_id=body, id=body, frame_locked=True, cubes=cubes, spheres=spheres, cylinders=cylinders)


class RunWriter:
    """Writes one run to an MCAP file; use as a context manager.

    ``values`` passed to :meth:`write` follow the order of ``signals``; body poses follow
    ``bodies`` (world frame, metres, MuJoCo w-x-y-z quaternions). Raises
    :class:`elastokin.core.errors.InputError` if ``path`` exists and ``overwrite`` is false.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        *,
        signals: list[SignalSpec],
        bodies: list[str],
        geometry: list[GeomSpec],
        metadata: RunMetadata,
        overwrite: bool = False,
    ):
        self.path = check_output(path)
        if self.path.exists() and not overwrite:
            raise InputError(
                "the output exists; pass --overwrite (overwrite=True) to replace it", source=str(self.path)
            )
        _check_specs(signals, bodies, geometry)
        if metadata.source not in SOURCES:
            raise ValueError(f"run source {metadata.source!r}; expected one of {SOURCES}")
        if metadata.source in MEASURED_SOURCES and (metadata.vehicle_yaml or metadata.bushing_parameters):
            raise ValueError(f"a {metadata.source} recording carries no model: leave vehicle_yaml and "
                             f"bushing_parameters empty")
        model = {"vehicle_yaml": metadata.vehicle_yaml, "bushing_parameters": to_json(metadata.bushing_parameters)}
        self.signals = list(signals)
        self.bodies = list(bodies)
        self.partial_path = self.path.with_name(self.path.name + PARTIAL_SUFFIX)
        self._last_t_ns = -1
        self._closed = False
        #: The bushing directions with unconverged steps, written in the status record at :meth:`close`.
        self.unconverged: tuple[UnconvergedSteps, ...] = ()
        self._tf_layouts: dict[int, FrameTransformsLayout] = {}

        run_record = {
            "format": FORMAT_VERSION,
            "source": metadata.source,
            "scenario_yaml": metadata.scenario_yaml,
            **(model if metadata.source == "simulation" else {}),
            "software_version": metadata.software_version,
            "git_revision": metadata.git_revision,
            "extra": to_json(metadata.extra),
            "signals": to_json([asdict(s) for s in self.signals]),
            "bodies": to_json(self.bodies),
            "geometry": to_json([asdict(g) for g in geometry]),
        }

        # A private foxglove context keeps these channels out of any other writer in the process.
        self._context = foxglove.Context()
        self._writer = foxglove.open_mcap(
            self.partial_path,
            allow_overwrite=True,
            context=self._context,
            writer_options=MCAPWriteOptions(compression=MCAPCompression.Zstd, profile="", chunk_size=CHUNK_BYTES),
        )
        self._writer.write_metadata(RUN_RECORD, run_record)
        if self.bodies:  # no empty /tf channel in a recording without bodies
            self._tf_channel = foxglove.Channel(
                TF_TOPIC,
                schema=foxglove.messages.FrameTransforms.get_schema(),
                message_encoding="protobuf",
                context=self._context,
            )
        joint_state = foxglove.Schema(name="sensor_msgs/msg/JointState", encoding="ros2msg", data=JOINT_STATE_SCHEMA)
        self._groups: list[tuple[foxglove.Channel, JointStateLayout, np.ndarray]] = []
        for group in dict.fromkeys(s.group for s in self.signals):
            members = [i for i, s in enumerate(self.signals) if s.group == group]
            specs = [self.signals[i] for i in members]
            channel = foxglove.Channel(
                SIGNAL_TOPIC_PREFIX + group,
                schema=joint_state,
                message_encoding="cdr",
                context=self._context,
                metadata={"names": to_json([s.name for s in specs]), "units": to_json([s.unit for s in specs])},
            )
            layout = JointStateLayout([signal_label(s) for s in specs])
            self._groups.append((channel, layout, np.array(members, dtype=np.intp)))
        # every signal again, by name, in one message a step: Foxglove's Plot panel
        self._plot = PlotLayout(self.signals) if self.signals else None
        if self._plot is not None:
            self._plot_channel = foxglove.Channel(
                PLOT_TOPIC, schema=foxglove.Schema(name=self._plot.type_name, encoding="ros2msg", data=self._plot.schema),
                message_encoding="cdr", context=self._context)
        if geometry:
            scene = SceneUpdateChannel(GEOMETRY_TOPIC, context=self._context)
            with_geoms = [b for b in self.bodies if any(g.body == b for g in geometry)]
            entities = [_scene_entity(b, [g for g in geometry if g.body == b]) for b in with_geoms]
            scene.log(SceneUpdate(entities=entities), log_time=0)

    def write(self, t_s: float, values: np.ndarray, body_pos_m: np.ndarray, body_quat_wxyz: np.ndarray) -> None:
        """Record one step at simulation time ``t_s`` (s, ≥ 0, strictly increasing)."""
        self.write_block(np.array([t_s]), np.asarray(values)[None], np.asarray(body_pos_m)[None],
                         np.asarray(body_quat_wxyz)[None])

    def write_block(self, t_s: np.ndarray, values: np.ndarray, body_pos_m: np.ndarray,
                    body_quat_wxyz: np.ndarray) -> np.ndarray:
        """Record consecutive steps at simulation times ``t_s`` (n,) (s, ≥ 0, strictly increasing),
        with ``values`` (n, signals), ``body_pos_m`` (n, bodies, 3) and ``body_quat_wxyz`` (n,
        bodies, 4); returns their log times [ns] (the file's time base: whole nanoseconds)."""
        if self._closed:
            raise ValueError(f"{self.path}: write after close")
        t_ns = np.round(np.asarray(t_s, dtype=np.float64) * 1e9).astype(np.int64)
        values = np.asarray(values, dtype=np.float64)
        pos = np.asarray(body_pos_m, dtype=np.float64)
        quat = np.asarray(body_quat_wxyz, dtype=np.float64)
        n, n_bodies = len(t_ns), len(self.bodies)
        if (t_ns.shape != (n,) or values.shape != (n, len(self.signals)) or pos.shape != (n, n_bodies, 3)
                or quat.shape != (n, n_bodies, 4)):
            raise ValueError(
                f"{self.path}: expected values (n, {len(self.signals)}), poses (n, {n_bodies}, 3) and "
                f"(n, {n_bodies}, 4) at times (n,); got {values.shape}, {pos.shape}, {quat.shape} at {t_ns.shape}"
            )
        before = np.concatenate([[self._last_t_ns], t_ns[:-1]])
        late = np.flatnonzero(t_ns <= before)
        if late.size:
            raise ValueError(f"{self.path}: time {t_s[late[0]]} s is negative or not after the previous step")
        poses = np.concatenate([pos, quat[:, :, 1:], quat[:, :, :1]], axis=2)
        groups = [(channel, layout.encode_block(t_ns, values[:, members])) for channel, layout, members in self._groups]
        if self._plot is not None:
            groups.append((self._plot_channel, self._plot.encode_block(t_ns, values)))
        for k, t in enumerate(t_ns.tolist()):
            if n_bodies:
                timestamp = timestamp_field(t)
                layout = self._tf_layouts.get(len(timestamp))
                if layout is None:
                    layout = self._tf_layouts[len(timestamp)] = FrameTransformsLayout(self.bodies, len(timestamp))
                self._tf_channel.log(layout.encode(timestamp, poses[k]), log_time=t)
            for channel, messages in groups:
                channel.log(messages[k].tobytes(), log_time=t)
            self._last_t_ns = t
        return t_ns.astype(np.uint64)

    def close(self, *, complete: bool = True, reason: str = "") -> None:
        """Write the ``vsim.status`` record, finish the MCAP and move it to its final name.

        Idempotent: only the first call counts.
        """
        if self._closed:
            return
        self._closed = True
        try:
            self._writer.write_metadata(STATUS_RECORD, {"complete": "true" if complete else "false", "reason": reason,
                                                        "unconverged": to_json([s.to_record() for s in self.unconverged])})
        finally:
            self._writer.close()
            os.replace(self.partial_path, self.path)

    def __enter__(self) -> RunWriter:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        if exc_type is None:
            self.close()
        else:
            self.close(complete=False, reason=f"{exc_type.__name__}: {exc}".rstrip(": "))


def write_run(run: Run, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Record the run ``run`` (made in memory, or read from a file) in the MCAP file ``path``: the
    same bytes as the recording made while it ran, for a run kept with its body poses. An incomplete
    run is recorded incomplete, with its reason. Raises :class:`InputError` if ``path`` exists and
    not ``overwrite``."""
    with RunWriter(path, signals=run.specs, bodies=run.body_names, geometry=run.geometry, metadata=run.metadata,
                   overwrite=overwrite) as writer:
        values = np.column_stack([run.signals[s.name] for s in run.specs]) if run.specs else np.empty((len(run.t_s), 0))
        if len(run.t_s):
            writer.write_block(run.t_s, values, run.body_pos, run.body_quat_wxyz)
        writer.unconverged = run.unconverged
        writer.close(complete=run.complete, reason=run.reason)
    return Path(path)
