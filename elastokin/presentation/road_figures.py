"""Figures of road runs: the responses of several cars to the same manoeuvre, overlaid case by
case against the time since the input started (what the bushings do on the road)."""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from elastokin.analysis.road_comparison import Variant  # noqa: E402
from elastokin.presentation.figures import save_figure  # noqa: E402

#: (signal or the front wheels' mean toe, axis label) of the overlay panels.
PANELS = (("steering_wheel", "steering wheel [deg]"), ("yaw_rate", "yaw rate [deg/s]"),
          ("lateral_acceleration", "lateral acceleration [m/s²]"), ("front_toe", "front toe-in, mean [deg]"),
          ("roll", "roll [deg]"), ("sideslip", "sideslip [deg]"))


def overlay_variants(variants: Sequence[Variant], out_dir: Path) -> list[Path]:
    """One PNG per case: the panels of :data:`PANELS` for every variant that holds them, from 0.5 s
    before the input."""
    written = []
    reference = variants[0].run
    for case in reference.metadata.extra["cases"]:
        fig, axes = plt.subplots(len(PANELS), 1, figsize=(8, 2.2 * len(PANELS)), sharex=True, constrained_layout=True)
        for v in variants:
            run = v.run
            c = next(x for x in run.metadata.extra["cases"] if x["case"] == case["case"])
            mask = (run.t_s >= c["input_start_s"] - 0.5) & (run.t_s <= c["end_s"])
            t = run.t_s[mask] - c["input_start_s"]
            for ax, (name, label) in zip(axes, PANELS):
                if name == "front_toe" and "toe_fl" in run.signals and "toe_fr" in run.signals:
                    y = 0.5 * (run.signals["toe_fl"] + run.signals["toe_fr"])
                elif name in run.signals:
                    y = run.signals[name]
                else:
                    continue   # a road test that did not log it
                ax.plot(t, y[mask], lw=1.0, label=v.label)
                ax.set_ylabel(label)
                ax.grid(alpha=0.3)
        axes[0].legend(fontsize=8)
        axes[-1].set_xlabel("time since the input started [s]")
        extra = reference.metadata.extra
        fig.suptitle(f"{extra['scenario']}: case {case['case']} '{case['label']}'")
        written.append(save_figure(fig, out_dir / f"case_{case['case']}.png"))
        plt.close(fig)
    return written
