"""The Rerun replay opens on what an engineer came to see (issue 26, item 7), checked with numbers on
short recordings of the real car: every primitive of the car, at every recorded sample, projects
inside the 3D view (the fixed eye on the rig, the follow camera on the road) and fills a good part of
it; the road has a ground under the whole drive and the chassis' path on it; every pair view shows
its whole curve, over the whole recording, inside its bounds; a time-series plot holds one unit.

What the viewer makes of it is checked by eye: `python tools/replay_screenshots.py`."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np
import pytest
import rerun.blueprint as rrb
import rerun.chunk

from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.presentation.replay import FOV_Y_RAD, TIMELINE, VIEW_ASPECT, blueprint, car_bounds_m, replay
from elastokin.recordings.recorder import run_scenario
from elastokin.recordings.run_format import Run, rotation_matrix
from elastokin.recordings.run_reader import load_run

RIG = """\
    type: pumping
    vehicle: {vehicle}
    axles: [front, rear]
    output_rate_hz: 50
    settle: {{before_bushings_s: 0.2, before_input_s: 0.2}}
    defaults: {{shape: triangle, frequency_hz: 1.0, cycles: 1}}
    cases: [{{amplitude_mm: 60}}]
"""
ROAD = """\
    type: step_steer
    vehicle: {vehicle}
    settle: {{at_rest_s: 0.3, bushings_on_s: 0.1, straight_s: 0.3}}
    output_rate_hz: 50
    defaults: {{speed_kmh: 80, hold_s: 1.0, rise_time_s: 0.1}}
    cases:
      - {{label: left, steering_wheel_deg: 90}}
      - {{label: right, steering_wheel_deg: -90}}
"""


def _record(tmp_path: Path, name: str, text: str) -> tuple[Run, dict[str, list]]:
    """The run recorded from the scenario ``text``, read back from its file, and its replay's chunks."""
    scenario = tmp_path / f"{name}.yaml"
    scenario.write_text(textwrap.dedent(text.format(vehicle=DEFAULT_VEHICLE)))
    run_scenario(load_scenario(scenario), tmp_path / f"{name}.mcap")
    run = load_run(tmp_path / f"{name}.mcap")
    replay(run, save=tmp_path / f"{name}.rrd")
    chunks: dict[str, list] = {}
    for chunk in rerun.chunk.RrdReader(tmp_path / f"{name}.rrd").stream():
        chunks.setdefault(chunk.entity_path, []).append(chunk)
    return run, chunks


@pytest.fixture(scope="module")
def rig(tmp_path_factory: pytest.TempPathFactory) -> tuple[Run, dict[str, list]]:
    return _record(tmp_path_factory.mktemp("rig"), "rig", RIG)


@pytest.fixture(scope="module")
def road(tmp_path_factory: pytest.TempPathFactory) -> tuple[Run, dict[str, list]]:
    return _record(tmp_path_factory.mktemp("road"), "road", ROAD)


def _column(chunks: list, name: str, *, static: bool | None = None) -> list:
    """The rows of column ``name`` over ``chunks`` (only the static or temporal ones if asked)."""
    return [row for c in chunks if static is None or c.is_static == static
            for batch in [c.to_record_batch()] if name in batch.schema.names for row in batch.column(name).to_pylist()]


def _times_s(chunks: list) -> np.ndarray:
    """The ``sim_time`` of the temporal rows of ``chunks``, in s (Python's timedelta: to the µs)."""
    return np.array([t.total_seconds() for t in _column(chunks, TIMELINE, static=False)])


def _views(part: rrb.Container | rrb.View) -> list[rrb.View]:
    return [part] if isinstance(part, rrb.View) else [v for c in part.contents for v in _views(c)]


def _car_corners(run: Run) -> np.ndarray:
    """(N, P, 3) world corners of every primitive's own (oriented) box at every sample."""
    index = {b: i for i, b in enumerate(run.body_names)}
    signs = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
    out = []
    for g in run.geometry:
        r, h = g.size_m[0], g.size_m[1]
        half = {"box": g.size_m, "ellipsoid": g.size_m, "sphere": (r, r, r), "cylinder": (r, r, h),
                "capsule": (r, r, h + r)}[g.kind]
        local = np.array(g.pos_m) + (signs * half) @ rotation_matrix(g.quat_wxyz).T
        b = index[g.body]
        turn = np.array([rotation_matrix(q) for q in run.body_quat_wxyz[:, b]])
        out.append(run.body_pos[:, b, None, :] + np.einsum("nij,pj->npi", turn, local))
    return np.concatenate(out, axis=1)


def _screen(points: np.ndarray, eye: np.ndarray, right: np.ndarray, up: np.ndarray, forward: np.ndarray,
            fov_y_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) of ``points`` in the picture of a perspective eye, ±1 at the edges of a VIEW_ASPECT view,
    and their depth."""
    rel = points - eye
    depth = rel @ forward
    tan_y = math.tan(fov_y_rad / 2)
    return np.stack([rel @ right / (VIEW_ASPECT * tan_y * depth), rel @ up / (tan_y * depth)], -1), depth


def test_the_rig_replay_frames_the_whole_car_on_its_pads_at_every_sample(rig) -> None:
    run, _ = rig
    view = _views(blueprint(run).root_container)[0]
    assert view.class_identifier == "3D" and view.origin == "/"
    eye = view.properties["EyeControls3D"]
    position = np.array(eye.position.as_arrow_array().to_pylist()[0])
    target = np.array(eye.look_target.as_arrow_array().to_pylist()[0])
    low, high = car_bounds_m(run)
    pads = [g for g in run.geometry if g.body.startswith("pad_")]
    assert len(pads) == 4 and low[2] <= -0.02        # the box holds the pads, under the tyres at z = 0
    np.testing.assert_allclose(target, (low + high) / 2, atol=1e-6)
    forward = (target - position) / np.linalg.norm(target - position)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    corners = _car_corners(run)
    screen, depth = _screen(corners, position, right, np.cross(right, forward), forward, FOV_Y_RAD)
    assert depth.min() > 1.0 and position[2] > high[2]    # in front of the eye, seen from above
    extent = np.abs(screen).max(axis=(0, 1))
    assert extent.max() <= 1.0 and extent.max() >= 0.6, extent  # all of it in view, and filling it
    assert np.ptp(corners[..., 2], axis=0).max() > 0.1       # the pads moved by ±60 mm meanwhile


def test_the_road_replay_follows_the_car_with_a_camera_that_frames_it_at_every_sample(road) -> None:
    run, chunks = road
    view = _views(blueprint(run).root_container)[0]
    assert view.properties["EyeControls3D"].tracking_entity.as_arrow_array().to_pylist() == ["road/camera"]
    camera = chunks["/road/camera"]
    np.testing.assert_allclose(_times_s(camera), run.t_s, atol=1e-6)
    position = np.array(_column(camera, "Transform3D:translation"))
    turns = np.array(_column(camera, "Transform3D:mat3x3")).reshape(-1, 3, 3).transpose(0, 2, 1)  # column-major
    intrinsics = np.array(_column(camera, "Pinhole:image_from_camera")[0]).reshape(3, 3).T
    height = np.ravel(_column(camera, "Pinhole:resolution")[0])[1]
    fov_y = 2 * math.atan(height / 2 / intrinsics[1, 1])
    assert fov_y == pytest.approx(FOV_Y_RAD, rel=1e-6)
    corners = _car_corners(run)
    extents = []
    for n in range(len(run.t_s)):   # a pinhole's RDF axes: right, down, forward
        screen, depth = _screen(corners[n], position[n], turns[n][:, 0], -turns[n][:, 1], turns[n][:, 2], fov_y)
        assert depth.min() > 1.0
        extents.append(np.abs(screen).max(axis=0))
    assert np.max(extents) <= 1.0 and np.min(np.max(extents, axis=1)) >= 0.6
    heading = np.degrees(np.arctan2(turns[:, 1, 2], turns[:, 0, 2]))
    assert np.ptp(heading) > 30.0    # the car turned and the camera turned with it


def test_the_road_replay_has_a_ground_under_the_whole_drive_and_the_path_of_each_case(road) -> None:
    run, chunks = road
    chassis = run.body_pos[:, run.body_names.index("chassis")]
    centre = np.ravel(_column(chunks["/road/ground"], "Boxes3D:centers", static=True)[0])
    half = np.ravel(_column(chunks["/road/ground"], "Boxes3D:half_sizes", static=True)[0])
    inside = np.abs(chassis[:, :2] - centre[:2])
    assert np.all(inside <= half[:2] - 10.0)         # 10 m of ground at least beyond every point of the drive
    assert -0.01 <= centre[2] + half[2] <= 0.0      # its top just under the road (z = 0)
    strips = _column(chunks["/road/trajectory"], "LineStrips3D:strips", static=True)[0]
    cases = run.signals["case"]
    assert len(strips) == len(np.unique(cases)) == 2
    for strip, case in zip(strips, np.unique(cases)):
        np.testing.assert_allclose(np.array(strip)[:, :2], chassis[cases == case, :2], atol=1e-4)   # float32
    assert np.ptp(chassis[:, 1]) > 5.0    # the path leaves the straight line: the car turned


@pytest.mark.parametrize("kind", ["rig", "road"])
def test_every_pair_view_shows_its_whole_curve_over_the_whole_recording(kind: str, request) -> None:
    run, chunks = request.getfixturevalue(kind)
    views = [v for v in _views(blueprint(run).root_container) if v.class_identifier == "2D"]
    assert len(views) == len(run.pairs()) and (kind == "road" or any("camber_fl" in v.contents for v in views))
    for view in views:
        # the view's origin is the pairs' parent, so that the pair's own transform applies
        assert view.origin == "pairs" and view.contents.startswith("+ /pairs/") and view.contents.endswith("/**")
        pair = view.contents[2:-3]
        (bounds,) = view.properties["VisualBounds2D"].range.as_arrow_array().to_pylist()
        scale = np.ravel(_column(chunks[pair], "Transform3D:scale", static=True)[0])
        # the curve is static: the viewer shows it whole at every time; its points are every sample
        (curve,) = _column(chunks[f"{pair}/curve"], "LineStrips2D:strips", static=True)[0]
        y_name, x_name = pair.removeprefix("/pairs/").split("__vs__")
        xy = np.column_stack([run.signals[x_name], run.signals[y_name]])
        span = np.where(np.ptp(xy, axis=0) > 0, np.ptp(xy, axis=0), 1.0)
        offsets = xy - (xy.min(axis=0) + xy.max(axis=0)) / 2
        assert np.abs((np.array(curve) - offsets) / span).max() < 1e-6   # every sample, exact to float32
        shown = np.array(curve) * scale[:2]
        assert scale[1] < 0 < scale[0]              # y up, as on paper
        np.testing.assert_allclose(shown.min(axis=0), [-0.5, -0.5], atol=1e-5)
        np.testing.assert_allclose(shown.max(axis=0), [0.5, 0.5], atol=1e-5)
        assert bounds["x_range"][0] < -0.5 and bounds["x_range"][1] > 0.5
        assert bounds["y_range"][0] < -0.5 and bounds["y_range"][1] > 0.5
        np.testing.assert_allclose(_times_s(chunks[f"{pair}/now"]), run.t_s, atol=1e-6)   # the point moves all along


@pytest.mark.parametrize("kind", ["rig", "road"])
def test_every_signal_is_plotted_once_against_time_with_one_unit_per_plot(kind: str, request) -> None:
    run, _ = request.getfixturevalue(kind)
    views = [v for v in _views(blueprint(run).root_container) if v.class_identifier == "TimeSeries"]
    plotted = [c.rpartition("/")[2] for v in views for c in v.contents]
    assert sorted(plotted) == sorted(s.name for s in run.specs)
    for view in views:
        units = {run.units[c.rpartition("/")[2]] for c in view.contents}
        assert len(units) == 1 and view.name.endswith(f"[{units.pop()}]")


def test_a_run_without_geometry_opens_on_its_signals_and_pairs(rig) -> None:
    """A measured run (no bodies recorded) has no car to show: no 3D view, and no box to frame."""
    run, _ = rig
    n = len(run.t_s)
    bare = Run(run.path, run.t_s, run.signals, run.units, run.groups, run.specs, [], np.empty((n, 0, 3)),
               np.empty((n, 0, 4)), [], run.metadata, True, "")
    kinds = {v.class_identifier for v in _views(blueprint(bare).root_container)}
    assert kinds == {"TimeSeries", "2D"}
    with pytest.raises(ValueError, match="records no geometry"):
        car_bounds_m(bare)
