"""The report of road runs side by side (:mod:`elastokin.analysis.road_comparison`): a text table of
every case's metrics per car with the differences from the first (the linear car, or the
measurement), a CSV of the same rows, the overlay figures; and for a simulated run against a
measured one, the responses' RMS errors."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Mapping, Sequence

from elastokin.analysis.road_comparison import Variant, differences, is_time
from elastokin.core.files import atomic_output
from elastokin.presentation.road_figures import overlay_variants

#: Metrics the text table shows (the CSV has them all).
TABLE_METRICS = ("yaw_rate_response_time_s", "yaw_rate_peak_response_time_s", "yaw_rate_overshoot_pct",
                 "yaw_rate_gain_per_s", "lateral_acceleration_response_time_s", "steady_lateral_acceleration_mps2",
                 "steady_front_toe_deg", "front_toe_lag_s", "second_yaw_rate_response_time_s",
                 "second_front_toe_lag_s", "yaw_rate_phase_deg", "lateral_acceleration_phase_deg",
                 "understeer_gradient_deg_per_g", "roll_gradient_deg_per_g")


def format_table(variants: Sequence[Variant]) -> str:
    """Per case, the metrics of :data:`TABLE_METRICS` of each car, and each car's difference from
    the first (times in ms)."""
    rows = differences(variants)
    labels = [v.label for v in variants]
    lines = [f"{'case':<14} {'metric':<40}" + "".join(f" {label[:24]:>24}" for label in labels)]
    seen = list(dict.fromkeys((r["case"], r["metric"]) for r in rows if r["metric"] in TABLE_METRICS))
    for case, metric in seen:
        cells = {r["variant"]: r for r in rows if r["case"] == case and r["metric"] == metric}
        values = []
        for label in labels:
            r = cells[label]
            delta = r["difference_ms"] if is_time(metric) else r["difference"]
            unit = " ms" if is_time(metric) else ""
            values.append(f"{r['value']:.4g}" + ("" if label == labels[0] or math.isnan(delta)
                                                   else f" ({delta:+.3g}{unit})"))
        lines.append(f"{case[:14]:<14} {metric:<40}" + "".join(f" {v:>24}" for v in values))
    return "\n".join(lines)


def format_errors(rows: Sequence[Mapping[str, object]]) -> str:
    """The RMS errors of :func:`elastokin.analysis.road_comparison.response_errors`, a line each."""
    lines = [f"{'case':<14} {'response':<28} {'RMS error':>12}"]
    lines += [f"{str(r['case'])[:14]:<14} {r['signal']:<28} {r['rms_error']:>12.4g} {r['unit']}" for r in rows]
    return "\n".join(lines)


def _write_rows(path: Path, rows: Sequence[Mapping[str, object]]) -> Path:
    with atomic_output(path) as tmp, open(tmp, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]) if rows else [])
        writer.writeheader()
        writer.writerows(rows)
    return path


def write_report(variants: Sequence[Variant], out_dir: Path,
                 errors: Sequence[Mapping[str, object]] = ()) -> list[Path]:
    """``out_dir/metrics.csv`` (every row of :func:`differences`), ``out_dir/errors.csv`` when
    ``errors`` are given, and the overlay PNGs."""
    out_dir.mkdir(parents=True, exist_ok=True)
    written = [_write_rows(out_dir / "metrics.csv", differences(variants))]
    if errors:
        written.append(_write_rows(out_dir / "errors.csv", errors))
    return [*written, *overlay_variants(variants, out_dir)]
