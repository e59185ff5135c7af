"""PNG pictures of a recorded run: signal pairs, bushing force-deflection loops, time histories."""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from elastokin.presentation.figures import save_figure
from elastokin.recordings.run_format import Run

PAIR_PANEL_IN = (4.5, 3.4)
TIME_PANEL_IN = (10.0, 3.2)


def _grid(n: int, columns: int, panel_in: tuple[float, float]) -> tuple[Figure, list[Axes]]:
    """A figure with ``n`` panels of ``panel_in`` inches, ``columns`` wide (not pyplot's: it is
    freed with its last reference, in a notebook as in a batch)."""
    cols = min(n, columns)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(panel_in[0] * cols, panel_in[1] * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:n])


def _title(run: Run, what: str) -> str:
    status = "" if run.complete else f" (INCOMPLETE: {run.reason})"
    return f"{run.path.name}: {what}{status}"


def pair_figures(run: Run) -> Iterator[tuple[str, Figure]]:
    """One figure per group of the y signal, a panel per (x, y) pair; a dot marks the start; each with
    the file name :func:`plot_run` gives it (``loops_bushing_e2_front_left``, ``pairs_camber``)."""
    by_group: dict[tuple[str, str], list[tuple[str, str]]] = {}
    for x, y in run.pairs():
        kind = "loops" if y.endswith("_force") and x.endswith("_deflection") else "pairs"
        by_group.setdefault((kind, run.groups[y]), []).append((x, y))
    for (kind, group), pairs in by_group.items():
        fig, axes = _grid(len(pairs), 3, PAIR_PANEL_IN)
        for ax, (x, y) in zip(axes, pairs):
            ax.plot(run.signals[x], run.signals[y], lw=0.9)
            ax.plot(run.signals[x][:1], run.signals[y][:1], "o", ms=4, color="k")
            ax.set_xlabel(run.label(x))
            ax.set_ylabel(run.label(y))
            ax.grid(True, alpha=0.3)
        what = "force-deflection loops" if kind == "loops" else "signal pairs"
        fig.suptitle(_title(run, f"{group}, {what}"))
        yield f"{kind}_{group}", fig


def time_figures(run: Run, *, log_time: bool = False, t0_s: float = 0.0) -> Iterator[tuple[str, Figure]]:
    """One figure per signal group, a panel per unit; ``log_time`` plots against log10(t - t0).
    Each with the file name :func:`plot_run` gives it (``time_camber``, ``time_camber_logt``)."""
    t = run.t_s - t0_s
    shown = t > 0 if log_time else np.ones_like(t, dtype=bool)
    groups = list(dict.fromkeys(s.group for s in run.specs))
    for group in groups:
        names = [s.name for s in run.specs if s.group == group]
        units = list(dict.fromkeys(run.units[n] for n in names))
        fig, axes = _grid(len(units), 1, TIME_PANEL_IN)
        for ax, unit in zip(axes, units):
            for n in names:
                if run.units[n] == unit:
                    ax.plot(t[shown], run.signals[n][shown], lw=0.9, label=n)
            ax.set_ylabel(unit)
            ax.set_xlabel(f"t - {t0_s:g} s [s]" if t0_s else "t [s]")
            if log_time:
                ax.set_xscale("log")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize="small", ncols=max(1, len(names) // 8))
        fig.suptitle(_title(run, f"{group} against time"))
        yield f"time_{group}{'_logt' if log_time else ''}", fig


def plot_run(run: Run, out_dir: Path, *, log_time: bool = False, t0_s: float = 0.0) -> list[Path]:
    """Every picture of ``run`` into ``out_dir`` (created) as PNGs, one figure made at a time; returns
    the files written."""
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for name, fig in itertools.chain(pair_figures(run), time_figures(run, log_time=log_time, t0_s=t0_s)):
        save_figure(fig, out_dir / f"{name}.png", dpi=110)
        written.append(out_dir / f"{name}.png")
    return written
