"""`vsim run SCENARIO.yaml`: run a scenario on the K&C rig with a progress bar, record it, summarise it.

The summary is computed from the recorded file (so it also describes an incomplete run) by
:mod:`vsim_analysis.run_metrics`: the centre-line gradients and loop widths of camber, toe and half-track
on each case's last cycle and the named K&C metrics of `vsim kc` per case and axle (periodic
inputs, with :mod:`vehicle.simulation.kc`'s definitions), the toe drift over the final hold (rack steps), and
the peak deflection of every bushing during the inputs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import TextIO

import numpy as np

from vsim_cli.model import BUSHING_MODELS

SUMMARY_CORNERS = {"front": "fl", "rear": "rl"}   #: the left wheel of each axle is summarised
_DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")


class ProgressBar:
    """A progress line on ``stream``: rewritten in place on a terminal (at most every
    ``interval_s``), else one line per case and phase."""

    def __init__(self, stream: TextIO | None = None, interval_s: float = 0.2, width: int = 30):
        self.stream = stream if stream is not None else sys.stderr
        self.interval_s, self.width = interval_s, width
        self.live = self.stream.isatty()
        from vehicle.simulation.runner import PHASES  # here, so that `vsim --help` does not load the runner

        self.phases = PHASES
        self.started = time.perf_counter()
        self.shown_at = -1.0
        self.last_stage = None
        self.dirty = False

    def __call__(self, p) -> None:
        """Show a :class:`vehicle.simulation.runner.Progress`."""
        now = time.perf_counter()
        stage = (p.case, p.phase)
        if not self.live:
            if stage != self.last_stage:
                print(f"case {p.case}/{p.cases} {p.label}: {self.phases[p.phase]}", file=self.stream, flush=True)
            self.last_stage = stage
            return
        if now - self.shown_at < self.interval_s and stage == self.last_stage:
            return
        self.shown_at, self.last_stage, self.dirty = now, stage, True
        fraction = min(1.0, p.done_s / p.total_s) if p.total_s > 0 else 1.0
        filled = int(round(fraction * self.width))
        elapsed = now - self.started
        remaining = f"~{elapsed * (1.0 - fraction) / fraction:.0f} s" if fraction > 0.01 else "?"
        line = (f"\r[{'#' * filled}{'.' * (self.width - filled)}] {100 * fraction:3.0f}%  "
                f"case {p.case}/{p.cases} {p.label} ({self.phases[p.phase]})  "
                f"sim {p.done_s:.1f}/{p.total_s:.1f} s  wall {elapsed:.0f} s, {remaining} left")
        self.stream.write(line + "\x1b[K")
        self.stream.flush()

    def close(self) -> None:
        """End the progress line."""
        if self.dirty:
            self.stream.write("\n")
            self.stream.flush()
            self.dirty = False


def _loop_table(run) -> list[str]:
    from vsim_analysis.run_metrics import BUMP_WINDOW_M, FIT_FRACTION, case_loop, cases, gradient_unit, loop_axes

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


def _kc_table(run) -> list[str]:
    from vehicle.simulation.kc import METRICS
    from vsim_analysis.run_metrics import cases, run_metrics

    metrics = run_metrics(run)
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


def _drift_table(run) -> list[str]:
    from vsim_analysis.run_metrics import case_mask, case_relaxation, cases

    rows = ["toe over the final hold (relaxation), front wheels [deg]:",
            f"  {'case':<28} {'wheel':<5} {'hold start':>11} {'end':>11} {'drift':>11}"]
    for case in cases(run):
        for tag in ("fl", "fr"):
            drift = case_relaxation(run, case, f"toe_{tag}")
            if drift is not None:
                end = run.signals[f"toe_{tag}"][case_mask(run, case)][-1]
                rows.append(f"  {case['label'][:28]:<28} {tag:<5} {end - drift:11.4f} {end:11.4f} {drift:11.4f}")
    return rows


def _peak_table(run) -> list[str]:
    inputs = run.signals["phase"] == 2
    bushings = sorted({s.group.removeprefix("bushing_") for s in run.specs if s.group.startswith("bushing_")})
    rows = ["peak bushing deflections during the inputs (|x|, |y|, |z| [mm]; |rx|, |ry|, |rz| [deg]):",
            f"  {'bushing':<20}" + "".join(f"{d:>8}" for d in _DIRECTIONS)]
    for b in bushings:
        peaks = [np.abs(run.signals[f"{b}_{d}_deflection"][inputs]).max(initial=0.0) for d in _DIRECTIONS]
        rows.append(f"  {b:<20}" + "".join(f"{v:8.3f}" for v in peaks))
    return rows


def summary(run) -> str:
    """The text summary of a recorded run (:class:`vsim_recordings.run_reader.Run` written by the runner)."""
    extra = run.metadata.extra
    status = "complete" if run.complete else f"INCOMPLETE ({run.reason})"
    origin = f"bushings: {extra['bushing_model']}" if "bushing_model" in extra else "measured on a rig"
    lines = [f"{extra['scenario']} ({extra['type']}, {origin}): "
             f"{len(extra['cases'])} case(s), {run.t_s[-1] if run.t_s.size else 0.0:.1f} s recorded, {status}"]
    if extra["duration_scale"] != 1.0:
        lines.append(f"durations scaled by {extra['duration_scale']:g}: rates differ from the scenario's, "
                     f"and so do rate-dependent loops")
    if extra["x_quantity"] is not None:
        lines += _loop_table(run) + _kc_table(run)
    else:
        lines += _drift_table(run)
    return "\n".join(lines + _peak_table(run))


def _run(args: argparse.Namespace) -> int:
    from vsim_recordings.run_reader import load_run
    from vehicle.simulation.runner import DivergenceError, default_output, run_scenario
    from vehicle.scenarios.scenario_file import load_scenario

    scenario = load_scenario(args.scenario)
    output = args.output or default_output(scenario)
    bar = ProgressBar()
    status, note = 0, ""
    started = time.perf_counter()
    try:
        result = run_scenario(scenario, output, bushing_model=args.bushings, overwrite=args.overwrite,
                              duration_scale=args.duration_scale, progress=bar)
        note = f"({result.simulated_s:.1f} s simulated in {result.wall_s:.1f} s, " \
               f"{result.simulated_s / result.wall_s:.1f}x real time)"
    except DivergenceError as exc:
        status, note = 1, f"stopped: {exc}"
    except KeyboardInterrupt:
        status, note = 130, f"interrupted after {time.perf_counter() - started:.0f} s"
    finally:
        bar.close()
    if status:
        kept = f"the incomplete recording is kept in {output}" if output.exists() else "nothing was recorded"
        print(f"vsim: run {note}; {kept}", file=sys.stderr)
    if output.exists():
        print(summary(load_run(output)))
        print(f"wrote {output} {note if not status else '(incomplete)'}")
    return status


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``run`` sub-command."""
    run = subparsers.add_parser(
        "run", help="run a scenario (.yaml) on the K&C rig and record it (.mcap)",
        description="Run every case of a scenario file (format: scenarios/README.md) and record them in one "
                    "MCAP file; print a summary (gradients and loop widths, K&C metrics, relaxation, peak bushing "
                    "deflections).")
    run.add_argument("scenario", type=Path, metavar="SCENARIO.yaml")
    run.add_argument("-o", "--output", type=Path, metavar="OUT.mcap", help="run file (default: out/<scenario>.mcap)")
    run.add_argument("--bushings", choices=BUSHING_MODELS, default=None,
                     help="this bushing model on every bushing direction (overrides the scenario's `bushings`)")
    run.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    run.add_argument("--duration-scale", type=float, default=1.0, metavar="X",
                     help="multiply every duration (settle phases, periods, holds) by X, e.g. 0.1 for a quick run")
    run.set_defaults(func=_run)
