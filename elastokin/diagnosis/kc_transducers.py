"""A K&C rig's transducers, nuisances the diagnosis fits beside the causes (issue 53 item 2). Written
from what a rig is known to do, apart from the virtual rig's chain (:mod:`elastokin.diagnosis.rig_chain`):

- a rig input is servoed: the controller makes its own transducer's reading (a pad's position or
  load cell, the rack's) follow the command, so the recording holds the command while a transducer
  reading (1 + g) × the truth gives the car the command / (1 + g). A load cell is calibrated to
  ±0.5–2 %; 1.5 % on the pads' lateral forces scales a lateral-force test's whole response by 1.5 %
  and reads as the car's lateral stiffness;
- a measured channel's transducer reads (1 + g) × the truth (its calibration), and some see another
  quantity of their wheel (:data:`CROSSTALK`: a wheel-angle head's toe its camber, a pad's vertical
  load cell its lateral force), before the acquisition's filter and delay;
- a transducer's zero drifts through a recording (its amplifier's temperature): a straight line in
  time, its rate [the channel's unit per minute] fitted per channel in each recording whose tests
  all repeat their input (:func:`drift_columns`), where a car's response repeats cycle after cycle
  and a drift does not; in a recording of a held input (a rack step) the car's own slow response
  (a relaxation) would be taken for it, and no drift is fitted there.

Each is a column: the compared rows' derivative with respect to it, (N, C) in the channels' units.
A moved input's comes from a baseline run of the tests it moves in with its command × (1 +
:data:`STEP`) (first order, the car's own nonlinearity in it); a channel's gain is its own
prediction; a cross-talk is the other quantity (the prediction, or the rig's command for an input)
placed in the channel; a drift is the time through its recording. The columns are projected out
of every residual with the acquisition's (:class:`elastokin.diagnosis.kc_scorer.Scorer`), so that
each cause is fitted jointly with them, each within its :func:`bounds` (:func:`bounded_solve`), and
what the data tell of each is reported. A gain is common to every test of its channel while a
car's cause acts on each test its own way, so the campaign tells most causes from the gains; one
that acts as a gain does (every response of a channel, or to an input, scaled alike) is not told
from it: the fit leaves it to the gain, and a static calibration of the transducer separates them
(:mod:`elastokin.diagnosis.kc_rig_or_car`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Mapping, Sequence

import numpy as np

from elastokin.diagnosis.kc_columns import OneChannel
from elastokin.diagnosis.kc_layout import Job, Layout
from elastokin.diagnosis.kc_rig_mechanics import BY_KEY, RIG
from elastokin.vehicle.scenarios.channels import INPUT_CHANNELS, channel_quantity, channel_wheel

#: The relative step of an input's command in the runs that give its gain's column.
STEP = 0.01
#: Which quantity a measured channel's transducer is taken to see of its wheel besides its own.
CROSSTALK = {"toe": "camber", "pad_fz": "pad_fy"}
#: A transducer's error is worth a word beyond this many standard uncertainties and this share (a
#: good transducer's calibration).
SAID_STD, SAID_SHARE = 3.0, 0.002
INPUT_GAIN, GAIN, CROSS, DRIFT = "input gain", "gain", "cross-talk", "drift"
#: What a reading held at its bound says beside its value.
AT_BOUND = " (at its bound: the data would have it larger)"
#: The largest transducer error fitted (a gain, or a cross-talk's coefficient, both ratios): a rig's
#: calibration is good to ±0.5–2 % (issue 53). What a larger one would take (a test's whole response
#: scaled, a channel's every response tilted) is left to the car's causes: unbounded, the camber heads'
#: gains took a strut top's 3.4 mm as 7–10 % (a hardpoint draw of the slow suite, "unexplained"). A
#: cause is fitted jointly with them (:meth:`elastokin.diagnosis.kc_scorer.Scorer.fit_effects`).
CALIBRATION_BOUND = 0.025


@dataclass(frozen=True)
class Reading:
    """A rig's error as fitted beside a model: a transducer's, or an element of the rig's own
    mechanics (:mod:`elastokin.diagnosis.kc_rig_mechanics`)."""

    kind: str             #: INPUT_GAIN, GAIN, CROSS, DRIFT or RIG
    channel: str          #: the channel it reads (a rig input's for INPUT_GAIN; the rig file key for RIG)
    source: str | None    #: the quantity of the same wheel a cross-talk sees; the recording a drift is in
    value: float          #: a gain g (it reads (1 + g) × the truth), a cross-talk's coefficient [the
    #: channel's unit per the source's], a drift's rate [the channel's unit per minute] or a rig element's
    #: value [its unit]
    std: float            #: its standard uncertainty
    #: held at its bound (:func:`bounds`): the data would have it larger, beyond a calibrated rig's
    #: (a transducer out of calibration, or a car cause acting as its error)
    at_bound: bool = False
    unit: str = ""        #: a drift's channel's unit

    def moved(self, by: float, std: float, at_bound: bool) -> "Reading":
        """This error with its column's coefficient moved ``by`` (:func:`reading`: an input's gain is
        not its coefficient), ``std`` the coefficient's standard uncertainty then (a drift's at least
        its quantity's spread, :func:`drift_spread`), ``at_bound`` whether it is then held at its bound."""
        if self.kind == INPUT_GAIN:
            coef = 1.0 / (1.0 + self.value) - 1.0 + by
            return reading(self.key, coef, std, at_bound)
        return replace(self, value=self.value + by, std=max(std, self.std) if self.kind == DRIFT else std,
                       at_bound=at_bound and self.value + by != 0.0)

    @property
    def key(self) -> "Key":
        """Its column's key: (kind, channel, source)."""
        return self.kind, self.channel, self.source

    @property
    def said(self) -> bool:
        """Whether the data show it (beyond SAID_STD standard uncertainties and SAID_SHARE, a rig
        element's floor; a drift's uncertainty alone)."""
        floor = BY_KEY[self.channel].floor if self.kind == RIG else 0.0 if self.kind == DRIFT else SAID_SHARE
        return abs(self.value) > max(SAID_STD * self.std, floor)

    @property
    def label(self) -> str:
        """``pad_fy_fl (input gain)``, ``toe_fl sees camber``, ``camber_fr (gain)``, ``toe_fl's zero drifts
        through 02_kc_roll``, ``the pads' friction``."""
        if self.kind == RIG:
            return BY_KEY[self.channel].label
        if self.kind == DRIFT:
            return f"{self.channel}'s zero drifts through {self.source}"
        return f"{self.channel} sees {self.source}" if self.kind == CROSS else f"{self.channel} ({self.kind})"

    @property
    def text(self) -> str:
        """Its value for people: a gain or a cross-talk (both ratios) in %, a drift in its channel's
        unit per minute, a rig element in its unit."""
        value = (f"{self.value:.3g} ± {self.std:.2g} {BY_KEY[self.channel].unit}" if self.kind == RIG
                 else f"{self.value:+.3g} ± {self.std:.2g} {self.unit}/min" if self.kind == DRIFT
                 else f"{100 * self.value:+.2f} ± {100 * self.std:.2g} %")
        return value + (AT_BOUND if self.at_bound else "")


Key = tuple[str, str, "str | None"]


def moved(layout: Layout) -> dict[str, list[int]]:
    """Each input channel that moves in some test (its command not zero throughout): the tests it
    moves in."""
    out: dict[str, list[int]] = {}
    for i, t in enumerate(layout.tests):
        (case,) = t.job.scenario.cases
        values = case.table.values if case.table is not None else np.asarray(case.pattern)[None, :]
        for j in np.flatnonzero(np.any(values != 0.0, axis=0)):
            out.setdefault(INPUT_CHANNELS[j], []).append(i)
    return out


def stepped(layout: Layout, channel: str, tests: list[int]) -> list[Job]:
    """The baseline runs of ``tests`` with ``channel``'s command × (1 + :data:`STEP`)."""
    return inputs_scaled([layout.tests[i].job for i in tests], {channel: 1.0 + STEP})


def inputs_scaled(jobs: Sequence[Job], factors: Mapping[str, float]) -> list[Job]:
    """``jobs`` with each rig input's command × its factor in ``factors`` (rig input channel ->
    factor; the others × 1): what the car gets from servos whose own transducers misread."""
    scale = np.array([factors.get(ch, 1.0) for ch in INPUT_CHANNELS])
    return [replace(j, scenario=j.scenario.with_inputs_scaled(scale)) for j in jobs]


def input_column(stepped_rows: np.ndarray, baseline: np.ndarray) -> np.ndarray:
    """(N, C) the rows' derivative with respect to an input command's scale, from its stepped runs'
    rows (NaN in the tests it does not move: 0 there) and the baseline's."""
    return np.nan_to_num((stepped_rows - baseline) / STEP, nan=0.0)


def reading_columns(layout: Layout, baseline: np.ndarray) -> dict[Key, OneChannel]:
    """Each measured channel's gain and cross-talk columns (module docstring), from the baseline's
    rows (N, C) and the rig's recorded commands: each on its channel alone."""
    index = {c: i for i, c in enumerate(layout.channels)}
    out: dict[Key, OneChannel] = {}
    for i, c in enumerate(layout.channels):
        out[(GAIN, c, None)] = OneChannel(i, baseline[:, i].copy())
        seen = seen_channel(c)
        if seen in index or (seen in INPUT_CHANNELS and layout.inputs is not None):
            source = baseline[:, index[seen]] if seen in index else layout.inputs[:, INPUT_CHANNELS.index(seen)]
            out[(CROSS, c, CROSSTALK[channel_quantity(c)])] = OneChannel(i, source.copy())
    return out


def seen_channel(channel: str) -> str | None:
    """The channel of the quantity ``channel``'s transducer sees of its wheel besides its own
    (:data:`CROSSTALK`), if any."""
    source = CROSSTALK.get(channel_quantity(channel))
    return f"{source}_{channel_wheel(channel)}" if source else None


def as_read(change: np.ndarray, keys: Sequence[Key], coef: np.ndarray, channels: Sequence[str]) -> np.ndarray:
    """A ``change`` (N, C) of the rows the gains' and cross-talks' columns were taken at (the
    baseline's, :func:`reading_columns`) as the transducers read it with the errors ``coef`` (one per
    key of ``keys``, the others' ignored): each channel's change × (1 + its gain) plus its cross-talk's
    share of its source's change (a rig command's: none). Those columns are the baseline's rows: a
    prediction away from it (a cause's toe change) is read through the same gains."""
    index = {c: i for i, c in enumerate(channels)}
    out = change.copy()
    for (kind, channel, _), a in zip(keys, coef):
        i, seen = index.get(channel), index.get(seen_channel(channel) or "")
        if kind == GAIN:
            out[:, i] += a * change[:, i]
        elif kind == CROSS and seen is not None:
            out[:, i] += a * change[:, seen]
    return out


def drift_columns(layout: Layout) -> dict[Key, OneChannel]:
    """Each measured channel's drift in each recording whose tests all repeat their input (module
    docstring): the time through the recording [min] on its rows, on that channel alone (its mean,
    and so its start, goes with the recording's zero; through the acquisition's filter and delay, as
    every column goes, a straight line stays one, late by a constant the zero takes too)."""
    clock = layout.clock
    out: dict[Key, OneChannel] = {}
    for k in np.unique(clock.recording):
        on = clock.recording == k
        if all(layout.tests[i].period > 0 for i in np.unique(layout.test[on])):
            minutes = np.where(on, clock.time_s / 60.0, 0.0)
            out.update({(DRIFT, c, clock.names[k]): OneChannel(i, minutes) for i, c in enumerate(layout.channels)})
    return out


def drift_spread(readings: list[Reading]) -> list[Reading]:
    """``readings`` with each drift's uncertainty at least the RMS of its quantity's drifts over its
    channels and recordings: a slow noise (1/f: a rig's temperature, its amplifiers' flicker) wanders
    over a recording as a drift does, more than the noise's model (white and first-order
    autoregressive) says where it fits a short correlation time (on the virtual rig's typical chain,
    3-4 × more on three quantities); the RMS counts that wander, and a drift is said only where it
    stands out of its quantity's (of 12, one beyond 6 × the others' spread reaches 3 of it)."""
    rates: dict[str, list[float]] = {}
    for g in readings:
        if g.kind == DRIFT:
            rates.setdefault(channel_quantity(g.channel), []).append(g.value)
    spread = {q: math.sqrt(float(np.mean(np.square(v)))) for q, v in rates.items()}
    return [replace(g, std=max(g.std, spread[channel_quantity(g.channel)])) if g.kind == DRIFT else g
            for g in readings]


def reading(key: Key, coef: float, std: float, at_bound: bool = False, unit: str = "") -> Reading:
    """The transducer error a fitted coefficient of ``key``'s column stands for: the coefficient for a
    measured channel's gain or cross-talk and a rig element's value; for an input, the gain g whose
    servo gives the car its command × (1 + ``coef``) (1 + coef = 1 / (1 + g)), its uncertainty
    carried to first order. ``at_bound``: the fit held it at its bound; ``unit``: a drift's channel's."""
    kind, channel, source = key
    if kind == INPUT_GAIN:
        return Reading(kind, channel, None, 1.0 / (1.0 + coef) - 1.0, std / (1.0 + coef) ** 2, at_bound)
    return Reading(kind, channel, source, coef, std, at_bound, unit if kind == DRIFT else "")


def bounded_solve(gram: np.ndarray, seen: np.ndarray, limits: np.ndarray, inverse: np.ndarray | None = None,
                  start: np.ndarray | None = None) -> np.ndarray:
    """The coefficients (K,) of columns (their ``gram`` matrix (K, K), their products ``seen`` (K,) with
    what they fit) that fit it best within ``limits`` (K, 2) (:func:`bounds`; those whose limits meet
    held there): the least-squares fit (``inverse``: the Gram matrix's pseudo-inverse, used when
    nothing is held), then an active set: each coefficient beyond its limits held at the nearer and
    the others refitted, a held one whose objective's slope points inwards let go, until none is
    beyond and none would leave its limit (the bounded least squares' optimum, from any start).
    ``start`` (K,): the coefficients held at a limit to begin with (their limit, NaN for the free),
    those of a fit of nearly the same problem: a screening's next hypothesis, a few steps from it."""
    lo, hi = limits.T
    fixed = lo == hi
    at = np.full(len(seen), np.nan) if start is None else \
        np.where(np.isfinite(start) & ((start == lo) | (start == hi)), start, np.nan)
    at[fixed] = lo[fixed]   # each coefficient's held value; NaN where free
    tol = 1e-9 * float(np.abs(seen).max(initial=0.0))   # a slope that is rounding's
    for _ in range(2 * len(seen) + 1):
        free = np.isnan(at)
        coef = np.where(free, 0.0, at)
        if free.all() and inverse is not None:
            coef = inverse @ seen
        elif free.any():
            rest = seen[free] - gram[np.ix_(free, ~free)] @ at[~free]
            coef[free] = np.linalg.pinv(gram[np.ix_(free, free)]) @ rest
        over = free & ((coef < lo) | (coef > hi))
        if over.any():
            at[over] = np.clip(coef[over], lo[over], hi[over])
            continue
        slope = gram @ coef - seen   # the half squared error's gradient
        inwards = ~free & ~fixed & (((at == lo) & (slope < -tol)) | ((at == hi) & (slope > tol)))
        if not inwards.any():
            return coef
        at[np.argmax(np.where(inwards, np.abs(slope), -1.0))] = np.nan
    if start is not None:   # a start too far from the optimum to reach it in as many steps as a cold one
        return bounded_solve(gram, seen, limits, inverse)
    return np.clip(coef, lo, hi)


def held_at_limits(coef: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """(K,) which coefficients ``coef`` (K,) a :func:`bounded_solve` within ``limits`` (K, 2) holds at
    one (within rounding's 1e-12 of it)."""
    return coef != np.clip(coef, limits[:, 0] + 1e-12, limits[:, 1] - 1e-12)


def bounds(key: Key) -> tuple[float, float]:
    """The bounds of a transducer's or the rig's coefficient (its column's scale); a drift's none."""
    kind, name, _ = key
    if kind == RIG:
        return 0.0, BY_KEY[name].bound
    if kind == DRIFT:
        return -math.inf, math.inf
    return -CALIBRATION_BOUND, CALIBRATION_BOUND
