"""Run files read by the MCAP project's own decoders, apart from the project's fixed-layout reader:
every message of a recording decoded from the schemas in the file (ROS 2 CDR and protobuf), each
signal found by its name on ``/plot`` (what Foxglove's Plot panel offers), and recordings written
before ``/plot`` existed still read."""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory as ProtobufDecoders
from mcap_ros2._dynamic import generate_dynamic
from mcap_ros2.decoder import DecoderFactory as Ros2Decoders

from elastokin.core.shipped import SHIPPED_ROOT
from elastokin.recordings.message_layouts import PlotLayout
from elastokin.recordings.recorder import run_scenario
from elastokin.recordings.run_format import Run, SignalSpec
from elastokin.recordings.run_reader import load_run
from elastokin.vehicle.scenarios.scenario_file import load_scenario

#: A field of a ``/plot`` group as the schema writes it: its name, then the signal and unit it holds.
FIELD_LINE = re.compile(r"^float64 (\S+)  # (\S+) \[(.*)\]$")
#: ROS 2's rule for a field name (rosidl): lowercase, digits, single underscores, no trailing one.
ROS2_FIELD = re.compile(r"^(?!.*__)(?!.*_$)[a-z][a-z0-9_]*$")


def _decoded(path: Path) -> tuple[dict[str, list], Counter, dict[str, str]]:
    """Every message of ``path`` decoded by the MCAP project's decoders, by topic; how many messages
    the file's summary counts on each topic; each ROS 2 topic's schema text."""
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[Ros2Decoders(), ProtobufDecoders()])
        summary = reader.get_summary()
        counted = Counter({summary.channels[c].topic: n for c, n in summary.statistics.channel_message_counts.items()})
        schemas = {c.topic: summary.schemas[c.schema_id].data.decode() for c in summary.channels.values()
                   if summary.schemas[c.schema_id].encoding == "ros2msg"}
        decoded: dict[str, list] = {}
        for _, channel, message, value in reader.iter_decoded_messages(log_time_order=False):
            decoded.setdefault(channel.topic, []).append((message.log_time, value))
    return decoded, counted, schemas


def _plot_fields(schema: str) -> dict[str, dict[str, tuple[str, str]]]:
    """Each ``/plot`` group's fields, read from the schema text alone: group type -> field -> (signal, unit)."""
    out: dict[str, dict[str, tuple[str, str]]] = {}
    for block in schema.split("=" * 80):
        lines = block.strip().splitlines()
        if lines and lines[0].startswith("MSG: vsim_msgs/"):
            out[lines[0].removeprefix("MSG: vsim_msgs/")] = {
                m[1]: (m[2], m[3]) for m in (FIELD_LINE.match(line) for line in lines[1:]) if m}
    return out


def _check_every_message(path: Path, run: Run) -> None:
    """Every message of ``path`` decodes; ``/plot`` holds each of ``run``'s signals by name, and
    ``/signals``, ``/tf`` and ``/geometry`` what ``run`` holds."""
    decoded, counted, schemas = _decoded(path)
    assert Counter({t: len(m) for t, m in decoded.items()}) == counted   # nothing left undecoded
    n = run.t_s.size
    t_ns = np.round(run.t_s * 1e9).astype(np.int64)

    plot = decoded["/plot"]
    assert len(plot) == n and [t for t, _ in plot] == t_ns.tolist()
    groups = _plot_fields(schemas["/plot"])
    found: dict[str, np.ndarray] = {}
    for group_field in plot[0][1].__slots__[1:]:
        group_type = type(getattr(plot[0][1], group_field)).__name__
        for field, (signal, unit) in groups[group_type].items():
            assert ROS2_FIELD.match(field) and signal not in found
            assert run.units[signal] == unit
            found[signal] = np.array([getattr(getattr(m, group_field), field) for _, m in plot])
    assert found.keys() == run.signals.keys()
    for name, values in found.items():
        np.testing.assert_array_equal(values, run.signals[name], err_msg=name)
    stamps = np.array([m.stamp.sec * 1_000_000_000 + m.stamp.nanosec for _, m in plot])
    np.testing.assert_array_equal(stamps, t_ns)

    joint_state = [s for s in run.specs if s.group == "camber"] or [s for s in run.specs if s.group == "vehicle"]
    messages = decoded[f"/signals/{joint_state[0].group}"]
    assert messages[0][1].name == [f"{s.name} [{s.unit}]" for s in joint_state]
    np.testing.assert_array_equal(np.array([m.position for _, m in messages]),
                                  np.column_stack([run.signals[s.name] for s in joint_state]))

    tf = decoded["/tf"]
    assert len(tf) == n and [f.child_frame_id for f in tf[-1][1].transforms] == run.body_names
    translation = tf[-1][1].transforms[0].translation
    np.testing.assert_array_equal([translation.x, translation.y, translation.z], run.body_pos[-1, 0])
    entities = decoded["/geometry"][0][1].entities
    assert {e.id for e in entities} <= set(run.body_names) and entities


@pytest.mark.parametrize("scenario, scale", [("kc/pumping", 0.05), ("road/step_steer", 0.15)])
def test_an_independent_reader_decodes_every_message_each_signal_by_name(scenario: str, scale: float,
                                                                         tmp_path: Path) -> None:
    result = run_scenario(load_scenario(scenario), tmp_path / "run.mcap", duration_scale=scale)
    _check_every_message(result.path, result.run)
    assert load_run(result.path).signals.keys() == result.run.signals.keys()


def test_the_names_are_ros2_names_whatever_the_signals_are_called() -> None:
    # groups interleaved, as a run's need not be: the message holds them group by group
    specs = [SignalSpec("toe_FL", "deg", "wheels"), SignalSpec("1st", "-", "run"),
             SignalSpec("rx_force", "N·m", "bushing_E1-fl"), SignalSpec("toe_fl", "deg", "wheels"),
             SignalSpec("a_y", "m/s²", "bushing_E1_fl"), SignalSpec("slip", "%", "run"),
             SignalSpec("yaw.rate", "deg/s", "run"), SignalSpec("t", "s", "stamp")]
    layout = PlotLayout(specs)
    types = generate_dynamic(layout.type_name, layout.schema.decode())   # rosidl's parser refuses a bad name
    t_ns = np.array([0, 1_500_000_000])
    values = np.arange(2 * len(specs), dtype=float).reshape(2, len(specs))
    message = types[layout.type_name](layout.encode_block(t_ns, values)[1].tobytes())
    assert list(message.__slots__) == ["stamp", "wheels", "run", "bushing_e1_fl", "bushing_e1_fl_2", "stamp_2"]
    assert (message.stamp.sec, message.stamp.nanosec) == (1, 500_000_000)
    assert [getattr(message.wheels, f) for f in ("toe_fl_deg", "toe_fl_deg_2")] == [8.0, 11.0]
    assert (message.run.s_1st, message.run.slip_pct, message.run.yaw_rate_deg_per_s) == (9.0, 13.0, 14.0)
    assert message.bushing_e1_fl.rx_force_n_m == 10.0 and message.bushing_e1_fl_2.a_y_m_per_s2 == 12.0
    assert message.stamp_2.t_s == 15.0
    assert type(message.bushing_e1_fl).__name__ != type(message.bushing_e1_fl_2).__name__


def test_recordings_from_before_the_named_signals_read_as_they_did() -> None:
    path = SHIPPED_ROOT / "data" / "rig" / "kc" / "01_kc_pumping.mcap"
    decoded, counted, _ = _decoded(path)
    assert "/plot" not in counted and Counter({t: len(m) for t, m in decoded.items()}) == counted
    run = load_run(path)
    assert run.complete and run.signals
    for spec in run.specs[:3]:
        messages = decoded[f"/signals/{spec.group}"]
        k = messages[0][1].name.index(f"{spec.name} [{spec.unit}]")
        np.testing.assert_array_equal([m.position[k] for _, m in messages], run.signals[spec.name])
