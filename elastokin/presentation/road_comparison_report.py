"""The report of what the bushings do on the road (:mod:`elastokin.analysis.road_comparison`): a text
table of every case's metrics per car with the differences from the linear car, a CSV of the same
rows, and the overlay figures."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Sequence

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


def write_report(variants: Sequence[Variant], out_dir: Path) -> list[Path]:
    """``out_dir/metrics.csv`` (every row of :func:`differences`) and the overlay PNGs."""
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / "metrics.csv"
    rows = differences(variants)
    with atomic_output(path) as tmp, open(tmp, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return [path, *overlay_variants(variants, out_dir)]
