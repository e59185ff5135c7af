"""The nuisance columns a K&C diagnosis fits with every prediction (:class:`elastokin.diagnosis.kc_scorer.Scorer`),
over the compared rows (samples × channels). Most of them act on one channel alone (a transducer's
gain, a cross-talk): those are held as that channel's samples, not as a (samples × channels) array
of zeros around them, so that the columns' products with a residual, their Gram matrix and their
sum cost and hold a channel's worth each (the campaign's 60-odd gains had doubled the diagnosis's
memory as dense arrays)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np


@dataclass(frozen=True)
class OneChannel:
    """A column that is zero but on one channel: that channel's index and its values there (N,)."""

    channel: int
    values: np.ndarray


class Columns:
    """Columns over (n, C) rows, in their order: dense ones (n, C) and :class:`OneChannel` ones."""

    def __init__(self, columns: Sequence[np.ndarray | OneChannel], shape: tuple[int, int]):
        self.shape = shape
        #: which columns are one channel's
        self.one = np.array([isinstance(c, OneChannel) for c in columns], dtype=bool).reshape(-1)
        #: the dense columns in order, in blocks (each (k, n, C)): extended by a block, not copied whole
        self.blocks = (np.array([c for c in columns if not isinstance(c, OneChannel)]).reshape(-1, *shape),)
        #: (Ks, n) the one-channel columns and (Ks,) their channels, in order
        self.single = np.array([c.values for c in columns if isinstance(c, OneChannel)]).reshape(-1, shape[0])
        self.channel = np.array([c.channel for c in columns if isinstance(c, OneChannel)], dtype=np.int64)

    def __len__(self) -> int:
        return len(self.one)

    def extended(self, dense: Sequence[np.ndarray]) -> "Columns":
        """These columns and the ``dense`` ones (each (n, C)) after them, sharing these columns' arrays
        (copied, the campaign's dense columns were 57 MiB of the shipped dataset's diagnosis's peak)."""
        out = Columns([], self.shape)
        out.one = np.concatenate([self.one, np.zeros(len(dense), dtype=bool)])
        out.blocks = (*self.blocks, np.reshape(dense, (-1, *self.shape)))
        out.single, out.channel = self.single, self.channel
        return out

    def on_channel(self, c: int) -> np.ndarray:
        """(Kd, n) the dense columns on channel ``c``."""
        return np.vstack([b[:, :, c] for b in self.blocks])

    def _flat(self) -> list[np.ndarray]:
        """Each block's dense columns (k, n·C), each raveled as a residual is."""
        return [b.reshape(len(b), self.shape[0] * self.shape[1]) for b in self.blocks]

    def products(self, r: np.ndarray) -> np.ndarray:
        """(K,) each column's product with ``r`` (n, C)."""
        r = r.reshape(self.shape)
        out = np.empty(len(self))
        out[~self.one] = np.concatenate([f @ r.ravel() for f in self._flat()])
        out[self.one] = np.einsum("kn,nk->k", self.single, r[:, self.channel])
        return out

    def gram(self) -> np.ndarray:
        """(K, K) the columns' products with each other."""
        flat, one = self._flat(), self.one
        across = np.empty((int((~one).sum()), len(self.single)))
        for c in np.unique(self.channel):   # channel by channel: not the dense columns copied for each one-channel one
            on = self.channel == c
            across[:, on] = self.on_channel(c) @ self.single[on].T
        out = np.empty((len(self), len(self)))
        out[np.ix_(~one, ~one)] = np.block([[a @ b.T for b in flat] for a in flat])
        out[np.ix_(~one, one)] = across
        out[np.ix_(one, ~one)] = across.T
        out[np.ix_(one, one)] = (self.channel[:, None] == self.channel[None, :]) * (self.single @ self.single.T)
        return out

    def combine(self, coef: np.ndarray) -> np.ndarray:
        """(n, C) the columns weighted by ``coef`` (K,) and summed."""
        coef = np.asarray(coef, dtype=float)
        out = np.zeros(self.shape)
        for b, dense in zip(self.blocks, np.split(coef[~self.one], np.cumsum([len(b) for b in self.blocks])[:-1])):
            out += np.tensordot(dense, b, axes=1)
        np.add.at(out.T, self.channel, coef[self.one][:, None] * self.single)
        return out
