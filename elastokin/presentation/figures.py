"""Writing matplotlib figures as PNG files, atomically (no display needed)."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure

from elastokin.core.files import atomic_output


def save_figure(fig: Figure, path: Path, dpi: int = 120) -> Path:
    """Write the figure as an image atomically, so that a reader never sees half a file."""
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=dpi)
    return path
