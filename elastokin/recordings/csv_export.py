"""Exporting a rig recording as a K&C rig's CSV + META.yaml (format: ``data/README.md``), the
inverse of :mod:`elastokin.recordings.csv_import`: so that a dataset the virtual rig measured reaches
the diagnosis as a user's does, through `vsim rig import`, in a rig's own sign conventions.

:func:`write_declared_csv` writes the CSV any META file declares (each column = channel / (sign ×
unit factor) − offset); :func:`export_csv` first writes a META in one of :data:`CONVENTIONS`: the
run's units (time in s), a header ``<quantity>_<WHEEL>_<unit>`` per channel (``toe_FL_deg``,
``pad_mz_RR_Nm``), the signs of the convention, and the scenario played (a path relative to the
META file, or inline where the recording's scenario file is gone or has changed since).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from elastokin.core.documents import dump_yaml
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_directory, atomic_output, is_file, read_text
from elastokin.recordings.csv_import import read_meta
from elastokin.recordings.kc_dataset import read_kc_dataset, recorded_mapping
from elastokin.recordings.rig_recordings import measured_channels
from elastokin.recordings.run_format import Run
from elastokin.recordings.run_reader import load_run
from elastokin.vehicle.scenarios.channels import channel_quantity, channel_wheel

#: Significant digits of the CSV's numbers (the virtual rig's resolution, 0.001° or 0.01 mm, takes
#: at most 8 on its largest values).
DIGITS = 10


@dataclass(frozen=True)
class Convention:
    """A rig's sign convention: the quantities (channel names without their wheel) whose sign is
    the opposite of ISO 8855's."""

    name: str
    description: str
    flipped: frozenset[str]


#: The conventions a rig exports in. SAE J670's axes are x forward, y right, z down: a coordinate,
#: force or travel along y or z (a wheel centre's y and z, a pad's height and travel, Fy, Fz) and a
#: moment or rotation about z (the aligning torque, the steer angle, the rack's travel: steering
#: left) change sign; toe-in, camber top-out and wheel travel in bump, which both name by the wheel
#: and not by an axis, keep theirs, as do the half-track (a distance) and x.
CONVENTIONS = {
    "iso": Convention("iso", "ISO 8855 signs (x forward, y left, z up; toe-in, camber top-out and bump positive)",
                      frozenset()),
    "sae": Convention("sae", "SAE J670 signs (x forward, y right, z down; toe-in, camber top-out and bump positive)",
                      frozenset({"wheel_centre_y", "wheel_centre_z", "pad_height", "pad_z", "pad_fy", "pad_fz",
                                 "pad_mz", "steer", "rack"})),
}


def column_name(channel: str, unit: str) -> str:
    """The CSV header of ``channel`` in ``unit``: ``toe_fl`` in deg → ``toe_FL_deg``; ``rack`` in mm → ``rack_mm``."""
    wheel = channel_wheel(channel)
    return "_".join([channel_quantity(channel), *([wheel.upper()] if wheel else []), unit.replace("·", "")])


def write_declared_csv(run: Run, meta: str | os.PathLike[str], data: str | os.PathLike[str]) -> Path:
    """Write the CSV ``data`` that the META file ``meta`` declares for ``run``: its time column and
    each declared column as column = channel / (sign × unit factor) − offset, :data:`DIGITS`
    significant digits (`vsim rig import` gives the run's signals back to that precision).

    Raises:
        InputError: what reading the META refuses (:func:`elastokin.recordings.csv_import.read_meta`),
        or a declared channel the run does not hold; nothing is written then.
    """
    _, _, time, columns = read_meta(Path(meta))
    missing = [c for c in columns if c.channel not in run.signals]
    if missing:
        raise InputError(f"{run.path.name} holds no channel {missing[0].channel}", source=str(meta),
                         key=f"columns.{missing[0].name}")
    # + 0: a zero whose sign flipped is written 0, not -0
    table = np.column_stack([time.invert(run.t_s), *(c.invert(run.signals[c.channel]) for c in columns)]) + 0.0
    with atomic_output(Path(data)) as tmp:
        np.savetxt(tmp, table, delimiter=",", fmt=f"%.{DIGITS}g", header=",".join([time.name, *(c.name for c in columns)]),
                   comments="")
    return Path(data)


def export_csv(recording: str | os.PathLike[str], data: str | os.PathLike[str],
               meta: str | os.PathLike[str] | None = None, *, convention: str = "sae",
               overwrite: bool = False) -> tuple[Path, Path]:
    """Write the rig recording ``recording`` as a rig's CSV export ``data`` with its META file.

    Args:
        recording: a rig recording (.mcap, source ``rig``: the virtual rig's or `vsim rig import`'s).
        data: the CSV to write.
        meta: its META file (default: ``data`` with the suffix ``.meta.yaml``); `vsim rig import DATA
            --meta META` reads the pair back.
        convention: a key of :data:`CONVENTIONS` (``"sae"`` or ``"iso"``).
        overwrite: replace existing files.

    Returns:
        The paths written, (data, meta).

    Raises:
        InputError: an unknown convention, a recording that is not a rig recording, an existing
        output without ``overwrite``; nothing is written then.

    >>> from elastokin.recordings.csv_export import CONVENTIONS
    >>> sorted(CONVENTIONS["sae"].flipped)[:3]
    ['pad_fy', 'pad_fz', 'pad_height']
    """
    if convention not in CONVENTIONS:
        raise InputError(f"unknown convention {convention!r}; expected one of {', '.join(CONVENTIONS)}",
                         source=str(recording), key="convention")
    chosen = CONVENTIONS[convention]
    data = Path(data)
    meta = Path(meta) if meta is not None else data.with_name(f"{data.stem}.meta.yaml")
    for path in (data, meta):
        if path.exists() and not overwrite:
            raise InputError("the output exists; pass --overwrite (overwrite=True) to replace it", source=str(path))
    run = load_run(recording)
    if run.metadata.source != "rig":
        raise InputError(f"a {run.metadata.source} run, not a rig recording (source: rig)", source=str(recording))
    known = measured_channels()
    columns = {}
    for name in (n for n in known if n in run.signals):
        columns[column_name(name, known[name])] = {"channel": name, "unit": known[name],
                                                   **({"sign": -1} if channel_quantity(name) in chosen.flipped else {})}
    extra = run.metadata.extra
    rig = extra.get("rig") or {}
    notes = [str(rig["notes"])] if rig.get("notes") else []
    document = {"scenario": _scenario(run, meta), "duration_scale": float(extra.get("duration_scale", 1.0)),
                "rig": str(rig.get("name", "rig")),
                "notes": "; ".join([*notes, f"exported by vsim from {Path(recording).name} in {chosen.description}"]),
                "time": {"column": "time_s", "unit": "s"}, "columns": columns}
    with atomic_output(meta) as tmp:   # in place once the CSV it declares is
        tmp.write_text(dump_yaml(document, sort_keys=False, allow_unicode=True))
        write_declared_csv(run, tmp, data)
    return data, meta


def export_csv_folder(source: str | os.PathLike[str], folder: str | os.PathLike[str], *, convention: str = "sae",
                      overwrite: bool = False) -> list[tuple[Path, Path]]:
    """Export a rig recording, or every recording of a K&C dataset folder (with its ``rig.yaml``), as
    ``<recording stem>.csv`` + ``<recording stem>.meta.yaml`` in ``folder`` (:func:`export_csv`).

    Returns:
        The (data, meta) pairs written, in the dataset's order.

    Raises:
        InputError: what :func:`export_csv` and :func:`elastokin.recordings.kc_dataset.read_kc_dataset`
        refuse, or an existing ``folder`` without ``overwrite``; the folder is written whole or not
        at all.
    """
    source = Path(source)
    files = [t.file for t in read_kc_dataset(source).tests] if source.is_dir() else [source]
    root = Path(folder)
    with atomic_directory(root, overwrite=overwrite) as tmp:   # beside ``root``: the META's paths hold in both
        written = [export_csv(f, tmp / f"{f.stem}.csv", convention=convention) for f in files]
    return [(root / d.name, root / m.name) for d, m in written]


def _scenario(run: Run, meta: Path) -> str | dict[str, Any]:
    """The scenario the recording played, as META gives it: its file relative to ``meta``'s folder
    where that file still holds the text the recording stored; else inline (the stored mapping, its
    paths absolute, the vehicle left out: a rig recording names no model)."""
    inline, played = recorded_mapping(run, source=str(run.path))
    if is_file(played) and read_text(played) == run.metadata.scenario_yaml:
        return os.path.relpath(Path(played).resolve(), meta.parent.resolve())
    inline.pop("vehicle")
    return inline
