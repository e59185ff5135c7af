"""The industry's tyre property file (``.tir``, the TNO / Adams format) read into sections of
numbers and text, with the line of every key, so that each error names the file, line, section and
key.

The format: ``[SECTION]`` headers; ``KEY = value`` lines, the value a number (``1.5``, ``-2e-3``,
``1.0D+03``) or a quoted text (``'meter'``); ``$`` starts a comment anywhere outside quotes, ``!``
at the start of a line; a table section (``[SHAPE]``, ``[DEFLECTION_LOAD_CURVE]``, ...) holds a
``{column names}`` line and rows of numbers. Keys and section names are case-insensitive (read upper
case). Only SI files are read: ``[UNITS]`` must say meter, newton, radian, kg and second (a file in
other units is refused rather than converted key by key), and ``[MODEL] FITTYP`` must name a Magic
Formula this software evaluates (:data:`FITTYPS`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from elastokin.core.errors import InputError
from elastokin.core.files import is_file, read_text

#: FITTYP values read, with the Magic Formula version each names: MF 5.2 files say 6 (MF-Tyre 5.2,
#: Adams' PAC2002), 21 (MF-Tyre) or 52 (files written by hand), as MFeval reads them; MF-Tyre 5.0
#: and 5.1 files (FITTYP 5) differ in equations not checked here and stay refused.
FITTYPS = {6: "MF 5.2", 21: "MF 5.2", 52: "MF 5.2", 61: "MF 6.1", 62: "MF 6.2"}
#: [UNITS] keys and the SI names accepted for each (lower case).
SI_UNITS = {"LENGTH": ("meter", "metre", "m"), "FORCE": ("newton", "n"), "ANGLE": ("radian", "radians", "rad"),
            "MASS": ("kg", "kilogram"), "TIME": ("second", "sec", "s")}

_SECTION = re.compile(r"^\[([A-Za-z0-9_]+)\]$")
_ENTRY = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)\s*=\s*(.*)$")
_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eEdD][-+]?\d+)?$")


@dataclass(frozen=True)
class TirFile:
    """A read ``.tir`` file: ``values[section][key]`` (a float or a text), ``tables[section]`` (rows ×
    columns, with ``columns[section]`` their names), ``lines[(section, key)]`` the line of each key."""

    path: Path
    values: dict[str, dict[str, float | str]]
    tables: dict[str, np.ndarray] = field(default_factory=dict)
    columns: dict[str, tuple[str, ...]] = field(default_factory=dict)
    lines: dict[tuple[str, str], int] = field(default_factory=dict)

    def error(self, section: str, key: str, message: str) -> InputError:
        """An InputError naming this file, the key's line (if it has one), the section and the key."""
        line = self.lines.get((section, key))
        return InputError(message, source=f"{self.path}:{line}" if line else str(self.path), key=f"[{section}] {key}")

    def number(self, section: str, key: str, default: float | None = None) -> float:
        """The number at ``[section] key``; ``default`` if the key is absent and a default is given."""
        value = self.values.get(section, {}).get(key)
        if value is None:
            if default is not None:
                return default
            raise self.error(section, key, "missing; expected a number" +
                             ("" if section in self.values else f" (the file has no [{section}] section)"))
        if isinstance(value, str):
            raise self.error(section, key, f"expected a number, got '{value}'")
        return value

    def text(self, section: str, key: str, default: str | None = None) -> str:
        """The text at ``[section] key`` (quoted in the file); ``default`` if absent and given."""
        value = self.values.get(section, {}).get(key)
        if value is None:
            if default is not None:
                return default
            raise self.error(section, key, "missing; expected a quoted text")
        return value if isinstance(value, str) else f"{value:g}"

    @property
    def fittyp(self) -> int:
        """``[MODEL] FITTYP``: which Magic Formula the coefficients fit."""
        return int(self.number("MODEL", "FITTYP"))


def read_tir(path: str | Path) -> TirFile:
    """Read and check the ``.tir`` file ``path``: InputError naming the file, line, section and key
    for a line that is neither a section, an entry, a comment nor a table row, a key given twice,
    a value that is neither a finite number nor a quoted text, units other than SI, or a FITTYP
    other than :data:`FITTYPS`."""
    path = Path(path)
    if not is_file(path):
        raise InputError("no such tyre property file", source=str(path))
    values: dict[str, dict[str, float | str]] = {}
    lines: dict[tuple[str, str], int] = {}
    rows: dict[str, list[list[float]]] = {}
    columns: dict[str, tuple[str, ...]] = {}
    section = ""
    for number, raw in enumerate(read_text(path).splitlines(), start=1):
        line = _without_comment(raw).strip()
        where = f"{path}:{number}"
        if not line:
            continue
        header = _SECTION.match(line)
        if header:
            section = header[1].upper()
            if section in values or section in rows:
                raise InputError(f"section [{section}] appears twice", source=where)
            values[section] = {}
            continue
        if not section:
            raise InputError(f"{line[:40]!r} before any [SECTION]", source=where)
        if line.startswith("{"):
            columns[section] = tuple(line.strip("{}").split())
            rows[section] = []
            continue
        if section in rows:
            rows[section].append(_table_row(line, len(columns[section]), where, section))
            continue
        entry = _ENTRY.match(line)
        if entry is None:
            raise InputError(f"expected KEY = value, a [SECTION] or a comment, got {line[:60]!r}", source=where,
                             key=f"[{section}]")
        key = entry[1].upper()
        if key in values[section]:
            raise InputError(f"given twice (first at line {lines[(section, key)]})", source=where,
                             key=f"[{section}] {key}")
        values[section][key] = _value(entry[2].strip(), where, f"[{section}] {key}")
        lines[(section, key)] = number
    tir = TirFile(path, values, {s: np.array(r, dtype=float).reshape(len(r), len(columns[s])) for s, r in rows.items()},
                  columns, lines)
    _check_units(tir)
    if tir.number("MODEL", "FITTYP") not in FITTYPS:
        raise tir.error("MODEL", "FITTYP", f"unknown Magic Formula {tir.values['MODEL']['FITTYP']!r}; expected one of "
                                           f"{', '.join(f'{k} ({v})' for k, v in FITTYPS.items())}")
    return tir


def _without_comment(raw: str) -> str:
    """``raw`` without its comment: from ``$`` outside quotes, or the whole line if it starts with ``!``."""
    if raw.lstrip().startswith("!"):
        return ""
    quoted = False
    for i, char in enumerate(raw):
        if char == "'":
            quoted = not quoted
        elif char == "$" and not quoted:
            return raw[:i]
    return raw


def _number(text: str) -> float | None:
    """``text`` as a finite number (Fortran's D exponent too), or None."""
    value = float(text.replace("D", "e").replace("d", "e")) if _NUMBER.match(text) else math.nan
    return value if math.isfinite(value) else None


def _value(text: str, where: str, key: str) -> float | str:
    if len(text) >= 2 and text[0] == text[-1] == "'":
        return text[1:-1].strip()
    value = _number(text)
    if value is None:
        raise InputError(f"expected a finite number or a quoted text, got {text[:60]!r}", source=where, key=key)
    return value


def _table_row(line: str, width: int, where: str, section: str) -> list[float]:
    cells = line.split()
    if len(cells) != width or not all(_NUMBER.match(c) for c in cells):
        raise InputError(f"expected a row of {width} numbers, got {line[:60]!r}", source=where, key=f"[{section}]")
    row = [_number(c) for c in cells]
    if None in row:
        raise InputError(f"expected finite numbers, got {line[:60]!r}", source=where, key=f"[{section}]")
    return row


def _check_units(tir: TirFile) -> None:
    for key, accepted in SI_UNITS.items():
        unit = tir.text("UNITS", key).lower()
        if unit not in accepted:
            raise tir.error("UNITS", key, f"'{unit}' is not SI; expected '{accepted[0]}' (files in other units are "
                                          f"not converted: convert its dimensional keys first)")
