"""CSV tables of numbers: reading named columns with errors naming file, line and column, and writing
columns atomically."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output, read_text


def read_csv_header(path: str | Path) -> list[str]:
    """The column names of a CSV file's header line; InputError naming the file when it cannot be read."""
    return [h.strip() for h in next(csv.reader(read_text(path).splitlines()), [])]


def read_csv_columns(path: str | Path, columns: Sequence[str], min_rows: int,
                     limits: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
    """Read the named numeric columns of a CSV file with a header line (other columns ignored).

    Values stay in the file's units. Raises InputError naming the file, line and column for a
    missing or repeated column, a line with more fields than the header, a non-number, a NaN, a time
    (first column) that does not increase strictly, a value larger in magnitude than its column's
    ``limits`` (in the file's unit), or fewer than ``min_rows`` data lines.
    """
    source = str(path)
    rows = csv.reader(read_text(path).splitlines())
    header = [h.strip() for h in next(rows, [])]
    repeated = sorted({h for h in header if header.count(h) > 1})
    if repeated:
        raise InputError(f"column {repeated[0]!r} appears {header.count(repeated[0])} times; expected each name once",
                         source=source, key="line 1")
    missing = [c for c in columns if c not in header]
    if missing:
        raise InputError(f"missing column(s) {', '.join(missing)}; expected a header with {','.join(columns)}, "
                         f"got {','.join(header) or 'an empty file'}", source=source, key="line 1")
    cols = [header.index(c) for c in columns]
    data: list[list[float]] = []
    for line, row in enumerate(rows, start=2):
        if not row or not "".join(row).strip():
            continue
        if len(row) > len(header):
            raise InputError(f"{len(row)} fields; expected {len(header)}, as the header has", source=source,
                             key=f"line {line}")
        values = []
        for name, col in zip(columns, cols):
            where = f"line {line}, column {name}"
            if col >= len(row):
                raise InputError(f"missing value (expected {len(header)} columns)", source=source, key=where)
            try:
                value = float(row[col])
            except ValueError:
                raise InputError(f"expected a number, got {row[col]!r}", source=source, key=where) from None
            if not math.isfinite(value):
                raise InputError(f"expected a finite number, got {row[col]!r}", source=source, key=where)
            if limits and name in limits and not abs(value) <= limits[name]:
                raise InputError(f"{row[col]!r} is beyond any plausible value; expected at most {limits[name]:g} in "
                                 f"magnitude", source=source, key=where)
            values.append(value)
        if data and not values[0] > data[-1][0]:
            raise InputError(f"time must increase strictly: {values[0]!r} s follows {data[-1][0]!r} s",
                             source=source, key=f"line {line}, column {columns[0]}")
        data.append(values)
    if len(data) < min_rows:
        raise InputError(f"too short: {len(data)} samples, expected at least {min_rows}", source=source)
    arr = np.array(data).reshape(-1, len(columns))
    return {name: arr[:, j] for j, name in enumerate(columns)}


def write_csv_columns(path: Path, columns: Mapping[str, np.ndarray]) -> None:
    """Write the columns as CSV with a header line of their names, atomically."""
    with atomic_output(path) as tmp:
        np.savetxt(tmp, np.column_stack(list(columns.values())), delimiter=",", fmt="%.10g",
                   header=",".join(columns), comments="")
