"""A truth file of either level (``level: bench`` or ``level: kc``), and what the virtual rig measures
on it: the one entry point of `vsim rig measure`."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Mapping

from elastokin.core.documents import Document
from elastokin.diagnosis.virtual_bench import Truth, measure_bench, parse_truth
from elastokin.diagnosis.virtual_kc_rig import KCTruth, measure_kc, parse_kc_truth


def load_truth(path: Path) -> Truth | KCTruth:
    """Read and validate a truth YAML file of either level: a :class:`Truth` (``level: bench``) or a
    :class:`elastokin.diagnosis.virtual_kc_rig.KCTruth` (``level: kc``)."""
    path = Path(path)
    data = Document.read(path, "no such truth file").data
    if isinstance(data, Mapping) and data.get("level") == "kc":
        return parse_kc_truth(data, str(path), path.parent)
    return parse_truth(data, str(path), path.parent)



def measure(truth: Truth | KCTruth, output: str | os.PathLike[str], *, overwrite: bool = False,
            progress: Callable[[int, int, str], None] | None = None) -> Path:
    """The measured dataset of ``truth`` written to ``output`` by the virtual bench or K&C rig;
    ``progress(i, n, name)`` before each test or scenario."""
    if isinstance(truth, KCTruth):
        return measure_kc(truth, output, overwrite=overwrite, progress=progress)
    return measure_bench(truth, Path(output), overwrite=overwrite, progress=progress)
