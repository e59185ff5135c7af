"""The TeimOrbit property-file format that Adams and MF-Tyre files share (``.tir`` tyres, ``.bus``
bushings), read into sections of numbers, texts and tables, with the line of every key and table,
so that each error names the file, line, section and key.

The format: ``[SECTION]`` headers; ``KEY = value`` lines, the value a number (``1.5``, ``-2e-3``,
``1.0D+03``) or a quoted text (``'meter'``); ``$`` starts a comment anywhere outside quotes, ``!``
at the start of a line; ``(SUBBLOCK)`` lines (``(COMMENTS)``) group what follows and are read
through; a table holds a ``{column names}`` line and rows of numbers, or rows of quoted texts
(``{comment_string}``). Some sections are tables without their ``{...}`` line (a ``.bus`` file's
curves, written by hand): the reader is told which. Keys and section names are case-insensitive
(read upper case).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from elastokin.core.errors import InputError
from elastokin.core.files import is_file, read_text

_SECTION = re.compile(r"^\[([A-Za-z0-9_]+)\]$")
_SUBBLOCK = re.compile(r"^\(([A-Za-z0-9_]+)\)$")
_ENTRY = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)\s*=\s*(.*)$")
_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eEdD][-+]?\d+)?$")
_QUOTED = re.compile(r"^'[^']*'$")


@dataclass(frozen=True)
class TeimOrbitFile:
    """A read property file: ``values[section][key]`` (a float or a text), ``tables[section]``
    (rows × columns of numbers, with ``columns[section]`` their names; empty names for a table
    written without its ``{...}`` line), ``texts[section]`` (the rows of a table of quoted texts),
    ``lines[(section, key)]`` the line of each key, ``table_lines[section]`` of each table row and
    ``sections[section]`` of each section's header."""

    path: Path
    values: dict[str, dict[str, float | str]]
    tables: dict[str, np.ndarray] = field(default_factory=dict)
    columns: dict[str, tuple[str, ...]] = field(default_factory=dict)
    lines: dict[tuple[str, str], int] = field(default_factory=dict)
    texts: dict[str, list[str]] = field(default_factory=dict)
    table_lines: dict[str, list[int]] = field(default_factory=dict)
    sections: dict[str, int] = field(default_factory=dict)   #: the line of each section's header

    def where(self, section: str, key: str | None = None, row: int | None = None) -> str:
        """``file:line`` of a key or a table row (the file alone if it has no line)."""
        if key is not None:
            line = self.lines.get((section, key))
        else:
            rows = self.table_lines.get(section, [])
            line = rows[row] if row is not None and 0 <= row < len(rows) else None
        return f"{self.path}:{line}" if line else str(self.path)

    def error(self, section: str, key: str, message: str) -> InputError:
        """An InputError naming this file, the key's line (if it has one), the section and the key."""
        return InputError(message, source=self.where(section, key), key=f"[{section}] {key}")

    def row_error(self, section: str, row: int, message: str) -> InputError:
        """An InputError naming this file, the table row's line, the section and the row (0-based)."""
        return InputError(message, source=self.where(section, row=row), key=f"[{section}] row {row + 1}")

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
            raise self.error(section, key, "missing; expected a quoted text" +
                             ("" if section in self.values else f" (the file has no [{section}] section)"))
        return value if isinstance(value, str) else f"{value:g}"


def read_teim_orbit(path: str | Path, what: str, headerless_tables: tuple[str, ...] = (),
                    kind: type[TeimOrbitFile] = TeimOrbitFile) -> TeimOrbitFile:
    """Read the property file ``path`` (``what`` names its kind in errors: "tyre property file")
    as a ``kind`` (a subclass, with the file type's own accessors).

    ``headerless_tables``: sections whose rows of numbers may come without a ``{...}`` line.
    InputError naming the file, line, section and key for a line that is neither a section, an
    entry, a sub-block, a comment nor a table row, a key or section given twice, a value that is
    neither a finite number nor a quoted text, or a table row of another width or of non-numbers.
    """
    path = Path(path)
    if not is_file(path):
        raise InputError(f"no such {what}", source=str(path))
    values: dict[str, dict[str, float | str]] = {}
    lines: dict[tuple[str, str], int] = {}
    rows: dict[str, list[list[float]]] = {}
    texts: dict[str, list[str]] = {}
    row_lines: dict[str, list[int]] = {}
    columns: dict[str, tuple[str, ...]] = {}
    sections: dict[str, int] = {}
    section, table = "", ""   # the section, and the table its rows go to ("" outside a table)
    for number, raw in enumerate(read_text(path).removeprefix("\ufeff").splitlines(), start=1):
        line = _without_comment(raw).strip()
        where = f"{path}:{number}"
        if not line:
            continue
        header = _SECTION.match(line)
        if header:
            section, table = header[1].upper(), ""
            if section in values:
                raise InputError(f"section [{section}] appears twice", source=where)
            values[section] = {}
            sections[section] = number
            continue
        if not section:
            raise InputError(f"{line[:40]!r} before any [SECTION]", source=where)
        if _SUBBLOCK.match(line):
            table = ""
            continue
        if line.startswith("{"):
            table = section
            if table in columns:
                raise InputError(f"a second table in [{section}]", source=where, key=f"[{section}]")
            columns[table] = tuple(line.strip("{}").split())
            rows[table], row_lines[table] = [], []
            continue
        if table and not rows[table] and (table in texts or _QUOTED.match(line)):
            if _QUOTED.match(line):   # a table of texts: it ends at the first line that is not one
                texts.setdefault(table, []).append(line[1:-1].strip())
                continue
            table = ""
        if not table and section in columns and _NUMBER.match(line.split()[0]):
            raise InputError(f"a row of numbers after the table of [{section}] ended (at a sub-block or a text row); "
                             f"expected one table per section", source=where, key=f"[{section}]")
        if not table and section in headerless_tables and not values[section] and _NUMBER.match(line.split()[0]):
            table = section
            columns[table] = ("",) * len(line.split())
            rows[table], row_lines[table] = [], []
        if table:
            rows[table].append(_table_row(line, len(columns[table]), where, section))
            row_lines[table].append(number)
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
    tables = {s: np.array(r, dtype=float).reshape(len(r), len(columns[s])) for s, r in rows.items() if s not in texts}
    return kind(path, values, tables, {s: c for s, c in columns.items() if s not in texts}, lines, texts,
                row_lines, sections)


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
