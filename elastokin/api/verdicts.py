"""What a diagnosis hands out, at either level: the verdict, its data and its report."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class Diagnosis:
    """A diagnosis of a measured dataset: ``level`` ``bench`` (one bushing on a bench) or ``kc``
    (a car on a K&C rig); ``result`` the diagnosis itself
    (:class:`~elastokin.diagnosis.bench_diagnosis.BenchDiagnosis` or
    :class:`~elastokin.diagnosis.kc_diagnosis.KCDiagnosis`: the ranking of every cause tried, the
    errors on training and held-out tests, the verdict); ``baseline`` the law or vehicle it started from."""

    level: str
    dataset: Path
    result: Any
    baseline: Any
    sentence: Callable[[Any], str] = field(repr=False)
    data: Callable[[Any], dict[str, Any]] = field(repr=False)
    report: Callable[[Path], list[Path]] = field(repr=False)

    def __repr__(self) -> str:
        return f"<Diagnosis of {self.dataset} ({self.level}): {self.verdict}>"

    @property
    def verdict(self) -> str:
        """The verdict in one sentence (the cause, its place and value, or why none is named)."""
        return self.sentence(self.result)

    def summary(self) -> dict[str, Any]:
        """The verdict as data: what ``vsim diagnose --json`` prints (the cause, its parameters
        with their uncertainties, the errors in noise units, the rivals)."""
        return self.data(self.result)

    def write_report(self, folder: str | Path) -> list[Path]:
        """Write the report into ``folder``: ``report.md``, PNGs, ``diagnosis.json`` and the
        extended model (``extended_model.yaml`` for a bench, ``extended_vehicle.yaml`` for K&C).

        Returns:
            The files written.
        """
        return self.report(Path(folder))
