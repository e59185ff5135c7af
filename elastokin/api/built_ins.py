"""The shipped files a user can name: vehicles, scenarios, sweeps, bushing parameter sets and
property files, tyres, bench programmes and example datasets; their list, and editable copies."""

from __future__ import annotations

import re
import shutil
from dataclasses import dataclass
from pathlib import Path

from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output, read_text
from elastokin.core.shipped import (BENCH_DIR, DATASET_DIR, PARAMETER_SET_DIR, SCENARIO_DIR, SWEEP_DIR, TYRE_DIR,
                                    VEHICLE_DIR, built_in, resolve)


@dataclass(frozen=True)
class Kind:
    """One kind of built-in: where its files are and how they end (a dataset is a folder)."""

    name: str            #: plural, as ``vsim list`` prints it
    folder: Path
    suffix: str          #: ``""`` for a folder (a dataset)
    about: str


#: Every kind of built-in, in the order of the data's flow.
KINDS = (
    Kind("vehicles", VEHICLE_DIR, ".yaml", "vehicle files (format: models/vehicles/README.md)"),
    Kind("bushing sets", PARAMETER_SET_DIR, ".yaml", "bushing parameter sets (models/bushings/README.md)"),
    Kind("bushing property files", PARAMETER_SET_DIR, ".bus",
         "Adams bushing property files, exported from sets (`property_file:` in a vehicle file)"),
    Kind("tyres", TYRE_DIR, ".tir", "tyre property files, Magic Formula (models/tyres/README.md)"),
    Kind("scenarios", SCENARIO_DIR, ".yaml", "what the car is made to do, on the rig and the road (scenarios/README.md)"),
    Kind("sweeps", SWEEP_DIR, ".yaml", "designs of runs over vehicle-file numbers (scenarios/sweeps/README.md)"),
    Kind("bench programmes", BENCH_DIR, ".yaml", "bushing bench programmes for `vsim bushing run`"),
    Kind("datasets", DATASET_DIR, "", "example measured datasets for `vsim diagnose` (data/README.md)"),
)


def _names(kind: Kind) -> list[str]:
    if not kind.suffix:
        return sorted(p.parent.name for p in kind.folder.glob("*/rig.yaml"))
    if kind.folder == PARAMETER_SET_DIR:   # the bench programmes are a folder of their own
        return sorted(p.stem for p in kind.folder.glob(f"*{kind.suffix}"))
    return built_in(kind.folder, kind.suffix)


def built_ins() -> dict[str, list[str]]:
    """The names of every built-in, by kind (``vehicles``, ``bushing sets``, ``tyres``,
    ``scenarios``, ``sweeps``, ``bench programmes``, ``datasets``).

    >>> import elastokin
    >>> elastokin.built_ins()["vehicles"]
    ['c_segment', 'c_segment_thesis']
    >>> "road/step_steer" in elastokin.built_ins()["scenarios"]
    True
    """
    return {kind.name: _names(kind) for kind in KINDS}


def dataset(name_or_path: str | Path) -> Path:
    """The folder of a measured dataset: ``name_or_path`` if it is a folder with a ``rig.yaml``, else
    the shipped example of that name (``kc``: a K&C campaign; ``bench``: a bushing bench's tests).

    Raises:
        InputError: neither (the shipped names listed).

    >>> import elastokin
    >>> (elastokin.dataset("kc") / "rig.yaml").is_file()
    True
    """
    path = Path(name_or_path)
    if (path / "rig.yaml").is_file():
        return path
    names = _names(KINDS[-1])
    if str(name_or_path) in names:
        return DATASET_DIR / str(name_or_path)
    raise InputError(f"no dataset folder (with a rig.yaml) there, and no shipped example of that name; shipped ones: "
                     f"{', '.join(names)}",
                     source=str(path))


def _find(name: str) -> tuple[Kind, Path]:
    """The kind and file (or folder) of the built-in ``name`` (``kind:name`` when two kinds share it)."""
    wanted, _, bare = name.rpartition(":") if ":" in name else ("", "", name)
    found = [(k, bare) for k in KINDS if (not wanted or k.name == wanted) and bare in _names(k)]
    if not found:
        raise InputError("no built-in of that name; `vsim list` lists them", source=name)
    if len(found) > 1:
        raise InputError(f"the name of a built-in {' and a built-in '.join(k.name for k, _ in found)}: write "
                         f"{' or '.join(f'{k.name}:{bare}' for k, _ in found)}", source=name)
    kind, bare = found[0]
    return kind, (kind.folder / bare if not kind.suffix else kind.folder / f"{bare}{kind.suffix}")


def _named(text: str, key: str, folder: Path, suffix: str, base: Path, into: Path) -> str:
    """``text`` with the top-level ``key``'s value replaced, where it is a path into the shipped
    ``folder``, by the copy of that file in ``into`` when there is one (a copied vehicle, to edit),
    else by the built-in's name (a copy elsewhere keeps finding it)."""
    match = re.search(rf"^({re.escape(key)}:\s*)([^\s#]+)", text, flags=re.M)
    if match is None:
        return text
    try:
        target = resolve(match.group(2).strip("'\""), folder, key, base=base, suffix=suffix).resolve()
    except InputError:
        return text
    if folder.resolve() not in target.parents:
        return text
    name = target.relative_to(folder.resolve()).with_suffix("").as_posix()
    if (into / target.name).is_file():
        name = target.name
    return text[:match.start(2)] + name + text[match.end(2):]


def copy_built_in(name: str, folder: str | Path, *, overwrite: bool = False) -> list[Path]:
    """An editable copy of the built-in ``name`` in ``folder``, that runs from there as it is.

    A vehicle comes with its tyre's property file (the copy's ``property_file`` names it); a
    scenario's or sweep's ``vehicle`` that points into the shipped vehicles names the copy of that
    vehicle in ``folder`` when there is one (copy the vehicle first, to run the scenario on your
    edits), else the built-in by its name; a dataset is copied whole. Bushing sets named by a vehicle stay built-ins (copy one with
    its name, then name the copy's path in the vehicle file).

    Args:
        name: a built-in name as :func:`built_ins` lists it (``kind:name`` where two kinds share one).
        folder: where the copy goes (made if missing).
        overwrite: replace files of the same names there.

    Returns:
        The files (or the folder, for a dataset) written.

    Raises:
        InputError: no such built-in, or a file of that name is already in ``folder``.
    """
    kind, source = _find(name)
    folder = Path(folder)
    target = folder / source.name
    copies: list[tuple[Path, Path | str]] = []
    if source.is_dir():
        copies.append((target, source))
    else:
        text = read_text(source)
        if kind.folder in (SCENARIO_DIR, SWEEP_DIR):
            text = _named(text, "vehicle", VEHICLE_DIR, ".yaml", source.parent, folder)
        if kind.folder == VEHICLE_DIR:
            match = re.search(r"^(\s+property_file:\s*)([^\s#]+)", text, flags=re.M)
            if match is not None:
                tyre = resolve(match.group(2).strip("'\""), TYRE_DIR, "tyre property", base=source.parent, suffix=".tir")
                copies.append((folder / tyre.name, tyre))
                text = text[:match.start(2)] + tyre.name + text[match.end(2):]
        copies.insert(0, (target, text))
    existing = [str(p) for p, _ in copies if p.exists()]
    if existing and not overwrite:
        raise InputError(f"already there: {', '.join(existing)}; pass --overwrite (overwrite=True) to replace",
                         source=str(folder))
    folder.mkdir(parents=True, exist_ok=True)
    for path, content in copies:
        if isinstance(content, str):
            with atomic_output(path) as partial:
                partial.write_text(content)
        elif content.is_dir():
            shutil.rmtree(path, ignore_errors=True)
            shutil.copytree(content, path)
        else:
            shutil.copyfile(content, path)
    return [p for p, _ in copies]
