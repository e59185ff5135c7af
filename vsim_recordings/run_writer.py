"""Record one simulation run into one MCAP file that Foxglove and Rerun open as it is.

Layout of a run file (topics, encodings and why):

``/tf``
    ``foxglove.FrameTransforms`` (protobuf), one message per recorded step holding every body's
    world pose (parent frame ``world``, child frame = body name, metres, unit quaternion).
    Foxglove's 3D panel and Rerun's MCAP importer both turn it into transforms. Absent from a
    recording without bodies (a measured rig recording, ``data/README.md``).
``/signals/<group>``
    ``sensor_msgs/msg/JointState`` (ROS 2 message definition, CDR), one message per step and
    group: ``position`` holds the group's values, ``name`` the labels ``"<signal> [<unit>]"``.
    Rerun plots JointState arrays without any configuration (entity ``/signals/<group>/position``)
    and Foxglove plots them too. The channel metadata repeats the bare names and the units as JSON
    lists (``names``, ``units``) so every channel describes itself.
``/geometry``
    one ``foxglove.SceneUpdate`` at t = 0 with each body's primitives locked to the body's frame,
    so Foxglove's 3D panel shows the car moving.
metadata record ``vsim.run``
    the source (``simulation`` or ``rig``), scenario and vehicle YAML, bushing parameter sets,
    software version, git revision, free-form extras, the signal list (name, unit, group, x-axis
    hint), the body list and the geometry (JSON). A ``rig`` record has no vehicle YAML and no
    bushing parameters: measured data carries nothing about a model.
metadata record ``vsim.status``
    written by :meth:`RunWriter.close`: ``complete`` (``"true"``/``"false"``) and ``reason``.

Every time in the file is simulation time (``log_time`` = ``publish_time`` = stamp = t in ns), so
equal inputs give bit-identical data. The file is written as ``<path>.partial`` and renamed to
``<path>`` when closed, so a file under the final name is always a finished MCAP; a run stopped by an
exception or Ctrl-C inside the ``with`` block is closed and marked incomplete.
"""

from __future__ import annotations

import json
import os
import re
import struct
from dataclasses import asdict, dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any, Mapping

import foxglove
import mujoco
import numpy as np
from foxglove.channels import SceneUpdateChannel
from foxglove.mcap import MCAPCompression, MCAPWriteOptions
from foxglove.messages import (
    Color,
    CubePrimitive,
    CylinderPrimitive,
    Pose,
    Quaternion,
    SceneEntity,
    SceneUpdate,
    SpherePrimitive,
    Vector3,
)

from vsim_core.errors import InputError

TF_TOPIC = "/tf"
GEOMETRY_TOPIC = "/geometry"
SIGNAL_TOPIC_PREFIX = "/signals/"
WORLD_FRAME = "world"
RUN_RECORD = "vsim.run"
STATUS_RECORD = "vsim.status"
FORMAT_VERSION = "vsim-run/1"
PARTIAL_SUFFIX = ".partial"

#: Where a run's signals come from: the simulator, or a rig (measured data, see ``data/README.md``).
SOURCES = ("simulation", "rig")

#: Signal, group and body names become topics, frame ids and Rerun entity paths: keep them plain.
NAME_PATTERN = re.compile(r"[A-Za-z0-9_.\-]+")

#: Geometry kinds a :class:`GeomSpec` may have (MuJoCo names; meshes are stored as their bounding box).
GEOM_KINDS = ("box", "sphere", "capsule", "cylinder", "ellipsoid")


@dataclass(frozen=True)
class SignalSpec:
    """One recorded scalar signal.

    ``name`` is unique in a run (e.g. ``camber_fl``); ``unit`` is how its values are expressed
    (e.g. ``deg``, ``mm``, ``N``); ``group`` chooses its channel (``/signals/<group>``);
    ``x_axis`` optionally names the signal to plot this one against (camber against wheel travel).
    """

    name: str
    unit: str
    group: str
    x_axis: str | None = None


@dataclass(frozen=True)
class GeomSpec:
    """One primitive attached to a body, for 3D replay.

    ``size_m`` follows MuJoCo: box and ellipsoid half-sizes; sphere (radius, 0, 0); capsule and
    cylinder (radius, half-length, 0), axis along the geom's local z. ``pos_m`` and ``quat_wxyz``
    place the geom in the body frame; ``rgba`` in [0, 1].
    """

    body: str
    kind: str
    size_m: tuple[float, float, float]
    pos_m: tuple[float, float, float]
    quat_wxyz: tuple[float, float, float, float]
    rgba: tuple[float, float, float, float]


@dataclass(frozen=True)
class RunMetadata:
    """What is needed to reproduce and identify a run; stored verbatim in the ``vsim.run`` record.

    ``source`` is one of SOURCES; a ``rig`` run must leave ``vehicle_yaml`` and
    ``bushing_parameters`` empty (they are not stored).
    """

    scenario_yaml: str = ""
    vehicle_yaml: str = ""
    bushing_parameters: Mapping[str, Any] = field(default_factory=dict)
    software_version: str = ""
    git_revision: str = ""
    extra: Mapping[str, Any] = field(default_factory=dict)
    source: str = "simulation"


def _json(value: Any) -> str:
    """Deterministic JSON (sorted keys) that also accepts numpy scalars and arrays."""

    def convert(obj: Any) -> Any:
        if isinstance(obj, np.ndarray):
            return obj.tolist()
        if isinstance(obj, np.generic):
            return obj.item()
        raise TypeError(f"cannot store {type(obj).__name__} in run metadata")

    return json.dumps(value, sort_keys=True, default=convert)


def _varint(n: int) -> bytes:
    out = bytearray()
    while True:
        byte = n & 0x7F
        n >>= 7
        if n:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


def _len_field(tag: int, payload: bytes) -> bytes:
    return bytes([tag]) + _varint(len(payload)) + payload


def timestamp_field(t_ns: int) -> bytes:
    """``timestamp`` (field 1) of a FrameTransform as a google.protobuf.Timestamp, zeros written."""
    sec, nanos = divmod(t_ns, 1_000_000_000)
    return _len_field(0x0A, b"\x08" + _varint(sec) + b"\x10" + _varint(nanos))


class FrameTransformsLayout:
    """Byte layout of ``foxglove.FrameTransforms`` for a fixed body list and timestamp length.

    Every field is written, zeros included (proto3 parsers accept that), so all messages of a run
    share one layout per timestamp length: encoding and decoding become one numpy scatter/gather
    instead of ~25 protobuf objects per step.
    """

    def __init__(self, bodies: list[str], timestamp_len: int):
        template = bytearray()
        ts_idx, val_idx = [], []
        for body in bodies:
            names = _len_field(0x12, WORLD_FRAME.encode()) + _len_field(0x1A, body.encode())
            body_len = timestamp_len + len(names) + 2 + 27 + 2 + 36
            template += b"\x0a" + _varint(body_len)
            ts_idx.append(range(len(template), len(template) + timestamp_len))
            template += bytes(timestamp_len) + names
            offsets = []
            # translation: Vector3 x, y, z (fields 1-3, doubles); rotation: Quaternion x, y, z, w.
            for header, tags in ((b"\x22\x1b", b"\x09\x11\x19"), (b"\x2a\x24", b"\x09\x11\x19\x21")):
                template += header
                for tag in tags:
                    template.append(tag)
                    offsets.append(len(template))
                    template += bytes(8)
            val_idx.append([[o + k for k in range(8)] for o in offsets])
        self.template = np.frombuffer(bytes(template), dtype=np.uint8)
        self.timestamp_index = np.array([list(r) for r in ts_idx], dtype=np.intp)
        self.value_index = np.array(val_idx, dtype=np.intp)  # (bodies, 7, 8)

    def encode(self, timestamp: bytes, pos_xyz_quat_xyzw: np.ndarray) -> bytes:
        """Message bytes for one step; ``pos_xyz_quat_xyzw`` is (bodies, 7) float64."""
        buf = self.template.copy()
        buf[self.timestamp_index] = np.frombuffer(timestamp, dtype=np.uint8)
        values = np.ascontiguousarray(pos_xyz_quat_xyzw, dtype="<f8")
        buf[self.value_index] = values.view(np.uint8).reshape(self.value_index.shape)
        return buf.tobytes()

    def decode(self, data: bytes) -> np.ndarray | None:
        """(bodies, 7) poses, or None when ``data`` does not have this layout."""
        buf = np.frombuffer(data, dtype=np.uint8)
        if buf.size != self.template.size:
            return None
        values = buf[self.value_index]
        check = buf.copy()
        check[self.value_index] = 0
        check[self.timestamp_index] = 0
        if not np.array_equal(check, self.template):
            return None
        return values.reshape(values.shape[0], 7, 8).copy().view("<f8").reshape(-1, 7)


JOINT_STATE_SCHEMA = b"""std_msgs/Header header
string[] name
float64[] position
float64[] velocity
float64[] effort
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
"""
CDR_LE_HEADER = b"\x00\x01\x00\x00"


class JointStateLayout:
    """CDR (little endian) layout of a ``sensor_msgs/msg/JointState`` with fixed names.

    Only the stamp and the ``position`` values change between messages; velocity and effort are
    empty. CDR alignment counts from the end of the 4-byte encapsulation header.
    """

    def __init__(self, labels: list[str]):
        body = bytearray(8)  # stamp: int32 sec, uint32 nanosec, filled per message

        def align(n: int) -> None:
            body.extend(bytes(-len(body) % n))

        def string(s: str) -> None:
            align(4)
            raw = s.encode() + b"\x00"
            body.extend(struct.pack("<I", len(raw)) + raw)

        string("")  # frame_id
        align(4)
        body.extend(struct.pack("<I", len(labels)))
        for label in labels:
            string(label)
        align(4)
        body.extend(struct.pack("<I", len(labels)))
        align(8)
        self.prefix = bytes(body[8:])
        self.size = len(labels)
        self.values_offset = len(CDR_LE_HEADER) + len(body)
        self.suffix = struct.pack("<II", 0, 0)  # empty velocity and effort
        self.message_len = self.values_offset + 8 * self.size + len(self.suffix)

    def encode(self, t_ns: int, values: np.ndarray) -> bytes:
        sec, nanos = divmod(t_ns, 1_000_000_000)
        return (
            CDR_LE_HEADER
            + struct.pack("<iI", sec, nanos)
            + self.prefix
            + np.ascontiguousarray(values, dtype="<f8").tobytes()
            + self.suffix
        )

    def matches(self, data: bytes) -> bool:
        """Whether ``data`` has this layout (same names, same number of values)."""
        start = len(CDR_LE_HEADER) + 8
        return (
            len(data) == self.message_len
            and data[:4] == CDR_LE_HEADER
            and data[start : start + len(self.prefix)] == self.prefix
        )


def rotation_matrix(quat_wxyz: tuple[float, float, float, float] | np.ndarray) -> np.ndarray:
    """(3, 3) rotation matrix of a MuJoCo w-x-y-z quaternion."""
    mat = np.empty(9)
    mujoco.mju_quat2Mat(mat, np.asarray(quat_wxyz, dtype=float))
    return mat.reshape(3, 3)


def signal_label(spec: SignalSpec) -> str:
    """The JointState name shown by viewers: ``"camber_fl [deg]"``."""
    return f"{spec.name} [{spec.unit}]"


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
    :class:`vsim_core.errors.InputError` if ``path`` exists and ``overwrite`` is false.
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
        self.path = Path(path)
        if self.path.exists() and not overwrite:
            raise InputError(
                "the output exists; pass --overwrite (overwrite=True) to replace it", source=str(self.path)
            )
        _check_specs(signals, bodies, geometry)
        if metadata.source not in SOURCES:
            raise ValueError(f"run source {metadata.source!r}; expected one of {SOURCES}")
        if metadata.source == "rig" and (metadata.vehicle_yaml or metadata.bushing_parameters):
            raise ValueError("a rig recording carries no model: leave vehicle_yaml and bushing_parameters empty")
        model = {"vehicle_yaml": metadata.vehicle_yaml, "bushing_parameters": _json(metadata.bushing_parameters)}
        self.signals = list(signals)
        self.bodies = list(bodies)
        self.partial_path = self.path.with_name(self.path.name + PARTIAL_SUFFIX)
        self._last_t_ns = -1
        self._closed = False
        self._tf_layouts: dict[int, FrameTransformsLayout] = {}

        run_record = {
            "format": FORMAT_VERSION,
            "source": metadata.source,
            "scenario_yaml": metadata.scenario_yaml,
            **(model if metadata.source == "simulation" else {}),
            "software_version": metadata.software_version,
            "git_revision": metadata.git_revision,
            "extra": _json(metadata.extra),
            "signals": _json([asdict(s) for s in self.signals]),
            "bodies": _json(self.bodies),
            "geometry": _json([asdict(g) for g in geometry]),
        }

        # A private foxglove context keeps these channels out of any other writer in the process.
        self._context = foxglove.Context()
        self._writer = foxglove.open_mcap(
            self.partial_path,
            allow_overwrite=True,
            context=self._context,
            writer_options=MCAPWriteOptions(compression=MCAPCompression.Zstd, profile=""),
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
                metadata={"names": _json([s.name for s in specs]), "units": _json([s.unit for s in specs])},
            )
            layout = JointStateLayout([signal_label(s) for s in specs])
            self._groups.append((channel, layout, np.array(members, dtype=np.intp)))
        if geometry:
            scene = SceneUpdateChannel(GEOMETRY_TOPIC, context=self._context)
            with_geoms = [b for b in self.bodies if any(g.body == b for g in geometry)]
            entities = [_scene_entity(b, [g for g in geometry if g.body == b]) for b in with_geoms]
            scene.log(SceneUpdate(entities=entities), log_time=0)

    def write(self, t_s: float, values: np.ndarray, body_pos_m: np.ndarray, body_quat_wxyz: np.ndarray) -> None:
        """Record one step at simulation time ``t_s`` (s, ≥ 0, strictly increasing)."""
        if self._closed:
            raise ValueError(f"{self.path}: write after close")
        t_ns = int(round(t_s * 1e9))
        if t_ns <= self._last_t_ns:
            raise ValueError(f"{self.path}: time {t_s} s is negative or not after the previous step")
        values = np.asarray(values, dtype=np.float64)
        pos = np.asarray(body_pos_m, dtype=np.float64)
        quat = np.asarray(body_quat_wxyz, dtype=np.float64)
        n_bodies = len(self.bodies)
        if values.shape != (len(self.signals),) or pos.shape != (n_bodies, 3) or quat.shape != (n_bodies, 4):
            raise ValueError(
                f"{self.path}: expected values ({len(self.signals)},), poses ({n_bodies}, 3) and "
                f"({n_bodies}, 4); got {values.shape}, {pos.shape}, {quat.shape}"
            )
        self._last_t_ns = t_ns
        if n_bodies:
            timestamp = timestamp_field(t_ns)
            layout = self._tf_layouts.get(len(timestamp))
            if layout is None:
                layout = self._tf_layouts[len(timestamp)] = FrameTransformsLayout(self.bodies, len(timestamp))
            poses = np.concatenate([pos, quat[:, 1:], quat[:, :1]], axis=1)
            self._tf_channel.log(layout.encode(timestamp, poses), log_time=t_ns)
        for channel, layout, members in self._groups:
            channel.log(layout.encode(t_ns, values[members]), log_time=t_ns)

    def close(self, *, complete: bool = True, reason: str = "") -> None:
        """Write the ``vsim.status`` record, finish the MCAP and move it to its final name.

        Idempotent: only the first call counts.
        """
        if self._closed:
            return
        self._closed = True
        try:
            self._writer.write_metadata(STATUS_RECORD, {"complete": "true" if complete else "false", "reason": reason})
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
