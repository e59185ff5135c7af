"""A comparison of a simulated run with a measured one (:mod:`elastokin.analysis.compare`) as people read
it: a text table, ``comparison.json``, and loop and time-history overlays (PNG)."""

from __future__ import annotations

import json
from pathlib import Path

from matplotlib.figure import Figure

from elastokin.vehicle.scenarios.channels import CORNER_TAGS, channel_quantity
from elastokin.analysis.compare import ChannelComparison, Comparison
from elastokin.analysis.run_metrics import case_mask, cases, loop_axes
from elastokin.core.files import atomic_output
from elastokin.presentation.figures import save_figure
from elastokin.recordings.run_format import Run

# -- text ------------------------------------------------------------------------------------------
METRIC_NAMES = ("gradient", "loop_width", "loop_area", "relaxation", "dynamic_stiffness")
_TITLES = {"gradient": "gradient", "loop_width": "loop width at design", "loop_area": "loop area",
           "relaxation": "relaxation over the hold", "dynamic_stiffness": "|K*| first harmonic"}
_CELL = 11


def format_table(c: Comparison) -> str:
    """The comparison as text: per case, per quantity a header with units, a row per wheel with each
    metric's simulation, rig and difference (simulation − rig), and the RMS error."""
    x = f", x = {c.x_quantity}" if c.x_quantity else ""
    lines = [f"{c.sim} (simulation) against {c.rig} (rig), scenario {c.scenario}{x}; diff = simulation − rig"]
    lines += [f"DAMAGED {path}: {item}" for path, items in c.damage.items() for item in items]
    for case in c.cases:
        lines.append(f"case {case.case} '{case.label}'")
        why: dict[str, list[str]] = {}
        for metric, reason in case.not_applicable.items():
            why.setdefault(reason, []).append(metric)
        if why:
            lines.append("  n/a: " + "; ".join(f"{', '.join(metrics)} ({reason})" for reason, metrics in why.items()))
        by_quantity: dict[str, list[ChannelComparison]] = {}
        for ch in case.channels:
            by_quantity.setdefault(channel_quantity(ch.channel), []).append(ch)
        for quantity, rows in by_quantity.items():
            shown = [m for m in METRIC_NAMES if any(m in r.metrics for r in rows)]
            units = {m: next(r.metrics[m].unit for r in rows if m in r.metrics) for m in shown}
            width = 3 * _CELL + 2
            lines.append(f"  {f'{quantity} [{rows[0].unit}]':<18}"
                         + "".join(f" {f'{_TITLES[m]} [{units[m]}]':^{width}}" for m in shown)
                         + f" {f'RMS [{rows[0].unit}]':>{_CELL}}")
            lines.append(f"  {'wheel':<18}" + f" {'sim':>{_CELL}}{'rig':>{_CELL}}{'diff':>{_CELL}}  " * len(shown))
            for r in rows:
                cells = [f" {_num(r.metrics[m].sim)}{_num(r.metrics[m].rig)}{_num(r.metrics[m].diff)}  "
                         if m in r.metrics else f" {'-':>{3 * _CELL}}  " for m in shown]
                lines.append(f"  {r.channel.rsplit('_', 1)[1]:<18}" + "".join(cells) + f" {_num(r.rms_error)}")
    return "\n".join(lines)


def _num(value: float) -> str:
    return f"{value:{_CELL}.4g}"


# -- files -----------------------------------------------------------------------------------------
def _plot_loops(sim: Run, rig: Run, case: int, tags: list[str], path: Path) -> Path:
    """Camber and toe against the x quantity, simulation and rig overlaid, a panel per wheel."""
    fig = Figure(figsize=(4.5 * len(tags), 7), layout="constrained")
    axes = fig.subplots(2, len(tags), squeeze=False)
    for row, quantity in enumerate(("camber", "toe")):
        for col, tag in enumerate(tags):
            ax, (x, _) = axes[row, col], loop_axes(sim, tag)
            for run, style, source in ((sim, "-", "simulation"), (rig, "--", "rig")):
                m = case_mask(run, cases(run)[case - 1])
                ax.plot(run.signals[x][m], run.signals[f"{quantity}_{tag}"][m], style, lw=0.9,
                        label=f"{source}: {run.path.name}")
            ax.set(xlabel=sim.label(x), ylabel=sim.label(f"{quantity}_{tag}"))
            ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize="small")
    fig.suptitle(f"case {case} '{cases(sim)[case - 1]['label']}': loops, simulation (solid) and rig (dashed)")
    return save_figure(fig, path, dpi=110)


def _plot_time(sim: Run, rig: Run, case: int, names: list[str], path: Path) -> Path:
    """Each compared quantity against the input time, simulation and rig overlaid, a line per wheel."""
    quantities = list(dict.fromkeys(channel_quantity(n) for n in names))
    fig = Figure(figsize=(10, 2.4 * len(quantities)), layout="constrained")
    axes = fig.subplots(len(quantities), 1, sharex=True, squeeze=False)[:, 0]
    for ax, quantity in zip(axes, quantities):
        # wheel-centre coordinates differ by a track or a wheelbase: show them from the simulation's start
        relative = quantity.startswith("wheel_centre")
        for k, name in enumerate(n for n in names if channel_quantity(n) == quantity):
            origin = sim.signals[name][case_mask(sim, cases(sim)[case - 1])][0] if relative else 0.0
            for run, style in ((sim, "-"), (rig, "--")):
                m = case_mask(run, cases(run)[case - 1])
                ax.plot(run.signals["input_time"][m], run.signals[name][m] - origin, style, color=f"C{k}", lw=0.9,
                        label=name if run is sim else None)
        ax.set_ylabel(f"{'Δ' if relative else ''}{quantity} [{sim.units[name]}]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small", ncols=4)
    axes[-1].set_xlabel("time since the input started [s]")
    fig.suptitle(f"case {case} '{cases(sim)[case - 1]['label']}': simulation (solid) and rig (dashed)")
    return save_figure(fig, path, dpi=110)


def write_outputs(c: Comparison, sim: Run, rig: Run, out_dir: Path) -> list[Path]:
    """Write ``out_dir/comparison.json`` and, per case, ``loops_case<k>.png`` (periodic inputs) and
    ``time_case<k>.png``, each atomically; returns the paths written."""
    path = out_dir / "comparison.json"
    with atomic_output(path) as tmp:
        tmp.write_text(json.dumps(c.to_json(), indent=2) + "\n")
    written = [path]
    names = [ch.channel for ch in c.cases[0].channels]
    tags = [t for t in CORNER_TAGS.values() if all(f"{q}_{t}" in names for q in ("camber", "toe"))
            and all(a in sim.signals and a in rig.signals for a in (loop_axes(sim, t) or ()))]
    for case in c.cases:
        if c.x_quantity is not None and tags:
            written.append(_plot_loops(sim, rig, case.case, tags, out_dir / f"loops_case{case.case}.png"))
        written.append(_plot_time(sim, rig, case.case, names, out_dir / f"time_case{case.case}.png"))
    return written
