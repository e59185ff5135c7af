"""The report both diagnosis levels write: a one-page ``report.md`` (the verdict, how it was reached,
the ranking of the causes and the error per test, the pictures) beside ``diagnosis.json``, every file
written atomically; and the ranking's chart."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Iterable, Sequence

from matplotlib.figure import Figure

from elastokin.core.files import atomic_output
from elastokin.diagnosis.verdict import MAX_EXCESS_LEFT, Separation
from elastokin.presentation.figures import save_figure


def _row(cells: Sequence[str]) -> str:
    return "|" + "|".join(f" {c} " if c else " " for c in cells) + "|"


class Report:
    """A one-page markdown report being composed: a title, the verdict sentence, then paragraphs,
    sections, tables and pictures in the order added."""

    def __init__(self, title: str, verdict: str, method: str):
        """``method`` says what was compared and how errors are counted."""
        self.lines = [f"# {title}", "", verdict, "", method, ""]

    def paragraph(self, text: str) -> None:
        """A paragraph of text."""
        self.lines += [text, ""]

    def section(self, heading: str) -> None:
        """A section heading."""
        self.lines += [f"## {heading}", ""]

    def table(self, header: Sequence[str], rows: Iterable[Sequence[str]]) -> None:
        """A table of text cells."""
        self.lines += [_row(header), "|" + "---|" * len(header)]
        self.lines += [_row(row) for row in rows]
        self.lines.append("")

    def picture(self, name: str) -> None:
        """A PNG of the report's folder, named by its stem."""
        self.lines += [f"![{Path(name).stem}]({name})", ""]

    def write(self, out_dir: Path, summary: dict[str, Any]) -> list[Path]:
        """``report.md`` and ``diagnosis.json`` (the machine-readable ``summary``) in ``out_dir``."""
        written = []
        for name, text in (("report.md", "\n".join(self.lines)), ("diagnosis.json", json.dumps(summary, indent=2))):
            with atomic_output(out_dir / name) as tmp:
                tmp.write_text(text)
            written.append(out_dir / name)
        return written


def finite(x: float) -> float | None:
    """``x``, or None (JSON's null, which has no infinity) for a figure not bounded or not computed (an
    uncertainty the tests do not bound, a training error no fit gave)."""
    return x if math.isfinite(x) else None


def ranking_chart(baseline: float, causes: Sequence[tuple[str, float]], floor: tuple[float, str], xlabel: str,
                  out: Path, *, log: bool = False) -> Path:
    """Bars of the held-out error of the baseline (red, on top) and of each ranked ``(cause, error)``
    (blue), the noise ``floor`` (value, label) dashed; written to ``out`` (PNG)."""
    fig = Figure(figsize=(7, 0.5 + 0.4 * (len(causes) + 1)))
    ax = fig.add_subplot(1, 1, 1)
    names = ["baseline"] + [name for name, _ in causes]
    values = [baseline] + [value for _, value in causes]
    ax.barh(names[::-1], values[::-1], color=["C0"] * len(causes) + ["C3"])
    ax.axvline(floor[0], color="k", ls="--", lw=0.8, label=floor[1])
    if log:
        ax.set_xscale("log")
    ax.set_xlabel(xlabel)
    ax.legend(fontsize=7)
    return save_figure(fig, out)


def partly_explained(share: float, left: str = "") -> str:
    """The sentence that follows a cause that explains the mismatch only partly (``share`` of its
    excess over the noise); ``left`` names what it still does not fit."""
    still = f"; still not fitted: {left}" if left else ""
    return (f" Partly explained: it removes {share:.0%} of the mismatch beyond the noise, short of a full "
            f"explanation (at least {1.0 - MAX_EXCESS_LEFT ** 2:.0%} removed, nothing significant left){still}.")


def separation_clause(sep: Separation, what: str) -> str:
    """Whether the extra ``what`` (e.g. "rig test") ``sep`` names would separate two causes the
    dataset cannot tell apart, with how far apart their predictions lie there."""
    if not sep.separates:
        return f"no shipped {what} separates them (the most, `{sep.test}`, by {sep.difference:.2g} × the noise, RMS)."
    return (f"the shipped {what} `{sep.test}` would separate them (their predictions differ there by "
            f"{sep.difference:.2g} × the noise, RMS).")
