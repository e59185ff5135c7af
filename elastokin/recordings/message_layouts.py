"""Fixed byte layouts of the run file's message types (``foxglove.FrameTransforms`` in protobuf,
``sensor_msgs/msg/JointState`` and the run's named signals in CDR): every message of a channel
shares its layout, so that encoding and decoding are one numpy scatter/gather instead of a protobuf
or CDR object per body and step."""

from __future__ import annotations

import re
import struct

import numpy as np

from elastokin.recordings.run_format import WORLD_FRAME, SignalSpec, signal_label


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


def _stamped_block(t_ns: np.ndarray, values: np.ndarray, message_len: int, values_offset: int) -> np.ndarray:
    """CDR messages (steps, ``message_len``) that open with the encapsulation header and a
    ``builtin_interfaces/Time`` stamp (int32 sec, uint32 nanosec) of ``t_ns`` (steps,) and hold
    ``values`` (steps, n) as float64 from byte ``values_offset``; the other bytes are left to fill."""
    n = len(t_ns)
    buf = np.empty((n, message_len), dtype=np.uint8)
    buf[:, :4] = np.frombuffer(CDR_LE_HEADER, dtype=np.uint8)
    sec, nanos = np.divmod(np.asarray(t_ns, dtype=np.int64), 1_000_000_000)
    buf[:, 4:8] = sec.astype("<i4")[:, None].view(np.uint8)
    buf[:, 8:12] = nanos.astype("<u4")[:, None].view(np.uint8)
    end = values_offset + 8 * values.shape[1]
    buf[:, values_offset:end] = np.ascontiguousarray(values, dtype="<f8").view(np.uint8).reshape(n, -1)
    return buf


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

    def encode_block(self, t_ns: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Message bytes (steps, message length) for steps at ``t_ns`` (steps,) with the group's
        ``values`` (steps, size): one row a message."""
        buf = _stamped_block(t_ns, values, self.message_len, self.values_offset)
        buf[:, 12:self.values_offset] = np.frombuffer(self.prefix, dtype=np.uint8)
        buf[:, self.values_offset + 8 * self.size:] = np.frombuffer(self.suffix, dtype=np.uint8)
        return buf

    def matches(self, data: bytes) -> bool:
        """Whether ``data`` has this layout (same names, same number of values)."""
        start = len(CDR_LE_HEADER) + 8
        return (
            len(data) == self.message_len
            and data[:4] == CDR_LE_HEADER
            and data[start : start + len(self.prefix)] == self.prefix
        )


class PlotLayout:
    """CDR (little endian) layout of a run's ``/plot`` message: every signal of a step in one ROS 2
    message of the run's own type, ``vsim_msgs/msg/Signals``, with a ``builtin_interfaces/Time
    stamp`` and a field per signal group, itself a message with a ``float64`` field per signal named
    by it and its unit (and a comment with both as recorded), so that Foxglove's Plot panel offers
    each signal by name: ``/plot.camber.camber_fl_deg``.

    Names follow ROS 2's rules (lowercase letters, digits, single underscores; types CamelCase):
    ``<signal>_<unit>`` (``pad_fz_fl_n``, ``yaw_rate_deg_per_s``, ``e1_front_left_rx_force_n_m``; a
    dimensionless ``-`` adds nothing), ``s_`` before a name that would not start with a letter, and
    a number after one that two signals (or groups) would share. The values follow :attr:`order`.
    """

    def __init__(self, specs: list[SignalSpec]):
        groups = list(dict.fromkeys(s.group for s in specs))
        members = [[i for i, s in enumerate(specs) if s.group == g] for g in groups]
        group_fields = _unique(["stamp", *(_field_name(g, "") for g in groups)], "_")[1:]   # beside the stamp
        types = _unique(["".join(w[:1].upper() + w[1:] for w in re.split(r"[^A-Za-z0-9]+", g) if w) for g in groups], "")
        types = [f"{t if t[:1].isalpha() else 'G' + t}Signals" for t in types]
        definitions = [["builtin_interfaces/Time stamp", *(f"{PLOT_PACKAGE}/{t} {f}" for t, f in zip(types, group_fields))]]
        for type_name, indices in zip(types, members):
            fields = _unique([_field_name(specs[i].name, specs[i].unit) for i in indices], "_")
            definitions.append([f"MSG: {PLOT_PACKAGE}/{type_name}",
                                *(f"float64 {f}  # {signal_label(specs[i])}" for f, i in zip(fields, indices))])
        definitions.append(["MSG: builtin_interfaces/Time", "int32 sec", "uint32 nanosec"])
        self.type_name = f"{PLOT_PACKAGE}/msg/Signals"   # apart from every group's <Group>Signals
        self.schema = f"\n{'=' * 80}\n".join("\n".join(d) for d in definitions).encode() + b"\n"
        self.order = np.array([i for indices in members for i in indices], dtype=np.intp)   #: signal indices
        self.values_offset = len(CDR_LE_HEADER) + 8   # after the 8-byte stamp: float64 aligned
        self.message_len = self.values_offset + 8 * len(specs)

    def encode_block(self, t_ns: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Message bytes (steps, message length) for steps at ``t_ns`` (steps,) with every signal's
        ``values`` (steps, signals) in the run's signal order: one row a message."""
        return _stamped_block(t_ns, values[:, self.order], self.message_len, self.values_offset)


#: The ROS 2 package of the ``/plot`` message types (named ``pkg/Type`` inside a schema, as
#: JointState's ``std_msgs/Header`` is).
PLOT_PACKAGE = "vsim_msgs"
#: Unit symbols spelt out in a ROS 2 field name.
_UNIT_SPELLING = {"/": "_per_", "·": "_", "²": "2", "³": "3", "%": "pct", "°": "deg"}


def _field_name(name: str, unit: str) -> str:
    """``name`` and ``unit`` as one ROS 2 field name (not yet unique)."""
    def words(text: str) -> str:
        for symbol, spelt in _UNIT_SPELLING.items():
            text = text.replace(symbol, spelt)
        return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")

    field = "_".join(w for w in (words(name), words(unit)) if w) or "s"
    return field if field[0].isalpha() else f"s_{field}"


def _unique(names: list[str], joint: str) -> list[str]:
    """``names`` with a number (2, 3 …, after ``joint``) on each that an earlier one already took."""
    out: list[str] = []
    for name in names:
        unique, k = name, 1
        while unique in out:
            k += 1
            unique = f"{name}{joint}{k}"
        out.append(unique)
    return out


def timestamp_len(frame_transforms: bytes) -> int:
    """Bytes taken by the first transform's ``timestamp`` field (tag, length, payload)."""
    # Byte 0 tags the first transform, a varint gives its length, then come the timestamp's tag
    # and its one-byte length.
    i = 1
    while frame_transforms[i] & 0x80:
        i += 1
    return 2 + frame_transforms[i + 2]
