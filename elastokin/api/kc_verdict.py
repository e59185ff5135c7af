"""The diagnosis of a K&C rig's dataset: the baseline car run on the virtual rig, on a cluster."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from elastokin.api.vehicles import Vehicle, load_vehicle
from elastokin.api.verdicts import Diagnosis
from elastokin.cluster.executor import executor as cluster
from elastokin.diagnosis.kc_diagnosis import diagnose_kc
from elastokin.presentation import kc_report
from elastokin.recordings.kc_dataset import read_kc_dataset


def diagnose_kc_dataset(folder: Path, vehicle: Vehicle | str | Path | None, *, scheduler: str | None = None,
                        workers: int | None = None, progress: Callable[[str], None] | None = None,
                        use_damaged: bool = False) -> Diagnosis:
    """:func:`elastokin.diagnose` of the K&C dataset in ``folder`` against ``vehicle`` (default:
    the built-in car), its runs on ``scheduler``'s cluster; with ``use_damaged``, on the samples
    its damaged or incomplete recordings hold."""
    car = load_vehicle() if vehicle is None else vehicle if isinstance(vehicle, Vehicle) else load_vehicle(vehicle)
    data = read_kc_dataset(folder, use_damaged=use_damaged)
    with cluster(scheduler, workers) as ex:
        result = diagnose_kc(data, car.definition, executor=ex, progress=progress)
    return Diagnosis("kc", folder, result, car, kc_report.verdict_sentence, kc_report.summary,
                     lambda out: kc_report.write_report(result, car.definition, out, str(folder)))
