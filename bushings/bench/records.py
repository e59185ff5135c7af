"""Bench records: reading a ``t_s,e_mm,F_N`` CSV into SI arrays, and simulating a record.

The CSV is in the thesis's units (s, mm, N); a :class:`BenchRecord` holds SI (s, m, N), converted
once here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from elastokin.bushings.bank import BushingBank
from elastokin.bushings.bench.programmes import RECORD_LIMITS
from elastokin.bushings.parameters import ChannelParams
from elastokin.core.tables import read_csv_columns
from elastokin.core.units import MM

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


def read_bench_csv(path: str | Path) -> BenchRecord:
    """Read a ``t_s,e_mm,F_N`` bench record; errors name the file, line and column."""
    cols = read_csv_columns(path, RECORD_COLUMNS, MIN_SAMPLES, limits=RECORD_LIMITS)
    return BenchRecord(source=Path(path).name, t=cols["t_s"], e=cols["e_mm"] * MM, F=cols["F_N"])


def sample_steps(t: np.ndarray) -> np.ndarray:
    """The step [s] before each sample of times ``t`` [s]: the first sample reached in one step of
    the record's first interval."""
    return np.diff(t, prepend=t[0] - (t[1] - t[0]))


def simulate_record(channels: Sequence[ChannelParams], t: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Forces (T, M) of M channels driven through the deflections e (T,) [m] at times t (T,) [s].

    Each channel starts virgin and at rest at e = 0; the first sample is reached in one step of
    the record's first interval. The time base may be non-uniform (e.g. a subsampled record).
    """
    bank = BushingBank(channels)
    dts = sample_steps(t)
    out = np.empty((len(t), bank.size))
    row = np.empty(bank.size)
    for i in range(len(t)):
        row.fill(e[i])
        out[i] = bank.step(row, dts[i])[0]
    return out
