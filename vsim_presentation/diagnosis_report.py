"""The report both diagnosis levels write: a one-page ``report.md`` (the verdict, how it was reached,
the ranking of the causes and the error per test, the pictures) beside ``diagnosis.json``, every file
written atomically."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterable, Sequence

from vsim_core.files import atomic_output


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
        self.lines += [f"| {' | '.join(header)} |", "|" + "---|" * len(header)]
        self.lines += [f"| {' | '.join(row)} |" for row in rows]
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
