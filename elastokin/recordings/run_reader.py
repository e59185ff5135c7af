"""Reading a run file (written by :class:`elastokin.recordings.run_writer.RunWriter`) back into a
:class:`elastokin.recordings.run_format.Run`: a simulated run, or a measured rig recording
(``data/README.md``: no bodies, no model in its metadata)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
from mcap.reader import make_reader
from mcap.records import Channel, Message, Metadata
from mcap.stream_reader import StreamReader

from elastokin.core.errors import InputError
from elastokin.core.files import is_file
from elastokin.recordings.message_layouts import FrameTransformsLayout, JointStateLayout, timestamp_len
from elastokin.recordings.run_format import (FORMAT_VERSION, PARTIAL_SUFFIX, RUN_RECORD, SIGNAL_TOPIC_PREFIX, STATUS_RECORD,
                                        TF_TOPIC, GeomSpec, Run, RunMetadata, SignalSpec, signal_label)


def _read(path: Path) -> tuple[dict[str, dict[str, str]], dict[str, list[tuple[int, bytes]]], str]:
    """The metadata records and the messages (log time, bytes) by topic of an MCAP file, and why it
    was cut short ("" for a whole file): read through its summary, else record by record as far as
    it goes (a killed run's file has complete chunks but no summary)."""
    with open(path, "rb") as stream:
        try:
            reader = make_reader(stream)
            records = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
            messages: dict[str, list[tuple[int, bytes]]] = {}
            for _, channel, message in reader.iter_messages(log_time_order=False):
                messages.setdefault(channel.topic, []).append((message.log_time, message.data))
            return records, messages, ""
        except Exception:  # noqa: BLE001 - a damaged file can fail the decoder in any way: read it record by record
            pass
    records, messages, topics = {}, {}, {}
    with open(path, "rb") as stream:
        try:
            for rec in StreamReader(stream).records:
                if isinstance(rec, Metadata):
                    records[rec.name] = dict(rec.metadata)
                elif isinstance(rec, Channel):
                    topics[rec.id] = rec.topic
                elif isinstance(rec, Message) and rec.channel_id in topics:
                    messages.setdefault(topics[rec.channel_id], []).append((rec.log_time, rec.data))
        except Exception as exc:  # noqa: BLE001 - where the readable part ends
            return records, messages, f"it ends early ({exc or type(exc).__name__})"
    return records, messages, "it has no summary"


def _run_record(records: dict[str, dict[str, str]], path: Path, cut: str) -> dict[str, str]:
    run = records.get(RUN_RECORD)
    if run is None or run.get("format") != FORMAT_VERSION:
        why = f"unreadable MCAP: {cut}" if cut else f"not a vsim run file (no '{RUN_RECORD}' record of format {FORMAT_VERSION})"
        raise InputError(why, source=str(path))
    return run


def load_run(path: str | os.PathLike[str]) -> Run:
    """Read a run file; raises :class:`InputError` if it is missing, unreadable or not a vsim run.

    A file cut short (a killed run: no summary, a last chunk unfinished) is read as far as it goes
    and marked incomplete."""
    path = Path(path)
    if not is_file(path):
        partial = path.with_name(path.name + PARTIAL_SUFFIX)
        hint = f" (an unfinished run left {partial.name}: name it to read what it holds)" if partial.exists() else ""
        raise InputError(f"no such run file{hint}", source=str(path))
    records, messages, cut = _read(path)
    run = _run_record(records, path, cut)
    try:
        specs = [SignalSpec(**s) for s in json.loads(run["signals"])]
        bodies = [str(b) for b in json.loads(run["bodies"])]
        geometry = [GeomSpec(**{k: tuple(v) if isinstance(v, list) else v for k, v in g.items()})
                    for g in json.loads(run["geometry"])]
        metadata = RunMetadata(
            scenario_yaml=run["scenario_yaml"],
            vehicle_yaml=run.get("vehicle_yaml", ""),  # a rig recording has no model
            bushing_parameters=json.loads(run.get("bushing_parameters", "{}")),
            software_version=run["software_version"],
            git_revision=run["git_revision"],
            extra=json.loads(run["extra"]),
            source=run.get("source", "simulation"),  # files written before sources existed are simulated
        )
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise InputError(f"its '{RUN_RECORD}' record is damaged ({type(exc).__name__}: {exc})", source=str(path)) from None
    group_specs: dict[str, list[SignalSpec]] = {}
    for s in specs:
        group_specs.setdefault(s.group, []).append(s)
    layouts = {SIGNAL_TOPIC_PREFIX + g: JointStateLayout([signal_label(s) for s in members])
               for g, members in group_specs.items()}
    topics = [TF_TOPIC, *layouts] if bodies else list(layouts)
    times = {topic: [t for t, _ in messages.get(topic, [])] for topic in topics}
    payloads = {topic: [d for _, d in messages.get(topic, [])] for topic in topics}

    # A run stopped inside RunWriter.write may lack the last step on some channels: keep whole steps.
    # (Log times are unsigned 64-bit in MCAP: a damaged one may not fit int64.)
    n_steps = min((len(t) for t in times.values()), default=0)
    t_ns = np.array(next(iter(times.values()), [])[:n_steps], dtype=np.uint64)
    for topic, topic_times in times.items():
        if not np.array_equal(np.asarray(topic_times[:n_steps], dtype=np.uint64), t_ns):
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
        try:
            size = timestamp_len(data)
        except IndexError:
            size = -1  # too short to hold one transform: no layout matches it
        layout = tf_layouts.get(size) or tf_layouts.setdefault(size, FrameTransformsLayout(bodies, max(size, 0)))
        decoded = layout.decode(data)
        if decoded is None:
            raise InputError(f"{TF_TOPIC} message {i} does not match the recorded body list", source=str(path))
        poses[i] = decoded

    status = records.get(STATUS_RECORD) or {"complete": "false", "reason": "no status record: the run was not closed"}
    if cut:
        status = {"complete": "false", "reason": f"{status['reason']}; {cut}: read as far as it goes".lstrip("; ")}
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
        geometry=geometry,
        metadata=metadata,
        complete=status.get("complete") == "true",
        reason=str(status.get("reason", "")),
    )
