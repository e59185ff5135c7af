"""Scenarios as the API hands them out: read from a file or a built-in name, or written in Python."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from elastokin.core.documents import dump_yaml
from elastokin.core.errors import InputError
from elastokin.vehicle.scenarios import scenario_file
from elastokin.vehicle.scenarios.road_scenario import RoadScenario
from elastokin.vehicle.scenarios.scenario import Scenario

#: What the errors of a scenario written in Python name as their source.
PYTHON_SOURCE = "scenario_from"


def load_scenario(name_or_path: str | Path) -> Scenario | RoadScenario:
    """Load and validate a scenario file, or a built-in scenario by name.

    Args:
        name_or_path: a scenario file (format: ``scenarios/README.md``), or a built-in name:
            ``pumping``, ``kc/roll``, ``road/step_steer`` (:func:`elastokin.built_ins` lists them).

    Returns:
        A rig :class:`~elastokin.vehicle.scenarios.scenario.Scenario` or a
        :class:`~elastokin.vehicle.scenarios.road_scenario.RoadScenario` (SI inside).

    Raises:
        InputError: no such file or built-in (the built-in names listed), or a bad value, named by
            file:line, key and value.

    >>> import elastokin
    >>> s = elastokin.load_scenario("pumping")
    >>> s.type, len(s.cases), s.cases[0].parameters["amplitude_mm"]
    ('pumping', 6, 10)
    """
    return scenario_file.load_scenario(name_or_path)


def scenario_from(spec: Mapping[str, Any], folder: str | Path = ".") -> Scenario | RoadScenario:
    """A scenario written in Python: the mapping a scenario file holds (its keys and units, as in
    ``scenarios/README.md``), checked as a file is.

    Args:
        spec: e.g. ``{"name": "quick", "type": "pumping", "vehicle": "c_segment",
            "cases": [{"amplitude_mm": 20, "frequency_hz": 0.5}]}``.
        folder: where its relative paths (a vehicle file, a CSV input) are taken from.

    Returns:
        The scenario; its recordings carry its text (the mapping written as YAML).

    Raises:
        InputError: a bad key or value, named by its key (source ``scenario_from``).

    >>> import elastokin
    >>> s = elastokin.scenario_from({"name": "quick", "type": "pumping", "vehicle": "c_segment",
    ...                              "cases": [{"amplitude_mm": 20, "frequency_hz": 0.5}]})
    >>> s.name, s.cases[0].parameters["amplitude_mm"]
    ('quick', 20)
    """
    if not isinstance(spec, Mapping):
        raise InputError(f"expected a mapping of a scenario file's keys, got {type(spec).__name__}", source=PYTHON_SOURCE)
    name = spec.get("name", "scenario")
    path = Path(folder) / f"{name if isinstance(name, str) else 'scenario'}.yaml"
    return scenario_file.parse_scenario(dump_yaml(dict(spec), sort_keys=False), path, PYTHON_SOURCE)
