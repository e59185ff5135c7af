"""The run file's format (MCAP that Foxglove and Rerun open as it is) and a run in memory.

Layout of a run file (topics, encodings and why):

``/tf``
    ``foxglove.FrameTransforms`` (protobuf), one message per recorded step holding every body's
    world pose (parent frame ``world``, child frame = body name, metres, unit quaternion).
    Foxglove's 3D panel and Rerun's MCAP importer both turn it into transforms. Absent from a
    recording without bodies (a measured rig recording, ``data/README.md``).
``/signals/<group>``
    ``sensor_msgs/msg/JointState`` (ROS 2 message definition, CDR), one message per step and
    group: ``position`` holds the group's values, ``name`` the labels ``"<signal> [<unit>]"``.
    Rerun plots JointState arrays without any configuration (entity ``/signals/<group>/position``).
    The channel metadata repeats the bare names and the units as JSON lists (``names``, ``units``)
    so every channel describes itself. The project's readers read the signals from here.
``/plot``
    every signal again, by name: one message per step of the run's own ROS 2 type
    (``vsim_msgs/msg/Signals``, CDR) with a field per group and, in each, a ``float64`` per
    signal named ``<signal>_<unit>``
    (:class:`elastokin.recordings.message_layouts.PlotLayout`), so that Foxglove's Plot panel offers
    each by its name and unit (``/plot.camber.camber_fl_deg``) where a JointState gives
    ``position[0]``. Files written before it existed lack it and read the same.
``/geometry``
    one ``foxglove.SceneUpdate`` at t = 0 with each body's primitives locked to the body's frame,
    so Foxglove's 3D panel shows the car moving.
metadata record ``vsim.run``
    the source (``simulation``, ``rig`` or ``road test``), scenario and vehicle YAML, bushing
    parameter sets, software version, git revision, free-form extras, the signal list (name, unit,
    group, x-axis hint), the body list and the geometry (JSON). A measured record (``rig``, ``road
    test``) has no vehicle YAML and no bushing parameters: measured data carries nothing about a model.
metadata record ``vsim.status``
    written by :meth:`elastokin.recordings.run_writer.RunWriter.close`: ``complete`` (``"true"``/``"false"``),
    ``reason`` and ``unconverged`` (JSON: a list of
    :meth:`elastokin.vehicle.simulation.unconverged.UnconvergedSteps.to_record`, one per bushing direction
    with steps whose solve did not converge; empty for a run without, and for a rig recording).

Every time in the file is simulation time (``log_time`` = ``publish_time`` = stamp = t in ns), so
equal inputs give bit-identical data. The file is written as ``<path>.partial`` and renamed to
``<path>`` when closed, so a file under the final name is always a finished MCAP; a run stopped by an
exception or Ctrl-C inside the ``with`` block is closed and marked incomplete.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from elastokin.vehicle.simulation.unconverged import UnconvergedSteps

TF_TOPIC = "/tf"
GEOMETRY_TOPIC = "/geometry"
SIGNAL_TOPIC_PREFIX = "/signals/"
PLOT_TOPIC = "/plot"
WORLD_FRAME = "world"
RUN_RECORD = "vsim.run"
STATUS_RECORD = "vsim.status"
FORMAT_VERSION = "vsim-run/1"
PARTIAL_SUFFIX = ".partial"

#: Where a run's signals come from: the simulator, a rig (measured data, see ``data/README.md``) or a
#: test car on the road (a ``measured_steer`` scenario's logs, ``vsim road import``).
SOURCES = ("simulation", "rig", "road test")
#: The sources of measured runs: they carry no model.
MEASURED_SOURCES = ("rig", "road test")

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

    ``source`` is one of SOURCES; a measured run (MEASURED_SOURCES) must leave ``vehicle_yaml`` and
    ``bushing_parameters`` empty (they are not stored).
    """

    scenario_yaml: str = ""
    vehicle_yaml: str = ""
    bushing_parameters: Mapping[str, Any] = field(default_factory=dict)
    software_version: str = ""
    git_revision: str = ""
    extra: Mapping[str, Any] = field(default_factory=dict)
    source: str = "simulation"


@dataclass
class Run:
    """A recorded run: N steps, S signals, B bodies.

    ``t_s`` (N,) simulation time in s, at the MCAP resolution of 1 ns; ``signals[name]`` (N,) in
    ``units[name]``; ``body_pos`` (N, B, 3) world positions in m; ``body_quat_wxyz`` (N, B, 4).
    ``complete`` is false for a run stopped early (divergence, Ctrl-C, exception), with the cause
    in ``reason``, and for a file read in part, what it could not give in ``damage`` (and ``reason``).
    ``unconverged`` lists the bushing directions whose solve stopped at its iteration cap in some steps.
    """

    path: Path
    t_s: np.ndarray
    signals: dict[str, np.ndarray]
    units: dict[str, str]
    groups: dict[str, str]
    specs: list[SignalSpec]
    body_names: list[str]
    body_pos: np.ndarray
    body_quat_wxyz: np.ndarray
    geometry: list[GeomSpec]
    metadata: RunMetadata
    complete: bool
    reason: str
    damage: tuple[str, ...] = ()   #: what a damaged file could not give (a chunk's CRC, a cut)
    unconverged: tuple[UnconvergedSteps, ...] = ()

    def label(self, name: str) -> str:
        """``"name [unit]"`` for axis labels and legends."""
        return f"{name} [{self.units[name]}]"

    def pairs(self) -> list[tuple[str, str]]:
        """(x, y) signal pairs to plot against each other, in signal order.

        Each signal with an ``x_axis`` hint (e.g. camber against wheel travel), then each bushing
        loop: ``<stem>_force`` against ``<stem>_deflection`` when both were recorded.
        """
        out = [(s.x_axis, s.name) for s in self.specs if s.x_axis is not None]
        for s in self.specs:
            stem = s.name.removesuffix("_deflection")
            if stem != s.name and f"{stem}_force" in self.signals:
                out.append((s.name, f"{stem}_force"))
        return out


def to_json(value: Any) -> str:
    """Deterministic JSON (sorted keys) that also accepts numpy scalars and arrays."""

    def convert(obj: Any) -> Any:
        if isinstance(obj, np.ndarray):
            return obj.tolist()
        if isinstance(obj, np.generic):
            return obj.item()
        raise TypeError(f"cannot store {type(obj).__name__} in run metadata")

    return json.dumps(value, sort_keys=True, default=convert)


def rotation_matrix(quat_wxyz: tuple[float, float, float, float] | np.ndarray) -> np.ndarray:
    """(3, 3) rotation matrix of a unit w-x-y-z quaternion (MuJoCo's order): the formula of MuJoCo's
    ``mju_quat2Mat``, in numpy, so that reading and drawing runs does not need MuJoCo."""
    w, x, y, z = (float(v) for v in quat_wxyz)
    if w == 1.0 and x == 0.0 and y == 0.0 and z == 0.0:
        return np.eye(3)
    ww, xx, yy, zz = w * w, x * x, y * y, z * z
    wx, wy, wz, xy, xz, yz = w * x, w * y, w * z, x * y, x * z, y * z
    return np.array([[ww + xx - yy - zz, 2 * (xy - wz), 2 * (xz + wy)],
                     [2 * (xy + wz), ww - xx + yy - zz, 2 * (yz - wx)],
                     [2 * (xz - wy), 2 * (yz + wx), ww - xx - yy + zz]])


def signal_label(spec: SignalSpec) -> str:
    """The JointState name shown by viewers: ``"camber_fl [deg]"``."""
    return f"{spec.name} [{spec.unit}]"


