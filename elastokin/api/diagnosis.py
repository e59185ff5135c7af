"""The diagnosis as the API hands it out: what the baseline gets wrong on a measured dataset, the
cause named, the gain measured on held-out tests; and its report."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from elastokin.api.bench_verdict import diagnose_bench_dataset
from elastokin.api.built_ins import dataset as dataset_folder
from elastokin.api.kc_verdict import diagnose_kc_dataset
from elastokin.api.vehicles import Vehicle
from elastokin.api.verdicts import Diagnosis
from elastokin.bushings.parameter_sets import ParameterSet
from elastokin.recordings.datasets import check_baseline, dataset_level


def diagnose(dataset: str | Path, vehicle: Vehicle | str | Path | None = None, *,
             bushings: ParameterSet | str | Path | None = None, scheduler: str | None = None,
             workers: int | None = None, progress: Callable[[str], None] | None = None,
             use_damaged: bool = False) -> Diagnosis:
    """What the model misses in a measured dataset: the baseline run on exactly the tests found,
    every applicable cause of the catalogue fitted on half of them and scored on the other half.

    Args:
        dataset: a dataset folder (with its ``rig.yaml``, format: ``data/README.md``), or a
            shipped example by name (``kc``, ``bench``: :func:`elastokin.built_ins`).
        vehicle: the baseline car of a K&C dataset (default: the built-in car).
        bushings: the baseline law of a bench dataset (a parameter set, its name or path).
        scheduler: where a K&C diagnosis's runs execute: a Dask scheduler's address, ``local``
            (a cluster on this machine) or ``serial`` (this process); default ``$VSIM_SCHEDULER``,
            else local.
        workers: worker processes of a local cluster (default: one per core).
        progress: called with a line of text at each stage.
        use_damaged: diagnose a K&C dataset whose recordings are damaged or incomplete with the
            samples they hold (what they lack is in the report and ``summary()["damage"]``);
            default: refuse it.

    Returns:
        The :class:`~elastokin.api.verdicts.Diagnosis`.

    Raises:
        InputError: a damaged (unless ``use_damaged``) or missing dataset, a baseline of the wrong level (a vehicle for a
            bench dataset, a law for a K&C one), a bench dataset without its baseline law.
    """
    folder = dataset_folder(dataset)
    level = dataset_level(folder)
    check_baseline(folder, level, vehicle is not None, bushings is not None, use_damaged)
    if level == "kc":
        return diagnose_kc_dataset(folder, vehicle, scheduler=scheduler, workers=workers, progress=progress,
                                   use_damaged=use_damaged)
    return diagnose_bench_dataset(folder, bushings, progress)
