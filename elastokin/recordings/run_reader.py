"""Reading a run file (written by :class:`elastokin.recordings.run_writer.RunWriter`) back into a
:class:`elastokin.recordings.run_format.Run`: a simulated run, or a measured rig recording
(``data/README.md``: no bodies, no model in its metadata)."""

from __future__ import annotations

import functools
import json
import os
import struct
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mcap.records import Channel, Chunk, DataEnd, Message, Metadata
from mcap.exceptions import EndOfFile
from mcap.stream_reader import CRCValidationError, StreamReader, breakup_chunk

from elastokin.core.errors import ElastokinWarning, InputError
from elastokin.core.files import is_file
from elastokin.vehicle.simulation.unconverged import UnconvergedSteps
from elastokin.recordings.message_layouts import FrameTransformsLayout, JointStateLayout, timestamp_len
from elastokin.recordings.run_format import (FORMAT_VERSION, PARTIAL_SUFFIX, RUN_RECORD, SIGNAL_TOPIC_PREFIX, STATUS_RECORD,
                                        TF_TOPIC, GeomSpec, Run, RunMetadata, SignalSpec, signal_label)


class DamagedRecording(ElastokinWarning):
    """A run file read in part: cut short, or with chunks that failed their CRC (the message says
    what is missing). :func:`load_run` warns with it, or raises it as an InputError when strict."""


@dataclass(frozen=True)
class _Lost:
    """A chunk that could not be read: its number (1-based), its messages' time span [ns], why."""

    number: int
    start_ns: int
    end_ns: int
    why: str


def _read(path: Path) -> tuple[dict[str, dict[str, str]], dict[str, list[tuple[int, bytes]]], list[_Lost], int, str]:
    """The metadata records and the messages (log time, bytes) by topic of an MCAP file, read record
    by record, each chunk checked against its CRC and left out when it fails (or does not
    decompress); the chunks lost, the number of chunks, and why the file ends early ("" for a
    whole file: its data section ended, and checked against its own CRC)."""
    records: dict[str, dict[str, str]] = {}
    topics: dict[int, str] = {}
    by_channel: dict[int, list[tuple[int, bytes]]] = {}
    lost: list[_Lost] = []
    cut = ""

    def take(rec: object) -> None:
        if isinstance(rec, Metadata):
            records[rec.name] = dict(rec.metadata)
        elif isinstance(rec, Channel):
            topics[rec.id] = rec.topic
        elif isinstance(rec, Message):
            by_channel.setdefault(rec.channel_id, []).append((rec.log_time, rec.data))

    chunks, data_end = 0, False

    def read(rec: object) -> None:
        nonlocal chunks, data_end
        if isinstance(rec, Chunk):
            chunks += 1
            try:
                inner = breakup_chunk(rec, validate_crc=True)
            except CRCValidationError:
                lost.append(_Lost(chunks, rec.message_start_time, rec.message_end_time, "failed its CRC"))
                return
            except Exception as exc:  # noqa: BLE001 - damaged bytes can fail the decoder in any way
                lost.append(_Lost(chunks, rec.message_start_time, rec.message_end_time,
                                  f"cannot be read ({type(exc).__name__})"))
                return
            for record in inner:
                take(record)
        elif not data_end or isinstance(rec, Channel):
            # the summary after the data repeats what the data held; its channels name the messages
            # of a chunk whose own channel records were in a chunk left out
            take(rec)
        data_end = data_end or isinstance(rec, DataEnd)

    with open(path, "rb") as stream:
        try:
            try:
                for rec in StreamReader(stream, emit_chunks=True, validate_crcs=True).records:
                    read(rec)
            except CRCValidationError as exc:   # the data section's own CRC, checked at its end record
                if not isinstance(exc.record, DataEnd):
                    raise
                data_end = True
                if not lost:   # a record outside the chunks changed
                    cut = "its data section failed its CRC"
                for rec in StreamReader(stream, skip_magic=True, emit_chunks=True).records:   # the summary
                    read(rec)
        except Exception as exc:  # noqa: BLE001 - where the readable part ends
            why = ("no summary section" if isinstance(exc, EndOfFile) else "the file ends inside a record"
                   if isinstance(exc, struct.error) else f"{type(exc).__name__}: {exc}")
            if not cut:
                cut = f"its summary section is cut ({why}); its data is whole" if data_end else why
    messages = {topics[c]: m for c, m in by_channel.items() if c in topics}
    return records, messages, lost, chunks, cut


def _run_record(records: dict[str, dict[str, str]], path: Path, cut: str) -> dict[str, str]:
    run = records.get(RUN_RECORD)
    if run is None or run.get("format") != FORMAT_VERSION:
        why = f"unreadable MCAP: {cut}" if cut else f"not a vsim run file (no '{RUN_RECORD}' record of format {FORMAT_VERSION})"
        raise InputError(why, source=str(path))
    return run


def load_run(path: str | os.PathLike[str], *, strict: bool = False) -> Run:
    """Read a run file; raises :class:`InputError` if it is missing, unreadable or not a vsim run.

    A damaged file is read as far as it goes, without the chunks that fail their CRC, and the run
    marked incomplete with what is missing in ``reason`` and ``damage``: a :class:`DamagedRecording`
    warning says so (with ``strict``, an InputError). A run stopped early but closed (divergence,
    Ctrl-C) is incomplete without damage."""
    path = Path(path)
    if not is_file(path):
        partial = path.with_name(path.name + PARTIAL_SUFFIX)
        hint = f" (an unfinished run left {partial.name}: name it to read what it holds)" if partial.exists() else ""
        raise InputError(f"no such run file{hint}", source=str(path))
    records, messages, lost, chunks, cut = _read(path)
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

    # The steps every channel holds: a run stopped inside RunWriter.write may lack its last step on
    # some channels, and a chunk left out may have held part of a step. (Log times are unsigned 64-bit
    # in MCAP: a damaged one may not fit int64.)
    times = {topic: np.array([t for t, _ in messages.get(topic, [])], dtype=np.uint64) for topic in topics}
    payloads = {topic: [d for _, d in messages.get(topic, [])] for topic in topics}
    for topic, topic_times in times.items():
        if topic_times.size > 1 and not np.all(topic_times[1:] > topic_times[:-1]):
            raise InputError(f"channel {topic}: its times do not increase", source=str(path))
    t_ns = functools.reduce(np.intersect1d, times.values()) if times else np.empty(0, np.uint64)
    kept = {topic: np.isin(topic_times, t_ns) for topic, topic_times in times.items()}
    for topic, topic_times in times.items():   # a step left out must be a lost chunk's or after the last whole one
        dropped = topic_times[~kept[topic]]
        explained = dropped > (t_ns[-1] if t_ns.size else 0)
        for c in lost:
            explained |= (dropped >= c.start_ns) & (dropped <= c.end_ns)
        if not np.all(explained) or (t_ns.size == 0 and dropped.size and not (lost or cut)):
            raise InputError(f"channel {topic} is not on the same time steps as the others", source=str(path))
    payloads = {topic: [d for d, keep in zip(payloads[topic], kept[topic]) if keep] for topic in topics}
    n_steps = t_ns.size

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

    damage = _damage(lost, chunks, cut, t_ns, metadata)
    status = records.get(STATUS_RECORD) or {"complete": "false", "reason": "no status record: the run was not closed"}
    whole = not lost and (not cut or cut.startswith("its summary section"))   # every sample is there
    if damage:
        if strict:
            raise InputError(f"damaged, and refused as strict reading asks: {'; '.join(damage)}", source=str(path))
        for item in damage:
            warnings.warn(DamagedRecording(f"{path}: {item}"), stacklevel=2)
        if not whole:
            status = {"complete": "false", "reason": "; ".join([*damage, status["reason"]] if status.get("complete") != "true"
                                                              else damage)}
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
        damage=tuple(damage),
        unconverged=_unconverged(records.get(STATUS_RECORD, {}), path),
    )


def _unconverged(status: dict[str, str], path: Path) -> tuple[UnconvergedSteps, ...]:
    """The status record's unconverged bushing steps (none in a file written before it kept them)."""
    try:
        return tuple(UnconvergedSteps.from_record(r) for r in json.loads(status.get("unconverged", "[]")))
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise InputError(f"its '{STATUS_RECORD}' record is damaged ({type(exc).__name__}: {exc})",
                         source=str(path)) from None


def _damage(lost: list[_Lost], chunks: int, cut: str, t_ns: np.ndarray, metadata: RunMetadata) -> list[str]:
    """What a damaged file could not give, in a reader's words: each chunk left out with the time it
    held, and where a cut file ends against where its run was to end."""
    out = [f"chunk {c.number} of {chunks} {c.why}: {(c.end_ns - c.start_ns) / 1e9:.1f} s missing "
           f"(t = {c.start_ns / 1e9:.1f} to {c.end_ns / 1e9:.1f} s)" for c in lost]
    if cut.startswith("its summary section"):
        out.append(cut)
    elif cut.startswith("its data section"):
        out.append(f"{cut}: a record outside its chunks (an index, or its metadata) changed; its samples are read, "
                   f"what it says of itself may be wrong")
    elif cut:
        cases = metadata.extra.get("cases") or [{}]
        planned = cases[-1].get("end_s") if isinstance(cases[-1], dict) else None
        of = f" of its {planned:.1f} s" if isinstance(planned, (int, float)) else ""
        at = f"at {t_ns[-1] / 1e9:.1f} s{of}" if t_ns.size else f"before its first whole sample{of and ' (' + of[1:] + ')'}"
        out.append(f"recording cut {at} ({cut}): read as far as it goes")
    return out


def check_samples(run: Run, what: str) -> None:
    """InputError unless ``run`` holds a sample to ``what`` (plot, replay): a recording cut before its
    first whole sample holds none."""
    if run.t_s.size == 0:
        raise InputError(f"holds no whole sample: nothing to {what}", source=str(run.path))
