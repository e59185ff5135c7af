"""What the virtual rigs share of a truth file: its numbers, its ``measurement`` imperfections over a
rig's defaults, and a sensor's quantisation."""

from __future__ import annotations

import math
from typing import Any, Mapping, Sequence

import numpy as np

from elastokin.core.errors import InputError


def truth_number(value: Any, source: str, key: str, *, lower: float = -math.inf, positive: bool = False) -> float:
    """A finite number of a truth file, ``>= lower`` (or ``> 0`` if ``positive``); errors name file and key."""
    ok = (not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)
          and (value > 0.0 if positive else value >= lower))
    if not ok:
        expected = "> 0" if positive else f">= {lower:g}" if lower > -math.inf else ""
        raise InputError(f"expected a finite number {expected}".rstrip() + f", got {value!r}", source=source, key=key)
    return float(value)


def truth_values(entry: Mapping[str, Any], params: Sequence[Any], source: str, key: str) -> dict[str, float]:
    """The values of a truth file's cause ``entry`` for its catalogue ``params``: finite numbers; a
    family's shape parameter left out takes its default (the family's first form)."""
    return {p.name: truth_number(entry[p.name], source, f"{key}.{p.name}") if p.name in entry else float(p.default)
            for p in params}


def required(params: Sequence[Any]) -> list[str]:
    """The names of ``params`` a truth file must give (those without a default)."""
    return [p.name for p in params if p.default is None]


def parse_measurement(raw: Any, defaults: Mapping[str, float], source: str) -> dict[str, float]:
    """A truth's ``measurement`` mapping over the rig's defaults: known keys, numbers >= 0."""
    measurement = dict(defaults)
    if raw is None:
        return measurement
    if not isinstance(raw, Mapping):
        raise InputError(f"expected a mapping, got {raw!r}", source=source, key="measurement")
    for key, value in raw.items():
        if key not in defaults:
            raise InputError(f"unknown key {key!r}; expected {', '.join(defaults)}", source=source,
                             key=f"measurement.{key}")
        measurement[key] = truth_number(value, source, f"measurement.{key}", lower=0.0)
    return measurement


def quantise(x: np.ndarray, step: float) -> np.ndarray:
    """``x`` on a sensor's resolution grid (unchanged for a zero step)."""
    return np.round(x / step) * step if step > 0.0 else x
