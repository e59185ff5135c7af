"""The K&C metrics of `vsim kc` as a text table with units and sign conventions."""

from __future__ import annotations

from elastokin.analysis.kc_metrics import METRICS


def format_table(metrics: dict[str, dict[str, float]]) -> str:
    """The metrics as an aligned text table with units and sign conventions; an axle without a
    metric (the rear's steering) shows a dash."""
    cell = lambda axle, key: f"{metrics[axle][key]:>9.4f}" if key in metrics[axle] else f"{'-':>9}"
    rows = [f"{'metric':<46} {'unit':<9} {'front':>9} {'rear':>9}  convention"]
    for key, unit, convention in METRICS:
        rows.append(f"{key:<46} {unit:<9} {cell('front', key)} {cell('rear', key)}  {convention}")
    return "\n".join(rows)
