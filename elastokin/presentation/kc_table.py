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


def format_comparison(comparison: dict[str, dict[str, dict[str, float]]]) -> str:
    """:meth:`elastokin.api.vehicles.Vehicle.compare_kc`'s metrics as a text table: per axle and
    metric, the simulated value, the rig's and their difference (rig − sim), in :data:`METRICS`'s order."""
    rows = [f"{'metric':<46} {'unit':<9} {'axle':<6} {'sim':>10} {'rig':>10} {'rig - sim':>10}"]
    for key, unit, _ in METRICS:
        for axle, metrics in comparison.items():
            if key in metrics:
                m = metrics[key]
                rows.append(f"{key:<46} {unit:<9} {axle:<6} {m['sim']:>10.4f} {m['rig']:>10.4f} {m['difference']:>10.4f}")
    return "\n".join(rows)
