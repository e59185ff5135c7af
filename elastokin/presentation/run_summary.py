"""The text summary of a recorded run (`vsim run`): on the road, the ISO 7401 / 4138 metrics of each
case (:mod:`elastokin.analysis.road_metrics`); on the rig, the centre-line gradients and loop widths of
camber, toe and half-track on each case's last cycle and the named K&C metrics of `vsim kc` per case
and axle (periodic inputs, :mod:`elastokin.analysis.run_metrics`), the toe drift over the final hold
(rack steps), the peak deflection of every bushing during the inputs, and the bushing steps whose
solve did not converge, if any."""

from __future__ import annotations


import numpy as np

from elastokin.analysis.kc_metrics import BUMP_WINDOW_M, FIT_FRACTION, METRICS
from elastokin.analysis.road_metrics import METRICS as ROAD_METRICS
from elastokin.analysis.road_metrics import RESPONSES, bandwidth_hz, road_metrics
from elastokin.analysis.run_metrics import (case_loop, case_mask, case_relaxation, cases, gradient_unit, input_phase, is_road,
                                       loop_axes, run_metrics)
from elastokin.recordings.run_format import Run
from elastokin.vehicle.simulation.unconverged import headline, worst_first

SUMMARY_CORNERS = {"front": "fl", "rear": "rl"}   #: the left wheel of each axle is summarised
_DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")


def _loop_table(run: Run) -> list[str]:
    extra = run.metadata.extra
    travel = extra["x_quantity"] == "wheel_travel"
    quantities = ("camber", "toe", "half_track")
    x_unit = run.units[loop_axes(run, "fl")[0]]
    units = {q: (run.units[f"{q}_fl"], gradient_unit(run.units[f"{q}_fl"], x_unit)) for q in quantities}
    window = f"±{FIT_FRACTION:.0%} of the range"
    rows = [f"last cycle, left wheels: gradient = centre-line slope at {'design height' if travel else 'zero load'} "
            f"(over {f'±{BUMP_WINDOW_M * 1e3:g} mm or ' if travel else ''}{window}{', the smaller' if travel else ''}); "
            f"loop = loop width there (largest over {window})",
            f"  {'case':<24} {'wheel':<5}" + "".join(f" {f'{q} [{per}]':>20} {f'loop [{u}]':>18}"
                                                      for q, (u, (_, per)) in units.items())]
    for case in cases(run):
        for axle in extra["axles"]:
            tag = SUMMARY_CORNERS[axle]
            x, driver = loop_axes(run, tag)
            loops = [case_loop(run, case, x, f"{q}_{tag}", driver) for q in quantities]
            if None in loops:
                continue  # an incomplete run did not reach this case's last cycle
            cells = [f" {scale * loop.gradient:20.4f} {f'{loop.width:.4f} ({loop.width_max:.4f})':>18}"
                     for loop, (_, (scale, _)) in zip(loops, units.values())]
            rows.append(f"  {case['label'][:24]:<24} {tag:<5}" + "".join(cells))
    if any(case["cycles"] == 1 for case in cases(run)):
        rows.append("  (a case of one cycle has the virgin first loading, 0 to +A, in its loading branch)")
    return rows


def _kc_table(run: Run, radius_m: float | None) -> list[str]:
    metrics = run_metrics(run, radius_m=radius_m)
    labels = {case["case"]: case["label"][:16] for case in cases(run)}
    keys = [(key, unit) for key, unit, _ in METRICS if any(key in m for c in metrics.values() for m in c.values())]
    if not keys:
        return []
    rows = ["K&C metrics from the recorded signals (definitions and signs of `vsim kc`, last cycle of each case):",
            f"  {'metric':<46} {'unit':<9} {'axle':<6}" + "".join(f" {labels[k]:>16}" for k in metrics)]
    for key, unit in keys:
        for axle in run.metadata.extra["axles"]:
            cells = [f" {metrics[k][axle][key]:16.5g}" if key in metrics[k].get(axle, {}) else f" {'-':>16}"
                     for k in metrics]
            rows.append(f"  {key:<46} {unit:<9} {axle:<6}" + "".join(cells))
    return rows


def _drift_table(run: Run) -> list[str]:
    rows = ["toe over the final hold (relaxation), front wheels [deg]:",
            f"  {'case':<28} {'wheel':<5} {'hold start':>11} {'end':>11} {'drift':>11}"]
    for case in cases(run):
        for tag in ("fl", "fr"):
            drift = case_relaxation(run, case, f"toe_{tag}")
            if drift is not None:
                end = run.signals[f"toe_{tag}"][case_mask(run, case)][-1]
                rows.append(f"  {case['label'][:28]:<28} {tag:<5} {end - drift:11.4f} {end:11.4f} {drift:11.4f}")
    return rows


def _road_table(run: Run) -> list[str]:
    metrics = road_metrics(run)
    if not metrics:
        return ["road metrics: no case finished"]
    labels = {case["case"]: case["label"][:16] for case in cases(run)}
    known = [(k, unit) for k, unit, _ in ROAD_METRICS] + [(f"second_{k}", unit) for k, unit, _ in ROAD_METRICS]
    rows = ["road metrics (ISO 7401 / ISO 4138 definitions; `elastokin.analysis.road_metrics`):",
            f"  {'metric':<54} {'unit':<9}" + "".join(f" {labels[k]:>16}" for k in metrics)]
    for key, unit in known:
        if any(key in m for m in metrics.values()):
            rows.append(f"  {key:<54} {unit:<9}" + "".join(f" {m[key]:16.5g}" if key in m else f" {'-':>16}"
                                                           for m in metrics.values()))
    sines = [c["parameters"] for c in cases(run)]
    if run.metadata.extra["type"] == "sine_steer":
        if len({(p["speed_kmh"], p["amplitude_deg"]) for p in sines}) > 1:
            rows.append("  bandwidth: none (the cases differ in speed or amplitude)")
            return rows
        for response in RESPONSES:
            f = bandwidth_hz(metrics, response)
            where = ("beyond the frequencies run" if f is None else "below the lowest frequency run" if f == 0.0
                     else f"{f:.3f} Hz")
            rows.append(f"  {response} bandwidth (45 deg phase lag): {where}")
    return rows


def _peak_table(run: Run) -> list[str]:
    inputs = run.signals["phase"] == input_phase(run)
    bushings = sorted({s.group.removeprefix("bushing_") for s in run.specs if s.group.startswith("bushing_")})
    rows = ["peak bushing deflections during the inputs (|x|, |y|, |z| [mm]; |rx|, |ry|, |rz| [deg]):",
            f"  {'bushing':<20}" + "".join(f"{d:>8}" for d in _DIRECTIONS)]
    for b in bushings:
        peaks = [np.abs(run.signals[f"{b}_{d}_deflection"][inputs]).max(initial=0.0) for d in _DIRECTIONS]
        rows.append(f"  {b:<20}" + "".join(f"{v:8.3f}" for v in peaks))
    return rows


def summary(run: Run, radius_m: float | None = None) -> str:
    """The text summary of a recorded run (simulated, or measured on a rig: its roll and roll-centre
    metrics need the measured car's tyre radius ``radius_m`` [m], which a simulated run carries)."""
    extra = run.metadata.extra
    status = "complete" if run.complete else f"INCOMPLETE ({run.reason})"
    origin = f"bushings: {extra['bushing_model']}" if "bushing_model" in extra else "measured on a rig"
    lines = [f"{extra['scenario']} ({extra['type']}, {origin}): "
             f"{len(extra['cases'])} case(s), {run.t_s[-1] if run.t_s.size else 0.0:.1f} s recorded, {status}"]
    if extra["duration_scale"] != 1.0:
        lines.append(f"durations scaled by {extra['duration_scale']:g}: rates differ from the scenario's, "
                     f"and so do rate-dependent loops")
    if run.unconverged:
        lines += [f"WARNING: {headline(run.unconverged)}:"] + [f"  {s.describe()}" for s in worst_first(run.unconverged)]
    if is_road(run):
        lines += _road_table(run)
    elif extra["x_quantity"] is not None:
        lines += _loop_table(run) + _kc_table(run, radius_m)
    else:
        lines += _drift_table(run)
    return "\n".join(lines + _peak_table(run))
