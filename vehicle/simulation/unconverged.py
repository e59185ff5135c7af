"""The bushing steps of a run whose implicit solve stopped at its iteration cap with a residual left:
counted per bushing direction, with the worst residual and the samples it came in, so that a run
says where its bushing forces are less exact than the solve's tolerance (it never stops for it)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from typing import Any, Mapping

import numpy as np

from elastokin.core.errors import ElastokinWarning
from elastokin.core.units import factor


class UnconvergedBushingSteps(ElastokinWarning):
    """A run whose bushing solve stopped at its iteration cap in some steps (the message says where
    and by how much); its forces there are less exact than the tolerance, the run goes on."""


@dataclass(frozen=True)
class UnconvergedSteps:
    """One bushing direction's unconverged steps over a run."""

    channel: str              #: ``bushing.direction``
    unit: str                 #: of its deflection: ``m`` or ``rad``
    steps: int                #: steps whose solve stopped with a residual left
    worst_residual: float     #: the largest residual [m or rad]: nodes placed to this instead of the tolerance
    tolerance: float          #: the solve's tolerance [m or rad]
    case: int                 #: the case (1-based) of the worst step
    from_s: float             #: the worst step came between these times of the run [s] (one block of samples)
    to_s: float

    def describe(self) -> str:
        """``"e2_front_left.y: 12 steps, worst residual 3.1e-04 mm (tolerance 1e-05 mm) in t = 2.000–3.000 s,
        case 1"``."""
        unit = "deg" if self.unit == "rad" else "mm"
        scale = factor(self.unit, unit)
        return (f"{self.channel}: {self.steps} step{'s' * (self.steps != 1)}, worst residual "
                f"{self.worst_residual * scale:.3g} {unit} (tolerance {self.tolerance * scale:.3g} {unit}) in "
                f"t = {self.from_s:.3f}–{self.to_s:.3f} s, case {self.case}")

    def to_record(self) -> dict[str, Any]:
        """The fields as a recording's status record keeps them (JSON: a NaN or infinite residual as
        the string 'nan', 'inf')."""
        record = asdict(self)
        residual = self.worst_residual
        record["worst_residual"] = residual if math.isfinite(residual) else str(residual)
        return record

    @classmethod
    def from_record(cls, record: Mapping[str, Any]) -> UnconvergedSteps:
        """The inverse of :meth:`to_record` (KeyError, TypeError or ValueError for a record that is not one)."""
        return cls(str(record["channel"]), str(record["unit"]), int(record["steps"]), float(record["worst_residual"]),
                   float(record["tolerance"]), int(record["case"]), float(record["from_s"]), float(record["to_s"]))


def worst_first(steps: tuple[UnconvergedSteps, ...]) -> list[UnconvergedSteps]:
    """The directions by their worst residual, the largest (or a NaN) first."""
    return sorted(steps, key=lambda s: (-s.worst_residual if s.worst_residual == s.worst_residual else -math.inf,
                                        s.channel))


def headline(steps: tuple[UnconvergedSteps, ...]) -> str:
    """``"12 bushing steps in 2 direction(s) did not converge to the solve's tolerance"``."""
    total = sum(s.steps for s in steps)
    return (f"{total} bushing step{'s' * (total != 1)} in {len(steps)} direction(s) did not converge to the "
            f"solve's tolerance (their forces are less exact than it)")


def summary(steps: tuple[UnconvergedSteps, ...], limit: int = 3) -> str:
    """One line for a warning: the :func:`headline`, then the ``limit`` worst directions."""
    more = f"; {len(steps) - limit} more direction(s)" if len(steps) > limit else ""
    return f"{headline(steps)}: {'; '.join(s.describe() for s in worst_first(steps)[:limit])}{more}"


class UnconvergedTally:
    """The unconverged steps of a run, gathered from its cars' banks after every block of samples."""

    def __init__(self) -> None:
        self._by_channel: dict[str, UnconvergedSteps] = {}

    def add(self, names: list[str], units: list[str], failed: np.ndarray, seen: np.ndarray, worst: np.ndarray,
            tolerances: np.ndarray, case: int, from_s: float, to_s: float) -> None:
        """Count a block of samples from ``from_s`` to ``to_s`` [s] of ``case``: ``failed`` (M,) the
        bank's counts now, ``seen`` (M,) the counts before the block (updated in place), ``worst`` (M,) the
        bank's worst residuals of the case so far [m or rad], ``tolerances`` (M,) its solves', ``names``
        (M,) its channels and ``units`` (M,) their deflections' (``m`` or ``rad``)."""
        for c in np.flatnonzero(failed != seen):
            name, new = names[c], int(failed[c] - seen[c])
            seen[c] = failed[c]
            old, residual = self._by_channel.get(name), float(worst[c])
            if old is None or (old.worst_residual == old.worst_residual   # a NaN, once found, is kept
                               and (residual != residual or residual > old.worst_residual)):
                # the case's worst grew in this block (a bank's worst only grows): it came in this block
                self._by_channel[name] = UnconvergedSteps(name, units[c], new + (old.steps if old else 0), residual,
                                                          float(tolerances[c]), case, from_s, to_s)
            else:
                self._by_channel[name] = replace(old, steps=old.steps + new)

    def steps(self) -> tuple[UnconvergedSteps, ...]:
        """Every direction with unconverged steps, in the order they were first found."""
        return tuple(self._by_channel.values())
