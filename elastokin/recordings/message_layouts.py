"""Fixed byte layouts of the run file's two message types (``foxglove.FrameTransforms`` in protobuf,
``sensor_msgs/msg/JointState`` in CDR): every message of a run shares its layout, so that encoding
and decoding are one numpy scatter/gather instead of a protobuf object per body and step."""

from __future__ import annotations

import struct

import numpy as np

from elastokin.recordings.run_format import WORLD_FRAME


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

    def encode_block(self, t_ns: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Message bytes (steps, message length) for steps at ``t_ns`` (steps,) with the group's
        ``values`` (steps, size): one row a message."""
        n = len(t_ns)
        buf = np.empty((n, self.message_len), dtype=np.uint8)
        buf[:, :4] = np.frombuffer(CDR_LE_HEADER, dtype=np.uint8)
        sec, nanos = np.divmod(np.asarray(t_ns, dtype=np.int64), 1_000_000_000)
        buf[:, 4:8] = sec.astype("<i4")[:, None].view(np.uint8)
        buf[:, 8:12] = nanos.astype("<u4")[:, None].view(np.uint8)
        buf[:, 12:self.values_offset] = np.frombuffer(self.prefix, dtype=np.uint8)
        end = self.values_offset + 8 * self.size
        buf[:, self.values_offset:end] = np.ascontiguousarray(values, dtype="<f8").view(np.uint8).reshape(n, -1)
        buf[:, end:] = np.frombuffer(self.suffix, dtype=np.uint8)
        return buf

    def matches(self, data: bytes) -> bool:
        """Whether ``data`` has this layout (same names, same number of values)."""
        start = len(CDR_LE_HEADER) + 8
        return (
            len(data) == self.message_len
            and data[:4] == CDR_LE_HEADER
            and data[start : start + len(self.prefix)] == self.prefix
        )


def timestamp_len(frame_transforms: bytes) -> int:
    """Bytes taken by the first transform's ``timestamp`` field (tag, length, payload)."""
    # Byte 0 tags the first transform, a varint gives its length, then come the timestamp's tag
    # and its one-byte length.
    i = 1
    while frame_transforms[i] & 0x80:
        i += 1
    return 2 + frame_transforms[i + 2]
