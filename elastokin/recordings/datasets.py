"""A measured dataset on disk: a folder whose ``rig.yaml`` declares its level (``bench``: CSV records
of a bushing bench, :mod:`elastokin.recordings.bench_dataset`; ``kc``: rig recordings of a car,
:mod:`elastokin.recordings.kc_dataset`) and lists its tests in the order played."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Mapping

from elastokin.core.documents import Document, dump_yaml
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output

RIG_FILE = "rig.yaml"
LEVELS = ("bench", "kc")


def _manifest(directory: str | os.PathLike[str]) -> tuple[Path, Any]:
    path = Path(directory) / RIG_FILE
    return path, Document.read(path, f"no {RIG_FILE} here: a measured directory describes its tests in {RIG_FILE}").data


def dataset_level(directory: str | os.PathLike[str]) -> str:
    """``bench`` or ``kc``: the level a measured directory declares in its rig.yaml."""
    path, data = _manifest(directory)
    if not isinstance(data, Mapping):
        raise InputError(f"expected a mapping with a level key (bench or kc), got {type(data).__name__}",
                         source=str(path))
    level = data.get("level")
    if level not in LEVELS:
        raise InputError(f"expected level bench or kc, got {level!r}", source=str(path), key="level")
    return level


def read_manifest(directory: str | os.PathLike[str], level: str, keys: tuple[str, ...]) -> tuple[Path, dict[str, Any]]:
    """The path and mapping of a dataset's rig.yaml, checked to hold only ``keys`` and to declare
    ``level``; errors name rig.yaml and the key."""
    path, data = _manifest(directory)
    source = str(path)
    if not isinstance(data, dict):
        raise InputError(f"expected a mapping with keys {', '.join(keys)}, got {type(data).__name__}", source=source)
    unknown = [k for k in data if k not in keys]
    if unknown:
        raise InputError(f"unknown key {unknown[0]!r}; expected {', '.join(keys)}", source=source, key=str(unknown[0]))
    if data.get("level") != level:
        raise InputError(f"expected level: {level}, got {data.get('level')!r}", source=source, key="level")
    return path, data


def write_manifest(directory: str | os.PathLike[str], manifest: Mapping[str, Any]) -> Path:
    """Write a dataset's rig.yaml, whole or not at all (the caller writes the tests)."""
    path = Path(directory) / RIG_FILE
    with atomic_output(path) as tmp:
        tmp.write_text(dump_yaml(dict(manifest), sort_keys=False, allow_unicode=True))
    return path


def check_baseline(directory: str | os.PathLike[str], level: str, vehicle: bool, law: bool,
                   use_damaged: bool = False) -> None:
    """InputError unless the baseline given suits the dataset's ``level``: a ``vehicle`` for K&C,
    a bushing ``law`` for a bench (which needs one); and unless ``use_damaged`` is asked of a K&C
    dataset only (a bench's CSV records are read whole or refused)."""
    where = str(Path(directory) / RIG_FILE)
    if level == "bench" and use_damaged:
        raise InputError("--use-damaged (use_damaged=True) is for a K&C dataset's recordings; a bench dataset's CSV "
                         "records are read whole or refused", source=where, key="level")
    if level == "kc" and law:
        raise InputError("a K&C dataset is diagnosed against a vehicle (--vehicle; vehicle=...), not a bushing set",
                         source=where, key="level")
    if level == "bench" and vehicle:
        raise InputError("a bench dataset is diagnosed against a bushing set (--bushing-set; bushings=...), not a "
                         "vehicle", source=where, key="level")
    if level == "bench" and not law:
        raise InputError("a bench dataset needs its baseline law: --bushing-set SET (bushings=SET), a parameter "
                         "set's name or path", source=str(directory))
