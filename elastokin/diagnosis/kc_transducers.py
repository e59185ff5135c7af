"""A K&C rig's transducers, nuisances the diagnosis fits beside the causes (issue 53 item 2). Written
from what a rig is known to do, apart from the virtual rig's chain (:mod:`elastokin.diagnosis.rig_chain`):

- a rig input is servoed: the controller makes its own transducer's reading (a pad's position or
  load cell, the rack's) follow the command, so the recording holds the command while a transducer
  reading (1 + g) × the truth gives the car the command / (1 + g). A load cell is calibrated to
  ±0.5–2 %; 1.5 % on the pads' lateral forces scales a lateral-force test's whole response by 1.5 %
  and reads as the car's lateral stiffness;
- a measured channel's transducer reads (1 + g) × the truth (its calibration), and some see another
  quantity of their wheel (:data:`CROSSTALK`: a wheel-angle head's toe its camber, a pad's vertical
  load cell its lateral force), before the acquisition's filter and delay.

Each is a column: the compared rows' derivative with respect to it, (N, C) in the channels' units.
A moved input's comes from a baseline run of the tests it moves in with its command × (1 +
:data:`STEP`) (first order, the car's own nonlinearity in it); a channel's gain is its own
prediction; a cross-talk is the other quantity (the prediction, or the rig's command for an input)
placed in the channel. The columns are projected out of every residual with the acquisition's
(:class:`elastokin.diagnosis.kc_fits.Scorer`), so that each cause is fitted jointly with them, and
what the data tell of each is reported. A gain is common to every test of its channel while a car's
cause acts on each test its own way, so the campaign tells most causes from the gains; one that acts
as a gain does (every response of a channel, or to an input, scaled alike) is not told from it: the
fit leaves it to the gain, and a static calibration of the transducer separates them.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from elastokin.diagnosis.kc_layout import Job, Layout
from elastokin.vehicle.scenarios.channels import INPUT_CHANNELS, channel_quantity, channel_wheel

#: The relative step of an input's command in the runs that give its gain's column.
STEP = 0.01
#: Which quantity a measured channel's transducer is taken to see of its wheel besides its own.
CROSSTALK = {"toe": "camber", "pad_fz": "pad_fy"}
#: A transducer's error is worth a word beyond this many standard uncertainties and this share (a
#: good transducer's calibration).
SAID_STD, SAID_SHARE = 3.0, 0.002
INPUT_GAIN, GAIN, CROSS = "input gain", "gain", "cross-talk"


@dataclass(frozen=True)
class Reading:
    """A transducer's error as fitted beside a model."""

    kind: str             #: INPUT_GAIN, GAIN or CROSS
    channel: str          #: the channel it reads (a rig input's for INPUT_GAIN)
    source: str | None    #: the quantity of the same wheel a cross-talk sees
    value: float          #: a gain g (it reads (1 + g) × the truth), or a cross-talk's coefficient
    #: [the channel's unit per the source's]
    std: float            #: its standard uncertainty

    @property
    def said(self) -> bool:
        """Whether the data show it (beyond SAID_STD standard uncertainties and SAID_SHARE)."""
        return abs(self.value) > max(SAID_STD * self.std, SAID_SHARE)

    @property
    def label(self) -> str:
        """``pad_fy_fl (input gain)``, ``toe_fl sees camber``, ``camber_fr (gain)``."""
        return f"{self.channel} sees {self.source}" if self.kind == CROSS else f"{self.channel} ({self.kind})"


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
    scale = np.where(np.array(INPUT_CHANNELS) == channel, 1.0 + STEP, 1.0)
    return [replace(layout.tests[i].job, scenario=layout.tests[i].job.scenario.with_inputs_scaled(scale))
            for i in tests]


def input_column(stepped_rows: np.ndarray, baseline: np.ndarray) -> np.ndarray:
    """(N, C) the rows' derivative with respect to an input command's scale, from its stepped runs'
    rows (NaN in the tests it does not move: 0 there) and the baseline's."""
    return np.nan_to_num((stepped_rows - baseline) / STEP, nan=0.0)


def reading_columns(layout: Layout, baseline: np.ndarray) -> dict[Key, np.ndarray]:
    """Each measured channel's gain and cross-talk columns (module docstring), from the baseline's
    rows (N, C) and the rig's recorded commands."""
    index = {c: i for i, c in enumerate(layout.channels)}
    out: dict[Key, np.ndarray] = {}
    for i, c in enumerate(layout.channels):
        own = np.zeros_like(baseline)
        own[:, i] = baseline[:, i]
        out[(GAIN, c, None)] = own
        source = CROSSTALK.get(channel_quantity(c))
        seen = f"{source}_{channel_wheel(c)}" if source else None
        if seen in index or (seen in INPUT_CHANNELS and layout.inputs is not None):
            other = np.zeros_like(baseline)
            other[:, i] = baseline[:, index[seen]] if seen in index else layout.inputs[:, INPUT_CHANNELS.index(seen)]
            out[(CROSS, c, source)] = other
    return out


def reading(key: Key, coef: float, std: float) -> Reading:
    """The transducer error a fitted coefficient of ``key``'s column stands for: the coefficient for a
    measured channel's gain or cross-talk; for an input, the gain g whose servo gives the car its
    command × (1 + ``coef``) (1 + coef = 1 / (1 + g)), its uncertainty carried to first order."""
    kind, channel, source = key
    if kind == INPUT_GAIN:
        return Reading(kind, channel, None, 1.0 / (1.0 + coef) - 1.0, std / (1.0 + coef) ** 2)
    return Reading(kind, channel, source, coef, std)
