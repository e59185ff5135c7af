"""The quick-start notebook (issue 49) runs as Jupyter runs it, in a kernel of its own, from a folder
of its own: its every cell, the K&C diagnosis (two minutes on two cores) in the slow stage only."""

from __future__ import annotations

from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOK = Path(__file__).resolve().parents[1] / "examples" / "quickstart.ipynb"


def _executed(folder: Path, skip: set[str]) -> nbformat.NotebookNode:
    """The notebook with its cells run in ``folder``, less those tagged with one of ``skip``;
    nbclient raises CellExecutionError, naming the cell, at the first that fails."""
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    notebook.cells = [c for c in notebook.cells if not set(c.metadata.get("tags", ())) & skip]
    NotebookClient(notebook, timeout=900, kernel_name="python3", resources={"metadata": {"path": str(folder)}}).execute()
    return notebook


def _text(cell: nbformat.NotebookNode) -> str:
    return "".join(o.get("text", "") + o.get("data", {}).get("text/plain", "") for o in cell.get("outputs", []))


def test_the_quick_start_notebook_runs(tmp_path: Path) -> None:
    notebook = _executed(tmp_path, skip={"slow"})
    code = [c for c in notebook.cells if c.cell_type == "code"]
    assert "<Run pumping (pumping): 6 case(s)" in _text(code[1]) and "rad deg" in _text(code[1])
    assert "bump_camber_deg_per_m" in _text(code[2])
    assert any("image/png" in o.get("data", {}) for o in code[3].outputs)   # the camber figure shows
    changed = [line.split() for line in _text(code[4]).splitlines()]
    assert [row[0] for row in changed] == ["bump_camber_deg_per_m", "camber_loop_width_deg", "toe_loop_width_deg"]
    assert "(True, True)" in _text(code[7])                                 # saved and read back the same
    assert (tmp_path / "pumping.mcap").is_file()


@pytest.mark.slow
def test_the_quick_start_notebook_diagnoses_the_shipped_kc_dataset(tmp_path: Path) -> None:
    notebook = _executed(tmp_path, skip=set())
    verdict = _text([c for c in notebook.cells if "slow" in c.metadata.get("tags", ())][0])
    assert "e1_rear" in verdict, verdict   # the shipped dataset's cross stiffness in the rear pivots (README)
