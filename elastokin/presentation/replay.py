"""Replay a recorded run in Rerun, offline, from the MCAP file alone.

Entities (all on the duration timeline ``sim_time``):

- ``car/<body>``: the body's world pose (Transform3D per step); its primitives are static children
  ``car/<body>/<kind>``, so they move with it.
- ``road/ground``, ``road/trajectory``, ``road/camera`` (road runs only): a ground plane under the
  whole drive, the path of the chassis frame's origin on it (a strip per case: each case starts
  again at the origin), and a pinhole behind the car that follows the chassis' position and heading;
  the 3D view's eye tracks it.
- ``signals/<group>/<signal>``: one Scalars series per signal, named ``"signal [unit]"``.
- ``pairs/<y>__vs__<x>``: a signal against another (camber against wheel travel, a bushing's force
  against its deflection): the whole curve as a static line (shown at every time), a frame around
  it labelled with each axis' range, and the current point, labelled with its values, moving along
  it. Coordinates are offsets from the centre of the pair's range; a 2D view has equal axes and y
  pointing down, so the entity carries a transform that scales each axis' range to 1 and flips y.
  Its view has ``pairs`` as origin: a view does not apply the transform of its own origin.

The layout opens on what the run is for: the whole car framed (on the rig from a fixed eye in front
and to the left of it, on the road from the follow camera), every loop over the whole recording,
and the signals against time with one plot per unit.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from elastokin.analysis.run_metrics import is_road
from elastokin.recordings.run_format import GeomSpec, Run, rotation_matrix

TIMELINE = "sim_time"
#: Vertical field of view of the 3D view's eye: Rerun's default, and the follow camera's.
FOV_Y_RAD = math.radians(55.0)
#: Width over height of the 3D view in this layout, rounded down (1.5 in a 1600 x 1000 window).
VIEW_ASPECT = 1.4
#: The car's box fills at most this fraction of the view's half-width and half-height.
FILL = 0.9
#: Where the eye looks from (azimuth from +x towards +y, elevation): on the rig from the front left,
#: where both axles' wheels and the body show; on the road from behind and to the right.
RIG_EYE_DEG = (40.0, 25.0)
ROAD_EYE_DEG = (200.0, 22.0)
#: The ground reaches this far beyond the drive on every side.
GROUND_MARGIN_M = 15.0
GROUND_COLOUR = (58, 62, 68)
TRAJECTORY_COLOUR = (255, 190, 40)
#: A pair view shows the curve's normalised [-0.5, 0.5] square with this margin on each side.
PAIR_MARGIN = 0.12
_UP = np.array([0.0, 0.0, 1.0])


def _log_geometry(rec: rr.RecordingStream, body: str, geoms: list[GeomSpec]) -> None:
    """Static primitives of one body, one archetype batch per kind."""
    for kind in sorted({g.kind for g in geoms}):
        batch = [g for g in geoms if g.kind == kind]
        quats = [rr.Quaternion(xyzw=[*g.quat_wxyz[1:], g.quat_wxyz[0]]) for g in batch]
        colors = np.array([g.rgba for g in batch], dtype=np.float32)
        sizes = np.array([g.size_m for g in batch])
        placed = {"centers": np.array([g.pos_m for g in batch]), "quaternions": quats, "colors": colors}
        if kind == "box":
            archetype = rr.Boxes3D(half_sizes=sizes, fill_mode="solid", **placed)
        elif kind in ("ellipsoid", "sphere"):
            half = sizes if kind == "ellipsoid" else np.repeat(sizes[:, :1], 3, axis=1)
            archetype = rr.Ellipsoids3D(half_sizes=half, fill_mode="solid", **placed)
        elif kind == "cylinder":
            archetype = rr.Cylinders3D(lengths=2 * sizes[:, 1], radii=sizes[:, 0], fill_mode="solid", **placed)
        else:  # capsule: Rerun's starts at its origin and runs along +z, MuJoCo's is centred
            starts = placed["centers"] - np.array([rotation_matrix(g.quat_wxyz)[:, 2] * g.size_m[1] for g in batch])
            archetype = rr.Capsules3D(
                lengths=2 * sizes[:, 1], radii=sizes[:, 0], translations=starts, quaternions=quats, colors=colors
            )
        rec.log(f"car/{body}/{kind}", archetype, static=True)


# -- framing the car ------------------------------------------------------------------------------
def _half_extents_m(g: GeomSpec) -> np.ndarray:
    """Half-sizes of the box that holds the primitive, in the primitive's own frame."""
    radius, half_length = g.size_m[0], g.size_m[1]
    if g.kind in ("box", "ellipsoid"):
        return np.array(g.size_m)
    if g.kind == "sphere":
        return np.full(3, radius)
    return np.array([radius, radius, half_length + (radius if g.kind == "capsule" else 0.0)])


def heading_rad(run: Run) -> np.ndarray:
    """(N,) heading of the chassis' x axis in the ground plane, from +x towards +y."""
    q = run.body_quat_wxyz[:, run.body_names.index("chassis")]
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.arctan2(2 * (x * y + w * z), w * w + x * x - y * y - z * z)


def _turns(angle_rad: np.ndarray | float) -> np.ndarray:
    """Rotations about z by ``angle_rad``: (3, 3), or (N, 3, 3) for N angles."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    zero, one = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, -s, zero], -1), np.stack([s, c, zero], -1), np.stack([zero, zero, one], -1)], -2)


def car_bounds_m(run: Run, sample: int = 0, *, chassis_frame: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) corners of the axis-aligned box around every recorded primitive at ``sample``, in
    the world or, with ``chassis_frame``, in the frame at the chassis origin turned by its heading."""
    if not run.geometry:
        raise ValueError(f"{run.path} records no geometry (a measured run): there is no car to frame")
    origin, turn = np.zeros(3), np.eye(3)
    if chassis_frame:
        origin = run.body_pos[sample, run.body_names.index("chassis")]
        turn = _turns(-heading_rad(run)[sample])
    index = {b: i for i, b in enumerate(run.body_names)}
    low, high = [], []
    for g in run.geometry:
        b = index[g.body]
        body_rot = turn @ rotation_matrix(run.body_quat_wxyz[sample, b])
        centre = turn @ (run.body_pos[sample, b] - origin) + body_rot @ np.array(g.pos_m)
        half = np.abs(body_rot @ rotation_matrix(g.quat_wxyz)) @ _half_extents_m(g)
        low.append(centre - half)
        high.append(centre + half)
    return np.min(low, axis=0), np.max(high, axis=0)


def _box_corners(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    return np.array([[(low, high)[i][0], (low, high)[j][1], (low, high)[k][2]]
                     for i in (0, 1) for j in (0, 1) for k in (0, 1)])


def eye_direction(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """Unit vector from the looked-at point to the eye."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


def view_axes(direction: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(right, up, forward) unit vectors of an eye looking against ``direction`` with +z up."""
    forward = -direction / np.linalg.norm(direction)
    right = np.cross(forward, _UP)
    right /= np.linalg.norm(right)
    return right, np.cross(right, forward), forward


def framing_distance_m(low: np.ndarray, high: np.ndarray, target: np.ndarray, direction: np.ndarray) -> float:
    """Distance from ``target`` along ``direction`` at which a perspective eye looking at ``target``
    (FOV_Y_RAD, VIEW_ASPECT) sees the box [low, high] within FILL of its half-width and half-height."""
    right, up, forward = view_axes(direction)
    corners = _box_corners(low, high) - target
    tan_y = FILL * math.tan(FOV_Y_RAD / 2)
    # a corner at depth d + c·forward must satisfy |c·right| <= tan_x * depth and |c·up| <= tan_y * depth
    ahead = -corners @ forward
    need = np.maximum(ahead + np.abs(corners @ right) / (VIEW_ASPECT * tan_y), ahead + np.abs(corners @ up) / tan_y)
    return float(need.max())


def framing_eye(low: np.ndarray, high: np.ndarray, azimuth_deg: float,
                elevation_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """(eye position, looked-at point): the box's centre seen from the given direction, framed."""
    target = (low + high) / 2
    direction = eye_direction(azimuth_deg, elevation_deg)
    return target + framing_distance_m(low, high, target, direction) * direction, target


def follow_camera(run: Run) -> tuple[np.ndarray, np.ndarray]:
    """(N, 3) positions and (N, 3, 3) orientations (columns right, down, forward: a pinhole's RDF)
    of the camera that follows the chassis: the framing eye of the car at the first sample, in the
    chassis' heading frame, carried along by the chassis' position and heading."""
    eye, target = framing_eye(*car_bounds_m(run, 0, chassis_frame=True), *ROAD_EYE_DEG)
    right, up, forward = view_axes(eye - target)
    local = np.column_stack([right, -up, forward])
    chassis = run.body_pos[:, run.body_names.index("chassis")]
    turns = _turns(heading_rad(run))
    return chassis + turns @ eye, turns @ local


# -- logging ---------------------------------------------------------------------------------------
def _pair_path(x: str, y: str) -> str:
    return f"pairs/{y}__vs__{x}"


def pair_span(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(centre, span) of the finite (x, y) samples, a span of 1 for a constant signal; None if none is finite."""
    finite = np.isfinite(x) & np.isfinite(y)
    if not finite.any():
        return None
    xy = np.column_stack([x, y])[finite]
    low, high = xy.min(axis=0), xy.max(axis=0)
    return (low + high) / 2, np.where(high > low, high - low, 1.0)


def _log_pair(rec: rr.RecordingStream, run: Run, x_name: str, y_name: str, time: list[rr.TimeColumn]) -> None:
    """The static curve, its frame and ranges, the moving current point, and the normalising transform.

    Coordinates are offsets from the centre of the pair's range: Rerun stores float32, which keeps
    a 3 µm change of a 745 mm half-track in 50 steps, and in 10^7 as an offset."""
    x, y = run.signals[x_name], run.signals[y_name]
    framing = pair_span(x, y)
    if framing is None:
        return
    centre, (sx, sy) = framing
    path = _pair_path(x_name, y_name)
    rec.log(path, rr.Transform3D(scale=[1.0 / sx, -1.0 / sy, 1.0]), static=True)
    xy = np.column_stack([x, y]) - centre
    finite = np.isfinite(xy).all(axis=1)
    rec.log(f"{path}/curve", rr.LineStrips2D([xy[finite]], radii=rr.Radius.ui_points(1.0)), static=True)
    half = np.array([sx, sy]) / 2
    frame = [(-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1)] * half
    rec.log(f"{path}/frame", rr.LineStrips2D([frame], radii=rr.Radius.ui_points(0.5), colors=[110, 110, 110]),
            static=True)
    units = run.units[x_name], run.units[y_name]
    low, high = centre - half, centre + half
    # each axis' range under and over the frame, short enough for a narrow panel; a label hangs
    # below its point, so both points sit at the top of their margin
    ranges = [f"{low[0]:.4g} … {high[0]:.4g} {units[0]}", f"{low[1]:.4g} … {high[1]:.4g} {units[1]}"]
    places = [(0.0, -half[1] - 0.01 * sy), (0.0, half[1] + (PAIR_MARGIN - 0.01) * sy)]
    rec.log(f"{path}/range", rr.Points2D(places, labels=ranges, radii=0.0, colors=[150, 150, 150]), static=True)
    labels = [f"{a:.4g} {units[0]}, {b:.4g} {units[1]}" for a, b in zip(x, y)]
    rec.send_columns(f"{path}/now", indexes=time, columns=rr.Points2D.columns(positions=xy, labels=labels))
    rec.log(f"{path}/now", rr.Points2D.from_fields(radii=rr.Radius.ui_points(5.0), colors=[230, 60, 30]), static=True)


def _case_strips(run: Run, xy: np.ndarray) -> list[np.ndarray]:
    """``xy`` cut where the recorded case changes (each case starts again from the origin)."""
    case = run.signals.get("case")
    if case is None:
        return [xy]
    cuts = np.flatnonzero(np.diff(case) != 0) + 1
    return [s for s in np.split(xy, cuts) if len(s) > 1]


def _log_road(rec: rr.RecordingStream, run: Run, time: list[rr.TimeColumn]) -> None:
    """The ground under the whole drive, the chassis' path on it and the follow camera."""
    path = run.body_pos[:, run.body_names.index("chassis"), :2]
    low, high = path.min(axis=0) - GROUND_MARGIN_M, path.max(axis=0) + GROUND_MARGIN_M
    # the road is z = 0: the ground's top sits just below it, so that the grid and the path show
    rec.log("road/ground", rr.Boxes3D(centers=[[*(low + high) / 2, -0.011]], half_sizes=[[*(high - low) / 2, 0.01]],
                                      colors=[GROUND_COLOUR], fill_mode="solid"), static=True)
    strips = [np.column_stack([s, np.full(len(s), 0.01)]) for s in _case_strips(run, path)]
    rec.log("road/trajectory", rr.LineStrips3D(strips, radii=rr.Radius.ui_points(2.0), colors=TRAJECTORY_COLOUR),
            static=True)
    position, orientation = follow_camera(run)
    # the eye takes the pinhole's pose and vertical field of view only: a frustum wider than any view,
    # drawn transparent and thin, keeps its outline out of the picture
    rec.log("road/camera", rr.Pinhole(fov_y=FOV_Y_RAD, aspect_ratio=4.0, color=[0, 0, 0, 0], line_width=0.0),
            static=True)
    rec.send_columns("road/camera", indexes=time,
                     columns=rr.Transform3D.columns(translation=position, mat3x3=orientation))


def log_run(rec: rr.RecordingStream, run: Run) -> None:
    """Log the whole run into ``rec``: poses, geometry, the road, every signal and every pair."""
    time = [rr.TimeColumn(TIMELINE, duration=run.t_s)]
    rec.log("/", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    for b, body in enumerate(run.body_names):
        quat_xyzw = np.concatenate([run.body_quat_wxyz[:, b, 1:], run.body_quat_wxyz[:, b, :1]], axis=1)
        columns = rr.Transform3D.columns(translation=run.body_pos[:, b], quaternion=quat_xyzw)
        rec.send_columns(f"car/{body}", indexes=time, columns=columns)
        geoms = [g for g in run.geometry if g.body == body]
        if geoms:
            _log_geometry(rec, body, geoms)
    if _follows(run):
        _log_road(rec, run, time)

    for spec in run.specs:
        path = f"signals/{spec.group}/{spec.name}"
        rec.log(path, rr.SeriesLines(names=run.label(spec.name)), static=True)
        rec.send_columns(path, indexes=time, columns=rr.Scalars.columns(scalars=run.signals[spec.name]))

    for x_name, y_name in run.pairs():
        _log_pair(rec, run, x_name, y_name, time)


# -- layout ----------------------------------------------------------------------------------------
def _follows(run: Run) -> bool:
    """Whether the run drives on the road with a recorded car to follow."""
    return is_road(run) and "chassis" in run.body_names and bool(run.geometry)


def car_view(run: Run) -> rrb.Spatial3DView:
    """The 3D view of a run with geometry: the car framed from the front left on the rig, through the
    follow camera on the road."""
    if _follows(run):
        eye = rrb.EyeControls3D(tracking_entity="road/camera")
    else:
        position, target = framing_eye(*car_bounds_m(run), *RIG_EYE_DEG)
        eye = rrb.EyeControls3D(position=position, look_target=target, eye_up=_UP)
    return rrb.Spatial3DView(origin="/", contents=["+ /car/**", "+ /road/**"], name="car", eye_controls=eye)


def time_series_views(run: Run) -> list[rrb.Grid]:
    """A grid per signal group, a time-series plot per unit in it (one scale for one quantity)."""
    grids = []
    for group in dict.fromkeys(s.group for s in run.specs):
        by_unit: dict[str, list[str]] = {}
        for s in run.specs:
            if s.group == group:
                by_unit.setdefault(s.unit, []).append(f"+ /signals/{group}/{s.name}")
        grids.append(rrb.Grid(*[rrb.TimeSeriesView(origin=f"signals/{group}", contents=c, name=f"{group} [{u}]")
                                for u, c in by_unit.items()], name=group))
    return grids


def pair_views(run: Run) -> dict[str, list[rrb.Spatial2DView]]:
    """The pair views by group of the y signal, each showing its pair's whole normalised curve."""
    side = 0.5 + PAIR_MARGIN
    bounds = rrb.VisualBounds2D(x_range=[-side, side], y_range=[-side, side])
    groups: dict[str, list[rrb.Spatial2DView]] = {}
    for x_name, y_name in run.pairs():
        if pair_span(run.signals[x_name], run.signals[y_name]) is None:
            continue
        view = rrb.Spatial2DView(origin="pairs", contents=f"+ /{_pair_path(x_name, y_name)}/**", visual_bounds=bounds,
                                 name=f"{run.label(y_name)} vs {run.label(x_name)}")
        groups.setdefault(run.groups[y_name], []).append(view)
    return groups


def blueprint(run: Run) -> rrb.Blueprint:
    """The 3D car (if recorded: not for a measured run) above the signals against time (a tab per
    group), beside the pairs (a tab per group)."""
    left: list[rrb.Container | rrb.View] = [car_view(run)] if run.geometry else []
    if run.specs:
        left.append(rrb.Tabs(*time_series_views(run)))
    columns: list[rrb.Container | rrb.View] = [rrb.Vertical(*left, row_shares=[3, 2] if len(left) == 2 else None)]
    if groups := pair_views(run):
        columns.append(rrb.Tabs(*[rrb.Grid(*views, name=f"{g} pairs") for g, views in groups.items()]))
    return rrb.Blueprint(rrb.Horizontal(*columns), collapse_panels=True)


def replay(run: Run, *, save: Path | None = None, spawn: bool = False) -> None:
    """Write the Rerun recording of ``run`` to ``save`` (.rrd) and/or show it in a spawned viewer."""
    rec = rr.RecordingStream("vsim", recording_id=run.path.stem)
    bp = blueprint(run)
    sinks: list[rr.FileSink | rr.GrpcSink] = []
    if save is not None:
        sinks.append(rr.FileSink(str(save)))
    if spawn:
        rr.spawn(connect=False)
        sinks.append(rr.GrpcSink())
    rec.set_sinks(*sinks, default_blueprint=bp)
    rec.send_recording_name(run.path.name if run.complete else f"{run.path.name} (INCOMPLETE: {run.reason})")
    log_run(rec, run)
    rec.flush()
    rec.disconnect()
