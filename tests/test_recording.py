"""Run files: write/read round trip, determinism, interrupted runs, Rerun conversion, replay and plots.

Synthetic signals and a toy MuJoCo model (a fixed chassis, a swinging arm, a spinning wheel) stand in
for the car and the scenario runner.
"""

from __future__ import annotations

import argparse
import subprocess
from pathlib import Path

import mujoco
import numpy as np
import pytest
import rerun.chunk
from foxglove.messages import FrameTransform, FrameTransforms, Quaternion, Timestamp, Vector3
from mcap.reader import make_reader

from elastokin.cli import plot as plot_cli
from elastokin.cli import view as view_cli
from elastokin.core.errors import InputError
from elastokin.recordings.message_layouts import FrameTransformsLayout, timestamp_field
from elastokin.recordings.recorder import geometry_from_model
from elastokin.recordings.run_format import RunMetadata, SignalSpec, rotation_matrix, signal_label
from elastokin.recordings.run_reader import load_run
from elastokin.recordings.run_writer import RunWriter

BODIES = ["chassis", "arm", "wheel"]
SIGNALS = [
    SignalSpec("wheel_travel_fl", "mm", "wheels"),
    SignalSpec("camber_fl", "deg", "wheels", x_axis="wheel_travel_fl"),
    SignalSpec("toe_fl", "deg", "wheels", x_axis="wheel_travel_fl"),
    SignalSpec("bushing_e1_fl_x_deflection", "mm", "bushings"),
    SignalSpec("bushing_e1_fl_x_force", "N", "bushings"),
    SignalSpec("rack_displacement", "mm", "inputs"),
]
METADATA = RunMetadata(
    scenario_yaml="name: pumping\ncases: [10, 20]\n",
    vehicle_yaml="wheelbase_m: 2.608\n",
    bushing_parameters={"e1_front": {"model": "STVS", "k0_N_per_m": 4.93e6, "tan_delta": 0.15}},
    software_version="0.1.0",
    git_revision="0123abc",
    extra={"case": 3, "amplitudes_mm": [10, 20]},
)
N_STEPS = 400


def toy_model() -> mujoco.MjModel:
    """Chassis (box and mesh) fixed in the world, arm (capsule) on a hinge, wheel on a hinge."""
    spec = mujoco.MjSpec()
    mesh = spec.add_mesh()
    mesh.name = "tetra"
    mesh.uservert = [0, 0, 0, 0.2, 0, 0, 0, 0.1, 0, 0, 0, 0.3]
    chassis = spec.worldbody.add_body(name="chassis", pos=[0, 0, 0.5])
    chassis.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[1, 0.5, 0.2], rgba=[0.6, 0.6, 0.6, 1])
    chassis.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="tetra", pos=[0.5, 0, 0.2])
    arm = chassis.add_body(name="arm", pos=[0.5, 0.5, 0])
    arm.add_joint(type=mujoco.mjtJoint.mjJNT_HINGE, axis=[1, 0, 0], stiffness=100, damping=1)
    arm.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.03, 0.2, 0], pos=[0, 0.2, 0], quat=[1, 1, 0, 0])
    wheel = arm.add_body(name="wheel", pos=[0, 0.45, 0])
    wheel.add_joint(type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0], damping=0.1)
    wheel.add_geom(type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[0.3, 0.1, 0], quat=[1, 1, 0, 0])
    wheel.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.05, 0, 0], pos=[0.2, 0, 0])
    wheel.add_geom(type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=[0.05, 0.02, 0.03], pos=[-0.2, 0, 0])
    return spec.compile()


@pytest.fixture(scope="module")
def trajectory() -> dict[str, np.ndarray]:
    """N_STEPS recorded steps of the toy model and synthetic K&C-like signals (a hysteretic loop)."""
    model = toy_model()
    data = mujoco.MjData(model)
    data.qvel[:] = [2.0, 20.0]
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in BODIES]
    t = np.arange(N_STEPS) * 0.01
    pos, quat = np.empty((N_STEPS, 3, 3)), np.empty((N_STEPS, 3, 4))
    for i in range(N_STEPS):
        pos[i], quat[i] = data.xpos[ids], data.xquat[ids]
        mujoco.mj_step(model, data, nstep=10)
    travel = 60 * np.sin(2 * np.pi * 0.5 * t)
    rate = np.cos(2 * np.pi * 0.5 * t)
    values = np.column_stack(
        [
            travel,
            -0.02 * travel + 0.1 * rate,
            1e-3 * travel,
            0.01 * travel,
            5 * travel + 40 * np.tanh(3 * rate),
            1e-3 * t,
        ]
    )
    return {"t": t, "values": values, "pos": pos, "quat": quat, "geometry": geometry_from_model(model, BODIES)}


def write_run(path: Path, traj: dict, *, steps: int = N_STEPS, overwrite: bool = False) -> None:
    with RunWriter(
        path, signals=SIGNALS, bodies=BODIES, geometry=traj["geometry"], metadata=METADATA, overwrite=overwrite
    ) as writer:
        for i in range(steps):
            writer.write(traj["t"][i], traj["values"][i], traj["pos"][i], traj["quat"][i])


@pytest.fixture(scope="module")
def run_file(tmp_path_factory: pytest.TempPathFactory, trajectory: dict) -> Path:
    path = tmp_path_factory.mktemp("run") / "run.mcap"
    write_run(path, trajectory)
    return path


def test_round_trip_of_every_channel(run_file: Path, trajectory: dict) -> None:
    run = load_run(run_file)
    assert run.complete and run.reason == ""
    np.testing.assert_array_equal(run.t_s, np.round(trajectory["t"] * 1e9) / 1e9)  # MCAP time is in ns
    for k, spec in enumerate(SIGNALS):
        np.testing.assert_array_equal(run.signals[spec.name], trajectory["values"][:, k])
        assert run.units[spec.name] == spec.unit and run.groups[spec.name] == spec.group
    assert run.specs == SIGNALS
    assert run.body_names == BODIES
    np.testing.assert_array_equal(run.body_pos, trajectory["pos"])
    np.testing.assert_array_equal(run.body_quat_wxyz, trajectory["quat"])
    assert run.geometry == trajectory["geometry"]
    assert run.metadata == METADATA
    assert run.pairs() == [
        ("wheel_travel_fl", "camber_fl"),
        ("wheel_travel_fl", "toe_fl"),
        ("bushing_e1_fl_x_deflection", "bushing_e1_fl_x_force"),
    ]
    with open(run_file, "rb") as stream:
        summary = make_reader(stream).get_summary()
    channels = {c.topic: c for c in summary.channels.values()}
    assert set(channels) == {"/tf", "/geometry", "/signals/wheels", "/signals/bushings", "/signals/inputs", "/plot"}
    assert channels["/signals/wheels"].metadata["units"] == '["mm", "deg", "deg"]'
    assert summary.schemas[channels["/tf"].schema_id].name == "foxglove.FrameTransforms"
    assert summary.schemas[channels["/signals/wheels"].schema_id].name == "sensor_msgs/msg/JointState"
    assert summary.schemas[channels["/plot"].schema_id].name == "vsim_msgs/msg/Signals"


def test_geometry_from_model_in_body_frames() -> None:
    geometry = geometry_from_model(toy_model(), BODIES)
    assert [(g.body, g.kind) for g in geometry] == [
        ("chassis", "box"),
        ("chassis", "box"),  # the mesh, as its bounding box
        ("arm", "capsule"),
        ("wheel", "cylinder"),
        ("wheel", "sphere"),
        ("wheel", "ellipsoid"),
    ]
    assert geometry[0].size_m == (1.0, 0.5, 0.2) and geometry[0].rgba == pytest.approx((0.6, 0.6, 0.6, 1))
    assert geometry[2].size_m[:2] == pytest.approx((0.03, 0.2)) and geometry[2].pos_m == pytest.approx((0, 0.2, 0))
    with pytest.raises(ValueError, match="nose"):
        geometry_from_model(toy_model(), ["nose"])


def test_rotation_matrix_is_mujocos_without_mujoco() -> None:
    """Reading and drawing runs needs no MuJoCo: the numpy rotation agrees with mju_quat2Mat within
    round-off, and is a rotation."""
    rng = np.random.default_rng(3)
    for q in [np.array([1.0, 0, 0, 0]), *(q / np.linalg.norm(q) for q in rng.normal(size=(200, 4)))]:
        expected = np.empty(9)
        mujoco.mju_quat2Mat(expected, q)
        r = rotation_matrix(q)
        np.testing.assert_allclose(r, expected.reshape(3, 3), rtol=0, atol=4e-16)
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-15)


def test_frame_transforms_encoding_matches_foxglove_sdk() -> None:
    """Our fixed-layout protobuf equals the SDK's (which omits only zero fields) for non-zero values."""
    rng = np.random.default_rng(1)
    poses = rng.uniform(0.1, 1.0, size=(2, 7))
    t_ns = 12_345_678_901
    sdk = FrameTransforms(
        transforms=[
            FrameTransform(
                timestamp=Timestamp(12, 345_678_901),
                parent_frame_id="world",
                child_frame_id=body,
                translation=Vector3(x=p[0], y=p[1], z=p[2]),
                rotation=Quaternion(x=p[3], y=p[4], z=p[5], w=p[6]),
            )
            for body, p in zip(["a", "wheel_fl"], poses)
        ]
    ).encode()
    timestamp = timestamp_field(t_ns)
    layout = FrameTransformsLayout(["a", "wheel_fl"], len(timestamp))
    assert layout.encode(timestamp, poses) == sdk
    np.testing.assert_array_equal(layout.decode(sdk), poses)


def test_equal_inputs_give_bit_identical_data(tmp_path: Path, trajectory: dict) -> None:
    write_run(tmp_path / "a.mcap", trajectory)
    write_run(tmp_path / "b.mcap", trajectory)
    a, b = load_run(tmp_path / "a.mcap"), load_run(tmp_path / "b.mcap")
    for name in a.signals:
        assert a.signals[name].tobytes() == b.signals[name].tobytes()
    assert a.t_s.tobytes() == b.t_s.tobytes() and a.body_pos.tobytes() == b.body_pos.tobytes()

    def messages(path: Path) -> list[tuple[str, int, int, bytes]]:
        with open(path, "rb") as stream:
            return [(c.topic, m.log_time, m.publish_time, m.data) for _, c, m in make_reader(stream).iter_messages()]

    first = messages(tmp_path / "a.mcap")
    assert first == messages(tmp_path / "b.mcap")
    assert first[-1][1] == int(round(trajectory["t"][-1] * 1e9))  # log time is simulation time


@pytest.mark.parametrize("stop", [RuntimeError("diverged at t = 0.5 s"), KeyboardInterrupt()])
def test_stopped_run_is_readable_and_marked_incomplete(tmp_path: Path, trajectory: dict, stop: BaseException) -> None:
    path = tmp_path / "stopped.mcap"
    with pytest.raises(type(stop)):
        with RunWriter(path, signals=SIGNALS, bodies=BODIES, geometry=[], metadata=METADATA) as writer:
            for i in range(50):
                writer.write(trajectory["t"][i], trajectory["values"][i], trajectory["pos"][i], trajectory["quat"][i])
            raise stop
    assert not path.with_name("stopped.mcap.partial").exists()
    run = load_run(path)
    assert not run.complete
    assert run.reason.startswith(type(stop).__name__)
    assert len(run.t_s) == 50
    np.testing.assert_array_equal(run.signals["camber_fl"], trajectory["values"][:50, 1])
    subprocess.run(["rerun", "mcap", "check", str(path)], check=True, capture_output=True)


def test_run_stopped_inside_a_step_keeps_whole_steps(tmp_path: Path, trajectory: dict) -> None:
    """Ctrl-C between two channels of one step: the reader drops the half-written step."""

    class InterruptedChannel:
        def __init__(self, channel: object, calls_before_stop: int):
            self.channel, self.calls_left = channel, calls_before_stop

        def log(self, data: bytes, log_time: int) -> None:
            if self.calls_left == 0:
                raise KeyboardInterrupt
            self.calls_left -= 1
            self.channel.log(data, log_time=log_time)

    path = tmp_path / "half.mcap"
    with pytest.raises(KeyboardInterrupt):
        with RunWriter(path, signals=SIGNALS, bodies=BODIES, geometry=[], metadata=METADATA) as writer:
            channel, layout, members = writer._groups[1]
            writer._groups[1] = (InterruptedChannel(channel, 7), layout, members)
            for i in range(20):
                writer.write(trajectory["t"][i], trajectory["values"][i], trajectory["pos"][i], trajectory["quat"][i])
    run = load_run(path)
    assert len(run.t_s) == 7 and run.body_pos.shape == (7, 3, 3) and not run.complete


def test_existing_output_is_not_overwritten(tmp_path: Path, trajectory: dict) -> None:
    path = tmp_path / "run.mcap"
    write_run(path, trajectory, steps=5)
    before = path.read_bytes()
    with pytest.raises(InputError, match="overwrite"):
        write_run(path, trajectory, steps=10)
    assert path.read_bytes() == before
    write_run(path, trajectory, steps=10, overwrite=True)
    assert len(load_run(path).t_s) == 10


def test_bad_writes_and_bad_files_are_refused(tmp_path: Path, trajectory: dict) -> None:
    with RunWriter(tmp_path / "r.mcap", signals=SIGNALS, bodies=BODIES, geometry=[], metadata=METADATA) as writer:
        writer.write(0.0, trajectory["values"][0], trajectory["pos"][0], trajectory["quat"][0])
        with pytest.raises(ValueError, match="not after the previous"):
            writer.write(0.0, trajectory["values"][0], trajectory["pos"][0], trajectory["quat"][0])
        with pytest.raises(ValueError, match="expected values"):
            writer.write(1.0, trajectory["values"][0][:2], trajectory["pos"][0], trajectory["quat"][0])
    with pytest.raises(ValueError, match="unique"):
        RunWriter(tmp_path / "d.mcap", signals=SIGNALS * 2, bodies=BODIES, geometry=[], metadata=METADATA)
    with pytest.raises(InputError, match="no such run file"):
        load_run(tmp_path / "missing.mcap")
    (tmp_path / "junk.mcap").write_bytes(b"not an mcap")
    with pytest.raises(InputError, match="unreadable MCAP"):
        load_run(tmp_path / "junk.mcap")


def _entities(rrd: Path) -> dict[str, list]:
    """Record batches of every chunk of an .rrd, by entity path."""
    out: dict[str, list] = {}
    for chunk in rerun.chunk.RrdReader(rrd).stream():
        out.setdefault(chunk.entity_path, []).append(chunk.to_record_batch())
    return out


def _column(batches: list, name: str) -> list:
    return [row for batch in batches if name in batch.schema.names for row in batch.column(name).to_pylist()]


def test_rerun_mcap_convert_holds_transforms_and_signals(run_file: Path, trajectory: dict, tmp_path: Path) -> None:
    rrd = tmp_path / "converted.rrd"
    subprocess.run(
        ["rerun", "mcap", "convert", str(run_file), "-o", str(rrd), "--timeline-type", "duration"],
        check=True,
        capture_output=True,
    )
    entities = _entities(rrd)
    tf = entities["/tf"]
    children = _column(tf, "Transform3D:child_frame")
    assert children[: len(BODIES)] == [[b] for b in BODIES] and len(children) == N_STEPS * len(BODIES)
    translations = np.array(_column(tf, "Transform3D:translation")).reshape(N_STEPS, len(BODIES), 3)
    np.testing.assert_allclose(translations, trajectory["pos"], rtol=1e-6, atol=1e-6)  # Rerun stores float32
    for group, columns in (("wheels", slice(0, 3)), ("bushings", slice(3, 5))):
        batches = entities[f"/signals/{group}/position"]
        assert _column(batches, "SeriesLines:names")[0] == [signal_label(s) for s in SIGNALS[columns]]
        np.testing.assert_array_equal(np.array(_column(batches, "Scalars:scalars")), trajectory["values"][:, columns])
        times = _column(batches, "message_log_time")
        assert times[-1].total_seconds() == pytest.approx(trajectory["t"][-1])


def _cli(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="vsim")
    commands = parser.add_subparsers(dest="command", required=True)
    for command in (view_cli, plot_cli):
        command.register(commands)
    args = parser.parse_args(argv)
    return args.func(args)


def test_vsim_view_save_writes_a_verified_recording(run_file: Path, tmp_path: Path) -> None:
    rrd = tmp_path / "view.rrd"
    assert _cli(["view", str(run_file), "--save", str(rrd)]) == 0
    subprocess.run(["rerun", "rrd", "verify", str(rrd)], check=True, capture_output=True)
    entities = _entities(rrd)
    for body in BODIES:
        assert len(_column(entities[f"/car/{body}"], "Transform3D:translation")) == N_STEPS
    assert "/car/arm/capsule" in entities and "/car/wheel/cylinder" in entities
    assert len(_column(entities["/signals/wheels/camber_fl"], "Scalars:scalars")) == N_STEPS
    assert "/pairs/bushing_e1_fl_x_force__vs__bushing_e1_fl_x_deflection/curve" in entities
    with pytest.raises(InputError, match="overwrite"):
        _cli(["view", str(run_file), "--save", str(rrd)])


def test_vsim_plot_writes_pngs(run_file: Path, tmp_path: Path) -> None:
    out = tmp_path / "png"
    assert _cli(["plot", str(run_file), "-o", str(out)]) == 0
    assert _cli(["plot", str(run_file), "-o", str(out), "--log-time", "--t0", "1.0"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == [
        "loops_bushings.png",
        "pairs_wheels.png",
        "time_bushings.png",
        "time_bushings_logt.png",
        "time_inputs.png",
        "time_inputs_logt.png",
        "time_wheels.png",
        "time_wheels_logt.png",
    ]
    for name in names:
        data = (out / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000


class _Blocks:
    """A stand-in writer and layout for BackgroundWriter: records what it writes, fails on request."""

    def __init__(self, fail_at: int = -1):
        self.written, self.fail_at = [], fail_at

    def values(self, block):
        return block.measured

    def write_block(self, t_s, values, pos, quat):
        if len(self.written) == self.fail_at:
            raise OSError("no space left on device")
        self.written.append(t_s.copy())
        return np.round(t_s * 1e9).astype(np.uint64)


def _block(k: int):
    from elastokin.vehicle.simulation.outputs import SampleBlock

    t = np.arange(k * 3, k * 3 + 3) * 0.02 + 0.02
    return SampleBlock(t, 1, 2, t, np.zeros((3, 0)), np.full((3, 2), float(k)), np.empty((3, 0, 3)),
                       np.empty((3, 0, 4)))


def test_background_writer_keeps_the_order_and_hands_its_errors_to_the_caller() -> None:
    """Blocks are written in the order given and kept for the run in memory; a failed write is
    raised at the caller's next put (nothing after it is written) and, when the caller itself
    stops on an error, joined to that error as a note."""
    from elastokin.recordings.background import BackgroundWriter

    sink = _Blocks()
    with BackgroundWriter(sink, sink) as writer:
        for k in range(20):
            writer.put(_block(k))
    assert [t[0] for t in sink.written] == [_block(k).time_s[0] for k in range(20)]
    assert np.array_equal(np.concatenate(writer.values)[:, 0], np.repeat(np.arange(20.0), 3))
    failing = _Blocks(fail_at=2)
    with pytest.raises(OSError, match="no space left"):
        with BackgroundWriter(failing, failing) as writer:
            for k in range(20):
                writer.put(_block(k))
    assert len(failing.written) == 2
    failing = _Blocks(fail_at=0)
    with pytest.raises(KeyboardInterrupt) as stopped:
        with BackgroundWriter(failing, failing) as writer:
            writer.put(_block(0))
            raise KeyboardInterrupt
    assert "the recording also failed: OSError: no space left on device" in stopped.value.__notes__
