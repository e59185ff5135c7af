"""A bushing-bench dataset on disk: ``rig.yaml`` plus one ``t_s,e_mm,F_N`` CSV per test.

``rig.yaml`` (documented in data/README.md)::

    level: bench
    part: "front lower arm, E1 front bushing, radial x"   # free text
    quantity: translation                                  # e in mm, F in N
    rig: {name: ..., notes: ...}                           # free text about the rig
    records:                                               # in the order played on the part
      - file: 01_triangle_2mm_slow.csv
        programme: {type: triangle, amplitude_mm: 2.0, speed_mm_s: 0.333, cycles: 2}
        rest_before_s: 0.0                                 # part at rest (e = 0) before the test

The order matters: the part's state (hysteresis memory, Mullins damage, heat) carries over.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from elastokin.bushings.bench.records import BenchRecord, read_bench_csv
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_directory, is_file
from elastokin.core.units import MM_PER_M
from elastokin.recordings.datasets import read_manifest, write_manifest

_KEYS = ("level", "part", "quantity", "rig", "records")
_RECORD_KEYS = {"file", "programme", "rest_before_s"}
#: Longest rest before a test [s] (a day): beyond, a unit or typing error.
MAX_REST_S = 86_400.0


@dataclass(frozen=True)
class BenchTestRecord:
    """One measured test in a dataset."""

    name: str
    programme: dict[str, Any]
    rest_before_s: float
    record: BenchRecord


@dataclass(frozen=True)
class BenchDataset:
    """A measured bench campaign on one part."""

    path: Path
    part: str
    quantity: str
    records: list[BenchTestRecord]
    rig: dict[str, Any] = field(default_factory=dict)


def read_bench_dataset(directory: str | os.PathLike[str]) -> BenchDataset:
    """Read and validate a bench dataset; errors name the file and key (or CSV line and column)."""
    root = Path(directory)
    path, data = read_manifest(root, "bench", _KEYS)
    source = str(path)
    quantity = data.get("quantity", "translation")
    if quantity != "translation":
        raise InputError(f"the bench works in mm and N; got quantity {quantity!r}", source=source, key="quantity")
    entries = data.get("records")
    if not isinstance(entries, list) or not entries:
        raise InputError("expected a non-empty list of records", source=source, key="records")
    records = []
    for i, entry in enumerate(entries):
        key = f"records[{i}]"
        if not isinstance(entry, dict) or "file" not in entry:
            raise InputError("expected a mapping with at least a file key", source=source, key=key)
        bad = sorted(set(entry) - _RECORD_KEYS)
        if bad:
            raise InputError(f"unknown key {bad[0]!r}; expected {', '.join(sorted(_RECORD_KEYS))}", source=source,
                             key=f"{key}.{bad[0]}")
        rest = entry.get("rest_before_s", 0.0)
        if isinstance(rest, bool) or not isinstance(rest, (int, float)) or not 0.0 <= rest <= MAX_REST_S:
            raise InputError(f"expected a rest duration from 0 to {MAX_REST_S:g} s, got {rest!r}", source=source,
                             key=f"{key}.rest_before_s")
        file, programme = entry["file"], entry.get("programme")
        programme = {} if programme is None else programme   # an empty `programme:` (but not 0, '' or [])
        if not isinstance(file, str) or not is_file(root / file) or Path(file).name != file:
            raise InputError(f"expected the name of a record file in {root}, got {file!r}", source=source,
                             key=f"{key}.file")
        if not isinstance(programme, Mapping):
            raise InputError(f"expected a mapping describing the programme played, got {programme!r}", source=source,
                             key=f"{key}.programme")
        records.append(BenchTestRecord(Path(file).stem, dict(programme), float(rest), read_bench_csv(root / file)))
    part, rig = data.get("part", ""), data.get("rig")
    rig = {} if rig is None else rig
    if not isinstance(part, str) or not isinstance(rig, Mapping):
        bad = "part" if not isinstance(part, str) else "rig"
        raise InputError(f"expected {'free text' if bad == 'part' else 'a mapping'}, got {data[bad]!r}", source=source,
                         key=bad)
    return BenchDataset(root, part, quantity, records, dict(rig))


def write_bench_dataset(directory: str | os.PathLike[str], part: str, records: Sequence[BenchTestRecord],
                        rig: dict[str, Any], *, overwrite: bool = False) -> Path:
    """Write a dataset as a whole: into a temporary folder renamed at the end, so that a reader
    never sees a partial one. Forces are written to 0.001 N, deflections to 0.1 nm."""
    root = Path(directory)
    with atomic_directory(root, overwrite=overwrite) as tmp:
        entries = []
        width = len(str(len(records)))
        for i, r in enumerate(records, start=1):
            name = f"{i:0{width}d}_{r.name}.csv"
            rec = r.record
            np.savetxt(tmp / name, np.column_stack([rec.t, rec.e * MM_PER_M, rec.F]), delimiter=",",
                       fmt=("%.6f", "%.7f", "%.3f"), header="t_s,e_mm,F_N", comments="")
            entries.append({"file": name, "programme": r.programme, "rest_before_s": r.rest_before_s})
        manifest = {"level": "bench", "part": part, "quantity": "translation", "rig": rig, "records": entries}
        write_manifest(tmp, manifest)
    return root
