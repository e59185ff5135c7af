"""What both diagnoses decide alike: which tests are held out from the fits, and, from the held-out
error before and after the best cause and the noise floor, whether the cause is named, nothing
significant is missing, or the mismatch is real but unexplained."""

from __future__ import annotations

import math

import numpy as np

#: Relative held-out error reduction below which a cause explains nothing significant.
MIN_GAIN = 0.10
#: A cause is named when the mismatch beyond noise it leaves on held-out tests is at most this
#: fraction of the baseline's (i.e. it explains at least 1 − 0.35² ≈ 88 % of the excess variance).
MAX_EXCESS_LEFT = 0.35
#: A baseline whose held-out error is within this factor of the noise floor fits the data.
NOISE_FACTOR = 1.5
#: The verdicts that name no cause (any other verdict is a catalogue id).
NOT_NAMED = ("none", "unexplained")


def split(n_tests: int) -> np.ndarray:
    """Held-out tests: every other one, starting with the second (the first is the virgin part's)."""
    return np.arange(n_tests) % 2 == 1


class Outcome:
    """What a diagnosis concluded: ``verdict`` is a catalogue id, ``none`` or ``unexplained``."""

    verdict: str

    @property
    def named(self) -> bool:
        """True when a catalogue cause is named (then the outcome's ``best`` is it)."""
        return self.verdict not in NOT_NAMED


def decide(before: float, after: float, floor: float) -> str:
    """``named``, ``none`` or ``unexplained`` from held-out errors before and after the best cause
    and the noise floor (all relative RMS)."""
    excess_before = math.sqrt(max(before ** 2 - floor ** 2, 0.0))
    excess_after = math.sqrt(max(after ** 2 - floor ** 2, 0.0))
    if after <= before * (1.0 - MIN_GAIN) and excess_after <= MAX_EXCESS_LEFT * excess_before:
        return "named"
    return "none" if before <= NOISE_FACTOR * floor else "unexplained"
