"""Bench records: reading a ``t_s,e_mm,F_N`` CSV into SI arrays, and simulating a record.

The CSV is in the thesis's units (s, mm, N); a :class:`BenchRecord` holds SI (s, m, N), converted
once here.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from bushings.bank import BushingBank
from vsim_core.errors import InputError
from bushings.parameters import ChannelParams

#: Columns a bench record must have (extra columns are ignored).
RECORD_COLUMNS = ("t_s", "e_mm", "F_N")
#: Fewest samples a record may have to be usable for identification.
MIN_SAMPLES = 10


@dataclass(frozen=True)
class BenchRecord:
    """One bench test: imposed deflection and measured force over time (SI)."""

    source: str        #: file name (or a label for synthetic records)
    t: np.ndarray      #: time [s], strictly increasing
    e: np.ndarray      #: deflection [m]
    F: np.ndarray      #: force [N]

    def __len__(self) -> int:
        return len(self.t)

    def subsampled(self, max_samples: int) -> "BenchRecord":
        """Every k-th sample (and the last) so that at most about ``max_samples`` remain."""
        stride = max(1, math.ceil(len(self.t) / max_samples))
        if stride == 1:
            return self
        idx = np.unique(np.r_[np.arange(0, len(self.t), stride), len(self.t) - 1])
        return BenchRecord(self.source, self.t[idx], self.e[idx], self.F[idx])


def read_csv_columns(path: str | Path, columns: Sequence[str], min_rows: int) -> dict[str, np.ndarray]:
    """Read the named numeric columns of a CSV file with a header line (other columns ignored).

    Values stay in the file's units. Raises InputError naming the file, line and column for a
    missing column, a non-number, a NaN, a time (first column) that does not increase strictly,
    or fewer than ``min_rows`` data lines.
    """
    path = Path(path)
    source = str(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", source=source) from exc
    rows = csv.reader(text.splitlines())
    header = [h.strip() for h in next(rows, [])]
    missing = [c for c in columns if c not in header]
    if missing:
        raise InputError(f"missing column(s) {', '.join(missing)}; expected a header with {','.join(columns)}, "
                         f"got {','.join(header) or 'an empty file'}", source=source, key="line 1")
    cols = [header.index(c) for c in columns]
    data: list[list[float]] = []
    for line, row in enumerate(rows, start=2):
        if not row or not "".join(row).strip():
            continue
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
            values.append(value)
        if data and not values[0] > data[-1][0]:
            raise InputError(f"time must increase strictly: {values[0]!r} s follows {data[-1][0]!r} s",
                             source=source, key=f"line {line}, column {columns[0]}")
        data.append(values)
    if len(data) < min_rows:
        raise InputError(f"too short: {len(data)} samples, expected at least {min_rows}", source=source)
    arr = np.array(data).reshape(-1, len(columns))
    return {name: arr[:, j] for j, name in enumerate(columns)}


def read_bench_csv(path: str | Path) -> BenchRecord:
    """Read a ``t_s,e_mm,F_N`` bench record; errors name the file, line and column."""
    cols = read_csv_columns(path, RECORD_COLUMNS, MIN_SAMPLES)
    return BenchRecord(source=Path(path).name, t=cols["t_s"], e=cols["e_mm"] * 1e-3, F=cols["F_N"])


def simulate_record(channels: Sequence[ChannelParams], t: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Forces (T, M) of M channels driven through the deflections e (T,) [m] at times t (T,) [s].

    Each channel starts virgin and at rest at e = 0; the first sample is reached in one step of
    the record's first interval. The time base may be non-uniform (e.g. a subsampled record).
    """
    bank = BushingBank(channels)
    dts = np.diff(t, prepend=t[0] - (t[1] - t[0]))
    out = np.empty((len(t), bank.size))
    row = np.empty(bank.size)
    for i in range(len(t)):
        row.fill(e[i])
        out[i] = bank.step(row, dts[i])[0]
    return out
