"""What both diagnoses decide alike: which tests are held out from the fits, which tests the baseline
does not fit (any test: the baseline fitted nothing), and, from the held-out error before and after
the best cause, the noise floor and those misfits, whether the cause is named, nothing significant
is missing, or the mismatch is real but unexplained."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
from scipy.special import gammaincc

#: Relative held-out error reduction below which a cause explains nothing significant.
MIN_GAIN = 0.10
#: A cause is named when the mismatch beyond noise it leaves on held-out tests is at most this
#: fraction of the baseline's (i.e. it explains at least 1 − 0.35² ≈ 88 % of the excess variance).
MAX_EXCESS_LEFT = 0.35
#: A cause that leaves more is still named, as explaining the mismatch in part, when the mismatch is
#: significant and it leaves at most this fraction of its excess (explains at least 75 % of the excess
#: variance): another form of a catalogued effect that its family follows only in part is its family's,
#: not "unexplained" (single_verdict).
MAX_EXCESS_LEFT_IN_PART = 0.5
#: A baseline whose held-out error is within this factor of the noise floor fits the data.
NOISE_FACTOR = 1.5
#: The verdicts that name no cause (any other verdict is a catalogue id).
NOT_NAMED = ("none", "unexplained")
#: Relative increase of an error per parameter fitted, in the rankings: of two causes that fit
#: alike, the one with fewer parameters first.
PARAMETER_PENALTY = 0.02


def penalised(error: float, fitted: int) -> float:
    """``error`` raised by PARAMETER_PENALTY per parameter ``fitted``: what the rankings order by."""
    return error * (1.0 + PARAMETER_PENALTY * fitted)


def split(n_tests: int) -> np.ndarray:
    """Held-out tests: every other one, starting with the second (the first is the virgin part's)."""
    return np.arange(n_tests) % 2 == 1


class Outcome:
    """What a diagnosis concluded: ``verdict`` is a catalogue id (two joined by "+" when two causes
    are named), ``none`` or ``unexplained``."""

    verdict: str

    @property
    def named(self) -> bool:
        """True when a catalogue cause (or two) is named."""
        return self.verdict not in NOT_NAMED


#: A stretch of a test is misfit when, in one channel, its mean squared residual is at least
#: NOISE_FACTOR² (in units of the noise) and the chance that the noise alone shows such a stretch
#: somewhere in the test is below this (χ² with as many degrees as independent samples in the window,
#: times the windows scanned in every channel).
MISFIT_CHANCE = 1e-6


def misfit_stretch(residual: np.ndarray, dof: Callable[[int], np.ndarray] | None = None
                   ) -> tuple[float, int, int, int]:
    """The least likely stretch of a test's ``residual`` under its noise (rows: samples in order;
    columns: channels; in units of their noise; NaN counted as no excess): (a bound on the chance
    that noise alone shows one as unlikely somewhere in the test, first row, last row, channel).
    ``dof``: for a window's width [samples], each channel's degrees of freedom of its mean square
    (default: the width, white noise; fewer for a correlated noise,
    :meth:`elastokin.diagnosis.kc_noise.NoiseModel.window_dof`).
    Windows of a twentieth of the test (at least 10 samples) are scanned in every channel; the
    chance of the least likely is multiplied by the number of windows scanned (overlapping windows
    are alike: a bound, not an estimate); the stretch is where its channel stays above half its
    peak."""
    n, channels = residual.shape
    if n == 0:
        return 1.0, 0, 0, 0
    width = min(n, max(10, n // 20))
    squares = np.vstack([np.zeros((1, channels)), np.cumsum(np.nan_to_num(residual) ** 2, axis=0)])
    mean = (squares[width:] - squares[:-width]) / width                     # (windows, channels)
    # the chance of a mean of `width` unit-variance squares at least this large (χ²), where it matters
    k = np.full(channels, float(width)) if dof is None else np.asarray(dof(width), dtype=float)
    tail = np.where(mean >= NOISE_FACTOR ** 2, gammaincc(0.5 * k, 0.5 * k * mean), 1.0)
    # beyond the floating-point range the tail is 0 for several windows: the largest mean among them
    least = np.where(tail == tail.min(), mean, -np.inf)
    k, channel = np.unravel_index(int(np.argmax(least)), tail.shape)
    chance = min(1.0, float(tail[k, channel]) * channels * mean.shape[0])
    if chance >= 1.0:
        return 1.0, 0, n - 1, int(channel)
    above = mean[:, channel] >= 0.5 * mean[k, channel]
    first, last = k, k
    while first > 0 and above[first - 1]:
        first -= 1
    while last < len(above) - 1 and above[last + 1]:
        last += 1
    return chance, int(first), int(last + width - 1), int(channel)


def misfit(error: float, chance: float, floor: float = 1.0) -> bool:
    """Whether the baseline does not fit a test: its whole error beyond NOISE_FACTOR times the noise
    ``floor`` (the criterion the held-out set passes or fails as a whole), or a stretch of it the
    noise alone would show with a ``chance`` below MISFIT_CHANCE (:func:`misfit_stretch`)."""
    return error > NOISE_FACTOR * floor or chance < MISFIT_CHANCE


def explained(verdict: str, before: float, after: float, floor: float, misfit_left: bool = False
              ) -> tuple[str, float]:
    """How much of the mismatch a verdict explains: ``full``, ``partial`` or ``none``, and the share
    of the baseline's excess over the noise (in variance, on the held-out tests) that the named
    cause removes: 1 − excess_after² / excess_before². A named cause explains partly when the
    held-out error it leaves is beyond NOISE_FACTOR times the noise ``floor``, ``misfit_left`` (a
    test it still does not fit), or it leaves more of the excess than MAX_EXCESS_LEFT (named by
    :func:`single_verdict` in part); "none" (nothing missing) is fully explained by the baseline,
    "unexplained" not at all."""
    if verdict == "none":
        return "full", 1.0
    if verdict == "unexplained":
        return "none", 0.0
    in_part = (after > NOISE_FACTOR * floor or misfit_left
               or _excess(after, floor) > MAX_EXCESS_LEFT * _excess(before, floor))
    return ("partial" if in_part else "full"), share(before, after, floor)


def _excess(error: float, floor: float) -> float:
    """The part of a relative RMS ``error`` beyond the noise ``floor``: √(error² − floor²), or 0."""
    return math.sqrt(max(error ** 2 - floor ** 2, 0.0))


def decide(before: float, after: float, floor: float, misfit_seen: bool = False) -> str:
    """``named``, ``none`` or ``unexplained`` from held-out errors before and after the best cause
    and the noise floor (all relative RMS); ``misfit_seen``: the baseline does not fit some test
    (:func:`misfit`, training or held out): then a baseline that fits the held-out tests taken
    together is not "none" but "unexplained" (a local misfit, on which no cause can be judged)."""
    if after <= before * (1.0 - MIN_GAIN) and _excess(after, floor) <= MAX_EXCESS_LEFT * _excess(before, floor):
        return "named"
    return "none" if before <= NOISE_FACTOR * floor and not misfit_seen else "unexplained"


def single_verdict(before: float, after: float, floor: float, misfit_seen: bool = False) -> str:
    """The verdict on the best single cause: :func:`decide`'s, or ``named`` in part where decide
    finds it unexplained but the baseline's mismatch is significant (``before`` beyond NOISE_FACTOR
    × the ``floor``) and the cause removes most of it (leaves at most MAX_EXCESS_LEFT_IN_PART of its
    excess, which from there is a gain beyond MIN_GAIN; :func:`explained` then says ``partial``).
    Pairs keep decide's stricter test; rivals of a cause named in part are judged by this one
    (:func:`alike`)."""
    verdict = decide(before, after, floor, misfit_seen)
    if (verdict == "unexplained" and before > NOISE_FACTOR * floor
            and _excess(after, floor) <= MAX_EXCESS_LEFT_IN_PART * _excess(before, floor)):
        return "named"
    return verdict


def told_apart(rival: float, best: float, floor: float) -> bool:
    """Whether the data tell the best cause (held-out error ``best``) from a ``rival`` (its own): the
    best beats the rival as a cause must beat the baseline (:func:`decide`), not by a share of the
    noise that another draw of it could reverse."""
    return decide(rival, best, floor) == "named"


def alike(before: float, rival: float, best: float, floor: float, in_part: bool = False) -> bool:
    """Whether a rival cause (held-out error ``rival``) is one the tests cannot tell from the best
    (``best``): it would be named on its own against the baseline's ``before`` as the best was (fully
    by :func:`decide`; ``in_part``, a best named only by :func:`single_verdict`: in part by it too),
    and the best does not beat it as a cause must (:func:`told_apart`)."""
    named = single_verdict if in_part else decide
    return named(before, rival, floor) == "named" and not told_apart(rival, best, floor)


@dataclass(frozen=True)
class Separation:
    """An extra test, the dataset's lacking, and how far apart two causes' predictions of it lie."""

    test: str              #: its name (a scenario, a bench programme)
    path: Path             #: its file
    difference: float      #: RMS of the predictions' difference [× the noise], each channel's mean removed

    @property
    def separates(self) -> bool:
        """Whether the test, measured, would tell the two apart as the diagnosis tells causes apart:
        the wrong one's error there, √(1 + difference²) × the noise, told from the right one's, the
        noise (:func:`told_apart`: a difference of at least 0.48)."""
        return told_apart(math.hypot(1.0, self.difference), 1.0, 1.0)


def difference(a: np.ndarray, b: np.ndarray, noise: np.ndarray | float) -> float:
    """RMS of (a − b) / noise over samples (rows) and channels (columns), each channel's mean removed
    (as a zero error would be)."""
    d = (a - b) / noise
    d = d - d.mean(axis=0)
    return math.sqrt(float(np.mean(d ** 2))) if d.size else 0.0


def second_cause_wanted(before: float, after: float, floor: float, misfit_left: bool = False) -> bool:
    """Whether to look for two causes at once: what the best single cause leaves (its held-out error
    ``after``, or the baseline's ``before`` if it makes things worse) is beyond NOISE_FACTOR times
    the noise ``floor``, or a test is still not fitted (whether or not the cause explains anything:
    two effects can hide each other, e.g. a preload and an asymmetry of opposite sides)."""
    return min(after, before) > NOISE_FACTOR * floor or misfit_left


def pair_named(before: float, single: float, pair: float, floor: float) -> bool:
    """Whether two causes are named: the pair's held-out error ``pair`` beats the best single
    cause's ``single`` as a cause must beat the baseline (:func:`decide`: what the second cause
    removes is most of what the first left, not a fit of the noise), and the pair explains the
    baseline's mismatch ``before`` as one cause must."""
    return decide(single, pair, floor) == "named" and decide(before, pair, floor) == "named"


def share(before: float, after: float, floor: float) -> float:
    """The share of the excess over the noise ``floor`` (in variance) that takes the error from
    ``before`` to ``after``: 1 − excess_after² / excess_before², within [0, 1]."""
    excess_before = before ** 2 - floor ** 2
    if excess_before <= 0.0:
        return 1.0
    return min(max(1.0 - max(after ** 2 - floor ** 2, 0.0) / excess_before, 0.0), 1.0)


def pair_shares(before: float, alone: Sequence[float], pair: float, floor: float) -> tuple[float, float]:
    """Each of two causes' share of the mismatch: its gain averaged over the two orders of adding
    them (from the held-out errors ``before``, with each cause ``alone`` and with the ``pair``); the
    two add up to the pair's share. Two effects that hide each other share the whole alike."""
    whole = share(before, pair, floor)
    a, b = (share(before, e, floor) for e in alone)
    return 0.5 * (a + whole - b), 0.5 * (b + whole - a)
