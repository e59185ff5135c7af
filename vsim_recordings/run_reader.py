"""Reading a run file (written by :class:`vsim_recordings.run_writer.RunWriter`) back into a
:class:`vsim_recordings.run_format.Run`: a simulated run, or a measured rig recording
(``data/README.md``: no bodies, no model in its metadata)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
from mcap.exceptions import McapError
from mcap.reader import make_reader

from vsim_core.errors import InputError
from vsim_recordings.message_layouts import FrameTransformsLayout, JointStateLayout, timestamp_len
from vsim_recordings.run_format import (FORMAT_VERSION, PARTIAL_SUFFIX, RUN_RECORD, SIGNAL_TOPIC_PREFIX, STATUS_RECORD,
                                        TF_TOPIC, GeomSpec, Run, RunMetadata, SignalSpec, signal_label)


def _run_record(records: dict[str, dict[str, str]], path: Path) -> dict[str, str]:
    run = records.get(RUN_RECORD)
    if run is None or run.get("format") != FORMAT_VERSION:
        raise InputError(f"not a vsim run file (no '{RUN_RECORD}' record of format {FORMAT_VERSION})", source=str(path))
    return run


def load_run(path: str | os.PathLike[str]) -> Run:
    """Read a run file; raises :class:`InputError` if it is missing or not a vsim run."""
    path = Path(path)
    if not path.is_file():
        partial = path.with_name(path.name + PARTIAL_SUFFIX).exists()
        hint = " (an unfinished run left a .partial file)" if partial else ""
        raise InputError(f"no such run file{hint}", source=str(path))
    with open(path, "rb") as stream:
        try:
            reader = make_reader(stream)
            records = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
            run = _run_record(records, path)
            specs = [SignalSpec(**s) for s in json.loads(run["signals"])]
            bodies = json.loads(run["bodies"])
            group_specs: dict[str, list[SignalSpec]] = {}
            for s in specs:
                group_specs.setdefault(s.group, []).append(s)
            layouts = {
                SIGNAL_TOPIC_PREFIX + g: JointStateLayout([signal_label(s) for s in members])
                for g, members in group_specs.items()
            }
            topics = [TF_TOPIC, *layouts] if bodies else list(layouts)
            times: dict[str, list[int]] = {topic: [] for topic in topics}
            payloads: dict[str, list[bytes]] = {topic: [] for topic in times}
            for _, channel, message in reader.iter_messages(topics=topics, log_time_order=False):
                times[channel.topic].append(message.log_time)
                payloads[channel.topic].append(message.data)
        except McapError as exc:
            raise InputError(f"unreadable MCAP: {exc}", source=str(path)) from exc

    # A run stopped inside RunWriter.write may lack the last step on some channels: keep whole steps.
    n_steps = min((len(t) for t in times.values()), default=0)
    t_ns = np.array(next(iter(times.values()), [])[:n_steps], dtype=np.int64)
    for topic, topic_times in times.items():
        if not np.array_equal(np.asarray(topic_times[:n_steps], dtype=np.int64), t_ns):
            raise InputError(f"channel {topic} is not on the same time steps as the others", source=str(path))

    signals: dict[str, np.ndarray] = {}
    for topic, layout in layouts.items():
        data = payloads[topic][:n_steps]
        if not all(layout.matches(d) for d in data):
            raise InputError(f"channel {topic}: messages do not match the recorded signal list", source=str(path))
        raw = b"".join(d[layout.values_offset : layout.values_offset + 8 * layout.size] for d in data)
        values = np.frombuffer(raw, dtype="<f8").reshape(n_steps, layout.size)
        for k, spec in enumerate(group_specs[topic[len(SIGNAL_TOPIC_PREFIX) :]]):
            signals[spec.name] = values[:, k].copy()

    poses = np.empty((n_steps, len(bodies), 7))
    tf_layouts: dict[int, FrameTransformsLayout] = {}
    for i, data in enumerate(payloads.get(TF_TOPIC, [])[:n_steps]):
        size = timestamp_len(data)
        layout = tf_layouts.get(size) or tf_layouts.setdefault(size, FrameTransformsLayout(bodies, size))
        decoded = layout.decode(data)
        if decoded is None:
            raise InputError(f"{TF_TOPIC} message {i} does not match the recorded body list", source=str(path))
        poses[i] = decoded

    status = records.get(STATUS_RECORD, {"complete": "false", "reason": "no status record: the run was not closed"})
    return Run(
        path=path,
        t_s=t_ns / 1e9,
        signals=signals,
        units={s.name: s.unit for s in specs},
        groups={s.name: s.group for s in specs},
        specs=specs,
        body_names=bodies,
        body_pos=poses[:, :, :3],
        body_quat_wxyz=np.concatenate([poses[:, :, 6:7], poses[:, :, 3:6]], axis=2),
        geometry=[
            GeomSpec(**{k: tuple(v) if isinstance(v, list) else v for k, v in g.items()})
            for g in json.loads(run["geometry"])
        ],
        metadata=RunMetadata(
            scenario_yaml=run["scenario_yaml"],
            vehicle_yaml=run.get("vehicle_yaml", ""),  # a rig recording has no model
            bushing_parameters=json.loads(run.get("bushing_parameters", "{}")),
            software_version=run["software_version"],
            git_revision=run["git_revision"],
            extra=json.loads(run["extra"]),
            source=run.get("source", "simulation"),  # files written before sources existed are simulated
        ),
        complete=status["complete"] == "true",
        reason=status["reason"],
    )
