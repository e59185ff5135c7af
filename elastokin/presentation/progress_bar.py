"""A progress line for long runs, on the terminal or as one line per stage in a log."""

from __future__ import annotations

import sys
import time
from typing import TextIO

from elastokin.vehicle.scenarios.schedule import Progress


class ProgressBar:
    """A progress line on ``stream``: rewritten in place on a terminal (at most every
    ``interval_s``), else one line per case and phase."""

    def __init__(self, stream: TextIO | None = None, interval_s: float = 0.2, width: int = 30):
        self.stream = stream if stream is not None else sys.stderr
        self.interval_s, self.width = interval_s, width
        self.live = self.stream.isatty()
        self.started = time.perf_counter()
        self.shown_at = -1.0
        self.last_stage = None
        self.dirty = False

    def __call__(self, p: Progress) -> None:
        """Show a :class:`elastokin.vehicle.scenarios.schedule.Progress`."""
        now = time.perf_counter()
        stage = (p.case, p.phase)
        if not self.live:
            if stage != self.last_stage:
                print(f"case {p.case}/{p.cases} {p.label}: {p.phase_name}", file=self.stream, flush=True)
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
                f"case {p.case}/{p.cases} {p.label} ({p.phase_name})  "
                f"sim {p.done_s:.1f}/{p.total_s:.1f} s  wall {elapsed:.0f} s, {remaining} left")
        self.stream.write(line + "\x1b[K")
        self.stream.flush()

    def close(self) -> None:
        """End the progress line."""
        if self.dirty:
            self.stream.write("\n")
            self.stream.flush()
            self.dirty = False
