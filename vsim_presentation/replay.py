"""Replay a recorded run in Rerun, offline, from the MCAP file alone.

Entities (all on the duration timeline ``sim_time``):

- ``car/<body>``: the body's world pose (Transform3D per step); its primitives are static children
  ``car/<body>/<kind>``, so they move with it.
- ``signals/<group>/<signal>``: one Scalars series per signal, named ``"signal [unit]"``.
- ``pairs/<y>__vs__<x>``: a signal against another (camber against wheel travel, a bushing's force
  against its deflection): the whole curve as a static line and the current point moving along it.
  A 2D view has equal axes and y pointing down, so the entity carries a scale transform that
  normalises each axis to its range and flips y; the logged coordinates stay the signal values.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from vsim_analysis.run_metrics import is_road
from vsim_recordings.run_format import GeomSpec, Run, rotation_matrix

TIMELINE = "sim_time"


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


def _pair_path(x: str, y: str) -> str:
    return f"pairs/{y}__vs__{x}"


def log_run(rec: rr.RecordingStream, run: Run) -> None:
    """Log the whole run into ``rec``: poses, geometry, every signal and every pair."""
    time = [rr.TimeColumn(TIMELINE, duration=run.t_s)]
    rec.log("car", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    for b, body in enumerate(run.body_names):
        quat_xyzw = np.concatenate([run.body_quat_wxyz[:, b, 1:], run.body_quat_wxyz[:, b, :1]], axis=1)
        columns = rr.Transform3D.columns(translation=run.body_pos[:, b], quaternion=quat_xyzw)
        rec.send_columns(f"car/{body}", indexes=time, columns=columns)
        geoms = [g for g in run.geometry if g.body == body]
        if geoms:
            _log_geometry(rec, body, geoms)

    for spec in run.specs:
        path = f"signals/{spec.group}/{spec.name}"
        rec.log(path, rr.SeriesLines(names=run.label(spec.name)), static=True)
        rec.send_columns(path, indexes=time, columns=rr.Scalars.columns(scalars=run.signals[spec.name]))

    for x_name, y_name in run.pairs():
        x, y = run.signals[x_name], run.signals[y_name]
        finite = np.isfinite(x) & np.isfinite(y)
        if not finite.any():
            continue
        span = [float(np.ptp(v[finite])) or 1.0 for v in (x, y)]
        path = _pair_path(x_name, y_name)
        rec.log(path, rr.Transform3D(scale=[1.0 / span[0], -1.0 / span[1], 1.0]), static=True)
        curve = rr.LineStrips2D([np.column_stack([x, y])[finite]], radii=rr.Radius.ui_points(1.0))
        rec.log(f"{path}/curve", curve, static=True)
        labels = [f"{run.label(x_name)} = {a:.4g}, {run.label(y_name)} = {b:.4g}" for a, b in zip(x, y)]
        rec.send_columns(
            f"{path}/now",
            indexes=time,
            columns=rr.Points2D.columns(positions=np.column_stack([x, y]), labels=labels),
        )
        marker = rr.Points2D.from_fields(radii=rr.Radius.ui_points(5.0), colors=[230, 60, 30])
        rec.log(f"{path}/now", marker, static=True)


def blueprint(run: Run) -> rrb.Blueprint:
    """3D car | time series (a tab per signal group) | signal pairs (a grid per group of the y signal)."""
    groups = list(dict.fromkeys(s.group for s in run.specs))
    series = [rrb.TimeSeriesView(origin=f"signals/{g}", name=g) for g in groups]
    pair_groups: dict[str, list[rrb.Spatial2DView]] = {}
    for x_name, y_name in run.pairs():
        view = rrb.Spatial2DView(origin=_pair_path(x_name, y_name), name=f"{run.label(y_name)} vs {run.label(x_name)}")
        pair_groups.setdefault(run.groups[y_name], []).append(view)
    # on the road the car leaves the scene's first frame: the eye follows the body, behind and above it
    eye = (rrb.EyeControls3D(tracking_entity="car/chassis", position=[-8.0, -6.0, 4.0], look_target=[-1.3, 0.0, 0.4])
           if is_road(run) and "chassis" in run.body_names else None)
    columns: list[rrb.Container | rrb.View] = [rrb.Spatial3DView(origin="car", name="car", eye_controls=eye)]
    if series:
        columns.append(rrb.Tabs(*series))
    if pair_groups:
        columns.append(rrb.Tabs(*[rrb.Grid(*views, name=f"{g} pairs") for g, views in pair_groups.items()]))
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
