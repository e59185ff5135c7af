"""Pictures of bench results (matplotlib, no display needed): loops, time histories, sweep maps."""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np
from matplotlib.figure import Figure

from elastokin.bushings.bench.bench_file import Bench
from elastokin.bushings.frequency import equivalent_damping
from elastokin.bushings.parameters import ChannelParams
from elastokin.core.units import MM
from elastokin.presentation.figures import save_figure


def _save(fig: Figure, path: Path) -> Path:
    fig.tight_layout()
    return save_figure(fig, path)


def plot_time_series(columns: Mapping[str, np.ndarray], kind: str, out_dir: Path, stem: str) -> list[Path]:
    """Force–displacement loop and force/displacement against time (log time for a step, from
    its first sample on) for a ``t_s, e_mm, F_N`` table; returns the PNG paths."""
    t, e, force = columns["t_s"], columns["e_mm"], columns["F_N"]
    loop = Figure(figsize=(6, 5))
    ax = loop.subplots()
    ax.plot(e, force, lw=0.8)
    ax.set(xlabel="deflection e [mm]", ylabel="force F [N]", title=f"{stem}: force–deflection ({kind})")
    ax.grid(True, alpha=0.3)
    history = Figure(figsize=(8, 6))
    ax_e, ax_f = history.subplots(2, 1, sharex=True)
    keep = t > t[0] if kind == "step" else np.ones_like(t, dtype=bool)
    for ax, y, label in ((ax_e, e, "deflection e [mm]"), (ax_f, force, "force F [N]")):
        ax.plot(t[keep], y[keep], lw=0.8)
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        if kind == "step":
            ax.set_xscale("log")
    ax_e.set_title(f"{stem}: {kind} programme")
    ax_f.set_xlabel("time t [s]" + (" (log)" if kind == "step" else ""))
    return [_save(loop, out_dir / f"{stem}_loop.png"), _save(history, out_dir / f"{stem}_time.png")]


def plot_sweep(columns: Mapping[str, np.ndarray], channel: ChannelParams, out_dir: Path, stem: str) -> list[Path]:
    """|K*| and tan δ against amplitude (one line per frequency) and against frequency (one line per
    amplitude) from a sweep table; for ladder models the equivalent-damping approximation (spec
    5.16/5.17) is drawn dashed over the time-domain reference. Returns the PNG path."""
    amplitude, frequency = columns["amplitude_mm"], columns["frequency_hz"]
    amps, freqs = np.unique(amplitude), np.unique(frequency)
    shape = (len(amps), len(freqs))  # the sweep table is amplitude-major
    k_time = columns["k_dyn_n_per_mm"].reshape(shape)
    tan_time = columns["tan_delta"].reshape(shape)
    approx = None if channel.continuous else equivalent_damping(channel, amplitude.reshape(shape) * MM,
                                                                frequency.reshape(shape))
    panels = ((k_time, None if approx is None else approx.k_dyn_n_per_m * MM, "|K*| [N/mm]"),
              (tan_time, None if approx is None else approx.tan_delta, "tan δ"))
    fig = Figure(figsize=(11, 8))
    axes = fig.subplots(2, 2)
    for row, (reference, estimate, ylabel) in enumerate(panels):
        # left: against amplitude, one line per frequency; right: the transpose
        for col, (x, lines, unit, xlabel) in enumerate(((amps, freqs, "Hz", "amplitude [mm]"),
                                                        (freqs, amps, "mm", "frequency [Hz]"))):
            ax = axes[row, col]
            for j, value in enumerate(lines):
                pick = (slice(None), j) if col == 0 else (j, slice(None))
                (line,) = ax.plot(x, reference[pick], marker="o", ms=3, label=f"{value:g} {unit}")
                if estimate is not None:
                    ax.plot(x, estimate[pick], ls="--", color=line.get_color())
            ax.set(xscale="log", xlabel=xlabel, ylabel=ylabel)
            ax.grid(True, which="both", alpha=0.3)
            if row == 0:
                ax.legend(fontsize=7, ncol=2)
    note = "solid: time-domain first harmonic; dashed: equivalent damping (Bourgeteau 2009, eqs. 5.16-5.17)" if approx is not None \
        else "time-domain first harmonic"
    fig.suptitle(f"{stem}: dynamic stiffness and loss factor ({channel.model}); {note}", fontsize=10)
    return [_save(fig, out_dir / f"{stem}_sweep.png")]


def plot_bench(bench: Bench, columns: Mapping[str, np.ndarray], out_dir: Path, stem: str) -> list[Path]:
    """The pictures of a bench run (:func:`elastokin.bushings.bench.bench_file.run_bench`'s ``columns``): a sweep's
    maps, or a time series' loop and histories. Returns the PNG paths."""
    if bench.programme.kind == "sweep":
        return plot_sweep(columns, bench.channel, out_dir, stem)
    return plot_time_series(columns, bench.programme.kind, out_dir, stem)
