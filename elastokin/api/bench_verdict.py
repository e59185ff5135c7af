"""The diagnosis of a bushing bench's dataset (no MuJoCo needed)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from elastokin.api.verdicts import Diagnosis
from elastokin.bushings.parameter_sets import ParameterSet, load_parameter_set
from elastokin.diagnosis.bench_diagnosis import diagnose_bench
from elastokin.presentation import bench_report
from elastokin.recordings.bench_dataset import read_bench_dataset
from elastokin.recordings.datasets import check_baseline


def diagnose_bench_dataset(folder: Path, bushings: ParameterSet | str | Path | None,
                           progress: Callable[[str], None] | None = None) -> Diagnosis:
    """:func:`elastokin.diagnose` of the bench dataset in ``folder`` against the law ``bushings``."""
    check_baseline(folder, "bench", False, bushings is not None)
    law = bushings if isinstance(bushings, ParameterSet) else load_parameter_set(bushings)
    result = diagnose_bench(read_bench_dataset(folder), law, progress=progress)
    return Diagnosis("bench", folder, result, law, bench_report.verdict_sentence, bench_report.summary,
                     lambda out: bench_report.write_report(result, out))
