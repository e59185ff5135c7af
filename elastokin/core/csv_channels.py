"""A measurement's CSV columns declared by name, unit, sign and offset, and converted once to the
unit its channel is kept in: the ``time`` and ``columns`` of a K&C rig export's META.yaml and of a
measured road scenario's cases, read one way for both.

The declaration (YAML)::

    time: {column: Time, unit: s, offset: 0.0}             # offset optional
    columns:
      SWA: {channel: steering_wheel, unit: deg, sign: -1}  # sign (±1) and offset optional
"""

from __future__ import annotations

import dataclasses
from typing import Any, Mapping

import numpy as np

from elastokin.core import units
from elastokin.core.documents import Document, Fields

#: Keys of the time declaration and of a column's.
TIME_KEYS = ("column", "unit", "offset")
COLUMN_KEYS = ("channel", "unit", "sign", "offset")
#: What errors call the time base.
TIME_NAME = "t_s"


@dataclasses.dataclass(frozen=True)
class Column:
    """One CSV column and how it becomes a channel: (value + offset) × factor."""

    name: str          #: CSV header
    channel: str       #: the channel (:data:`TIME_NAME` for the time)
    factor: float      #: channel units per column unit, times the sign
    offset: float      #: added to the column's values [column unit]
    limit: float       #: largest plausible magnitude [column unit]

    def convert(self, values: np.ndarray) -> np.ndarray:
        """The column's values in the channel's unit and sign."""
        return (values + self.offset) * self.factor

    def invert(self, values: np.ndarray) -> np.ndarray:
        """The column's values that :meth:`convert` gives ``values`` (in the channel's unit and sign) from."""
        return values / self.factor - self.offset


def unit_factor(f: Fields, channel: str, unit: str) -> float:
    """``unit`` per the unit declared at ``f``'s ``unit`` key, for ``channel`` kept in ``unit``;
    InputError at ``unit`` for an unknown unit or one of another dimension."""
    declared = f.text("unit")
    if declared not in units.UNITS:
        raise f.fail("unit", f"unknown unit {declared!r}; expected one of {', '.join(units.UNITS)}")
    if units.dimension(declared) != units.dimension(unit):
        fits = ", ".join(u for u in units.UNITS if units.dimension(u) == units.dimension(unit))
        raise f.fail("unit", f"unit mismatch: {declared!r} does not convert to {unit}, the unit of {channel}; "
                             f"expected one of {fits}")
    return units.factor(declared, unit)


def time_column(f: Fields) -> Column:
    """The time declaration ``f`` (keys :data:`TIME_KEYS`) as a column in seconds."""
    return Column(f.text("column"), TIME_NAME, unit_factor(f, "the time", "s"), f.number("offset", 0.0),
                  units.plausible(f.text("unit")))


def column(doc: Document, path: tuple, name: str, item: Any, known: Mapping[str, str], expected: str) -> Column:
    """The declaration ``item`` of CSV column ``name`` (at ``path`` of ``doc``) as a column of one of
    the ``known`` channels (channel → its unit); InputError naming the key for an unknown key or
    channel (``expected`` says which are known), a unit that does not convert, a sign not ±1."""
    f = Fields.of(doc, path, item, COLUMN_KEYS)
    channel = f.text("channel")
    if channel not in known:
        raise f.fail("channel", f"unknown channel {channel!r}; expected {expected}")
    factor = unit_factor(f, channel, known[channel])
    sign = f.number("sign", 1.0)
    if sign not in (1.0, -1.0):
        raise f.fail("sign", f"expected +1 or -1, got {sign!r}")
    return Column(str(name), channel, sign * factor, f.number("offset", 0.0), units.plausible(f.text("unit")))


def declared_columns(doc: Document, path: tuple, raw: Any, time: Column, known: Mapping[str, str],
                     expected: str) -> list[Column]:
    """The ``columns`` mapping ``raw`` (at ``path``): each CSV column's :func:`column`, no channel
    twice and none on the time column; InputError naming the key otherwise."""
    if not isinstance(raw, Mapping) or not raw:
        raise doc.error(path, f"expected a mapping of CSV columns to {{{', '.join(COLUMN_KEYS)}}}, got {raw!r}")
    if time.name in raw:
        raise doc.error(path + (time.name,), "this is the time column (key `time`); it cannot be a signal too")
    out: list[Column] = []
    for name, item in raw.items():
        c = column(doc, path + (name,), name, item, known, expected)
        twice = next((o for o in out if o.channel == c.channel), None)
        if twice is not None:
            raise doc.error(path + (name, "channel"), f"channel {c.channel} is already given by column {twice.name!r}")
        out.append(c)
    return out
