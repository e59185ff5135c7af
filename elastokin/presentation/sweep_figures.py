"""Figures of a sweep: each metric column against each parameter, one PNG per metric column (the
runs that failed or gave no value for it left out)."""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Mapping, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from elastokin.presentation.figures import save_figure  # noqa: E402


def metric_plots(rows: Sequence[Mapping[str, str]], parameters: Sequence[str], metrics: Sequence[str],
                 out_dir: Path) -> list[Path]:
    """``out_dir/<metric column>.png`` for each of ``metrics``: one panel per parameter, one point
    per run of the table ``rows`` (cells as the table holds them)."""
    written = []
    for metric in metrics:
        pairs = [(r, float(r[metric])) for r in rows if not r["failed"] and math.isfinite(float(r[metric]))]
        fig, axes = plt.subplots(1, len(parameters), figsize=(3.6 * len(parameters), 3.2), squeeze=False,
                                 constrained_layout=True)
        for ax, place in zip(axes[0], parameters):
            ax.plot([float(r[place]) for r, _ in pairs], [v for _, v in pairs], "o", ms=4, alpha=0.7)
            ax.set_xlabel(place)
            ax.grid(alpha=0.3)
        axes[0][0].set_ylabel(metric)
        fig.suptitle(f"{metric}: {len(pairs)} of {len(rows)} runs")
        written.append(save_figure(fig, out_dir / f"{re.sub(r'[^A-Za-z0-9_.-]', '_', metric)}.png"))
        plt.close(fig)
    return written
