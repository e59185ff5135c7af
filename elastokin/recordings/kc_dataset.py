"""A K&C dataset on disk: ``rig.yaml`` plus one MCAP rig recording per test (format: data/README.md).

``rig.yaml``::

    level: kc
    vehicle: "Peugeot 307-like hatchback (as delivered)"     # free text: the car measured
    rig: {name: ..., notes: ...}                             # free text about the rig
    recordings: [01_kc_pumping.mcap, 02_kc_roll.mcap]        # in the order played on the car

Each recording is a rig recording (:mod:`elastokin.recordings.rig_recordings`: source ``rig``, no model) that holds
the scenario it played; :func:`recorded_scenario` rebuilds that scenario with the scenarios
module's own parser, so that a measured test and its simulation split into the same cases. This
module is the one place that reads and writes the format.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping, Sequence


from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.vehicle.scenarios.scenario_file import parse_scenario
from elastokin.core.documents import Document, dump_yaml
from elastokin.core.errors import InputError
from elastokin.core.files import is_file
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.recordings.datasets import RIG_FILE, read_manifest, write_manifest
from elastokin.recordings.run_format import Run
from elastokin.recordings.run_reader import load_run

LEVEL = "kc"
_KEYS = ("level", "vehicle", "rig", "recordings")


@dataclass(frozen=True)
class KCTest:
    """One measured K&C test: its recording and the scenario it played."""

    name: str            #: the recording's file stem (``01_kc_pumping``)
    file: Path
    run: Run
    scenario: Scenario


@dataclass(frozen=True)
class KCDataset:
    """A measured K&C campaign on one car, tests in the order played."""

    path: Path
    vehicle_text: str
    rig: dict[str, Any] = field(default_factory=dict)
    tests: list[KCTest] = field(default_factory=list)
    #: what its damaged or incomplete recordings lack (``"02_kc_roll.mcap: chunk 3 of 12 failed ..."``),
    #: read with ``use_damaged``
    damage: tuple[str, ...] = ()


def write_kc_rig_yaml(directory: str | os.PathLike[str], vehicle_text: str, rig: Mapping[str, Any],
                      recordings: Sequence[str]) -> Path:
    """Write the ``rig.yaml`` of a K&C dataset into ``directory`` (whose recordings the caller writes)."""
    return write_manifest(directory, {"level": LEVEL, "vehicle": str(vehicle_text), "rig": dict(rig),
                                      "recordings": list(recordings)})


def read_kc_dataset(directory: str | os.PathLike[str], *, use_damaged: bool = False) -> KCDataset:
    """Read and validate a K&C dataset; errors name ``rig.yaml`` and the key (``recordings[i]`` for
    a recording that is missing, unreadable, not a rig recording, or whose scenario cannot be
    rebuilt; and, unless ``use_damaged``, one that is damaged or incomplete: with it, the samples
    such a recording holds are used and what it lacks is in the dataset's ``damage``)."""
    root = Path(directory)
    path, data = read_manifest(root, LEVEL, _KEYS)
    source = str(path)
    vehicle_text = data.get("vehicle", "")
    if not isinstance(vehicle_text, str):
        raise InputError(f"expected free text (the car measured), got {vehicle_text!r}", source=source, key="vehicle")
    rig = data.get("rig") or {}
    if not isinstance(rig, dict):
        raise InputError(f"expected a mapping (name, notes, ...), got {rig!r}", source=source, key="rig")
    entries = data.get("recordings")
    if not isinstance(entries, list) or not entries:
        raise InputError(f"expected a non-empty list of recording files (.mcap, relative to this file), got "
                         f"{entries!r}", source=source, key="recordings")
    tests = _tests(root, entries, source, use_damaged)
    damage = tuple(f"{t.file.name}: {t.run.reason}" for t in tests if not t.run.complete)
    return KCDataset(root, vehicle_text, dict(rig), tests, damage)


def _tests(root: Path, entries: list[Any], source: str, use_damaged: bool) -> list[KCTest]:
    """The tests of the recording files ``entries`` (relative to ``root``), in that order; errors
    name ``source`` and ``recordings[i]``."""
    tests, seen = [], set()
    for i, entry in enumerate(entries):
        key = f"recordings[{i}]"
        if not isinstance(entry, str) or not entry:
            raise InputError(f"expected a recording file name, got {entry!r}", source=source, key=key)
        if entry in seen:
            raise InputError(f"{entry!r} is listed twice", source=source, key=key)
        seen.add(entry)
        file = root / entry
        if not is_file(file):
            raise InputError(f"no such recording file {entry!r}", source=source, key=key)
        run = _load(file, source, key, use_damaged)
        tests.append(KCTest(file.stem, file, run, recorded_scenario(run, source=source, key=key)))
    return tests


def assemble_kc_dataset(directory: str | os.PathLike[str], recordings: Sequence[str] | None = None, *,
                        vehicle_text: str = "", overwrite: bool = False) -> KCDataset:
    """Make a folder of rig recordings (`vsim rig import`'s) a K&C dataset: write its ``rig.yaml``.

    Args:
        directory: the folder that holds the recordings.
        recordings: their file names in the order played (default: every ``*.mcap`` there, by name).
        vehicle_text: free text, the car measured.
        overwrite: replace an existing ``rig.yaml``.

    Returns:
        The dataset, read back as :func:`read_kc_dataset` reads it.

    Raises:
        InputError: naming ``rig.yaml`` and ``recordings[i]`` for a recording that is missing,
        unreadable, damaged, not a rig recording or whose scenario cannot be rebuilt; an existing
        ``rig.yaml`` without ``overwrite``; no recording at all. Nothing is written then. The rig's
        description is the first recording's (its name and notes; what it was imported from and its
        sampling rate are each recording's own).
    """
    root = Path(directory)
    path = root / RIG_FILE
    if path.exists() and not overwrite:
        raise InputError("the output exists; pass --overwrite (overwrite=True) to replace it", source=str(path))
    entries = list(recordings) if recordings is not None else sorted(p.name for p in root.glob("*.mcap"))
    if not entries:
        raise InputError(f"no recording (.mcap) in {root}; expected the tests of one car, as `vsim rig import` "
                         f"writes them", source=str(path), key="recordings")
    tests = _tests(root, entries, str(path), use_damaged=False)
    rig = {k: v for k, v in (tests[0].run.metadata.extra.get("rig") or {}).items()
           if k not in ("imported_from", "sample_rate_hz")}   # each recording's own
    write_kc_rig_yaml(root, vehicle_text, rig, entries)
    return read_kc_dataset(root)


def _load(file: Path, source: str, key: str, use_damaged: bool) -> Run:
    try:
        run = load_run(file)
    except InputError as exc:
        raise InputError(f"{file.name}: {exc.bare}", source=source, key=key) from exc
    if run.metadata.source != "rig":
        raise InputError(f"{file.name} is a {run.metadata.source} run, not a rig recording (source: rig); "
                         f"a measured dataset holds measurements only", source=source, key=key)
    if not run.complete and not use_damaged:
        raise InputError(f"{file.name} is incomplete ({run.reason}); --use-damaged (use_damaged=True) diagnoses "
                         f"with the samples it holds", source=source, key=key)
    if run.t_s.size < 2:
        raise InputError(f"{file.name} holds {run.t_s.size} sample(s); expected a whole test", source=source, key=key)
    return run


def recorded_scenario(run: Run, *, source: str | None = None, key: str | None = None) -> Scenario:
    """The scenario a recording played, rebuilt from its stored text by :func:`parse_scenario`.

    Paths in the text (the scenario's ``vehicle``, a CSV case's ``path``) are relative to the file
    the scenario was read from (``extra.scenario_file``: relative to the recording's folder, as the
    virtual rig writes it, else to the working directory, or absolute). A vehicle that does not
    resolve is replaced by the default vehicle: a recording names no model, and a simulation of the
    test is given its vehicle explicitly. The result carries the stored text, and the path of the
    scenario file where it was found (else as recorded).
    Errors are :class:`InputError` naming ``source`` and ``key``.
    """
    data, where = recorded_mapping(run, source=source, key=key)
    try:
        scenario = parse_scenario(dump_yaml(data, sort_keys=False, allow_unicode=True), where)
    except InputError as exc:
        sub = f", {exc.key}" if exc.key else ""
        raise InputError(f"{run.path.name}: its scenario{sub}: {exc.bare}", source=source, key=key) from None
    return replace(scenario, name=data["name"] or scenario.name, path=where, text=run.metadata.scenario_yaml)


def recorded_mapping(run: Run, *, source: str | None = None, key: str | None = None) -> tuple[dict[str, Any], Path]:
    """The scenario mapping a recording stored, its paths made absolute as :func:`recorded_scenario`
    says (the vehicle's, the default vehicle where it does not resolve) and its ``name`` the one it
    played under; and the scenario file where it was found (else as recorded). Errors name
    ``source`` and ``key``."""
    text = run.metadata.scenario_yaml
    try:
        data = Document(text, run.path.name).data
    except InputError as exc:
        sub = f", {exc.key}" if exc.key else ""
        raise InputError(f"{run.path.name}: its scenario{sub}: {exc.bare}", source=source, key=key) from None
    if not isinstance(data, dict):
        raise InputError(f"{run.path.name}: no scenario recorded (scenario_yaml is {text[:40]!r})", source=source,
                         key=key)
    recorded = str(run.metadata.extra.get("scenario_file") or "")
    file = _scenario_file(run, recorded)
    base = None if file is None else file.parent
    data = dict(data)
    vehicle = _resolve(data.get("vehicle"), base)
    found = isinstance(vehicle, str) and Path(vehicle).is_absolute() and is_file(vehicle)
    data["vehicle"] = vehicle if found else str(DEFAULT_VEHICLE)
    for part in (data.get("defaults"), *(data.get("cases") or [])):
        if isinstance(part, dict) and isinstance(part.get("path"), str):
            part["path"] = _resolve(part["path"], base)
    data["name"] = data["name"] if isinstance(data.get("name"), str) else str(run.metadata.extra.get("scenario", ""))
    return data, file or Path(recorded or run.path)


def _scenario_file(run: Run, recorded: str) -> Path | None:
    """The recorded scenario file, if it is still there (relative to the recording's folder, else
    to the working directory, or absolute)."""
    if not recorded:
        return None
    path = Path(recorded)
    candidates = [path] if path.is_absolute() else [run.path.parent / path, path]
    return next((c.resolve() for c in candidates if is_file(c)), None)


def _resolve(value: Any, base: Path | None) -> Any:
    """``value`` (a path in the scenario) made absolute against ``base`` when it is relative."""
    if not isinstance(value, str) or Path(value).is_absolute() or base is None:
        return value
    return str((base / value).resolve())
