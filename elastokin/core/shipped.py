"""Where the data shipped with the software lives: parameter sets, vehicles, scenarios, bench programmes.

In the source tree they are the repository's ``models/``, ``scenarios/`` and ``data/``; an installed
wheel carries the same folders inside the ``elastokin`` package (``pyproject.toml`` maps them there),
so that the scenarios' relative paths to the vehicles hold in both. Built-in files can be named: ``pumping``
for ``scenarios/pumping.yaml``, ``c_segment`` for ``models/vehicles/c_segment.yaml``.
"""

from __future__ import annotations

import importlib.resources
from pathlib import Path

from elastokin.core.errors import InputError
from elastokin.core.files import is_file

_PACKAGE = Path(str(importlib.resources.files("elastokin")))
#: The folder holding ``models/``, ``scenarios/`` and ``data/``: the package in a wheel, the repository in the source tree.
SHIPPED_ROOT = _PACKAGE if (_PACKAGE / "models").is_dir() else _PACKAGE.parent
#: The repository when running from its source tree (it holds ``.git``), else None.
SOURCE_TREE = _PACKAGE.parent if (_PACKAGE.parent / ".git").exists() else None
#: Named bushing parameter sets (``models/bushings/<name>.yaml``).
PARAMETER_SET_DIR = SHIPPED_ROOT / "models" / "bushings"
#: Bushing bench programmes (``models/bushings/benches/``).
BENCH_DIR = PARAMETER_SET_DIR / "benches"
#: Vehicle definitions (``models/vehicles/``).
VEHICLE_DIR = SHIPPED_ROOT / "models" / "vehicles"
#: The built-in default vehicle.
DEFAULT_VEHICLE = VEHICLE_DIR / "c_segment.yaml"
#: Tyre property files (``models/tyres/``, ``.tir``) and the default car's tyre.
TYRE_DIR = SHIPPED_ROOT / "models" / "tyres"
DEFAULT_TYRE = TYRE_DIR / "195_65R15.tir"
#: Rig scenarios (``scenarios/``) and the K&C campaign of the virtual rig (``scenarios/kc/``).
SCENARIO_DIR = SHIPPED_ROOT / "scenarios"
KC_SCENARIO_DIR = SCENARIO_DIR / "kc"
#: Sweep files (``scenarios/sweeps/``): they name scenarios, they are not scenarios.
SWEEP_DIR = SCENARIO_DIR / "sweeps"
#: The shipped example datasets (``data/rig/``: a bushing bench's and a K&C rig's measurements).
DATASET_DIR = SHIPPED_ROOT / "data" / "rig"


def built_in(folder: Path, suffix: str = ".yaml") -> list[str]:
    """The names of the ``suffix`` files shipped in ``folder`` (``kc/pumping`` for a file in a
    subfolder; the sweeps are not among the scenarios)."""
    return sorted(p.relative_to(folder).with_suffix("").as_posix() for p in folder.rglob(f"*{suffix}")
                  if folder == SWEEP_DIR or SWEEP_DIR not in p.parents)


def resolve(name_or_path: str | Path, folder: Path, what: str, base: Path | None = None,
            suffix: str = ".yaml") -> Path:
    """``name_or_path`` if it is a file (a relative path taken from ``base``, default the working
    folder); else the built-in ``folder/<name><suffix>`` of that name; else InputError naming the
    path and listing the built-in ones (``what``: what one of them is, e.g. ``scenario``)."""
    path = Path(name_or_path)
    path = base / path if base is not None and not path.is_absolute() else path
    if is_file(path):
        return path
    named = folder / f"{name_or_path}{suffix}"
    if path.suffix == "" and is_file(named) and folder.resolve() in named.resolve().parents:
        return named
    raise InputError(f"no such {what} file, and no built-in one of that name; built-in ones: "
                     f"{', '.join(built_in(folder, suffix))}", source=str(path))
