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
        #: (Kd, n, C) the dense columns, (Ks, n) the one-channel ones and (Ks,) their channels, in order
        self.dense = np.array([c for c in columns if not isinstance(c, OneChannel)]).reshape(-1, *shape)
        self.single = np.array([c.values for c in columns if isinstance(c, OneChannel)]).reshape(-1, shape[0])
        self.channel = np.array([c.channel for c in columns if isinstance(c, OneChannel)], dtype=np.int64)

    def __len__(self) -> int:
        return len(self.one)

    def extended(self, dense: Sequence[np.ndarray]) -> "Columns":
        """These columns and the ``dense`` ones (each (n, C)) after them."""
        out = Columns([], self.shape)
        out.one = np.concatenate([self.one, np.zeros(len(dense), dtype=bool)])
        out.dense = np.concatenate([self.dense, np.reshape(dense, (-1, *self.shape))])
        out.single, out.channel = self.single, self.channel
        return out

    def _flat(self) -> np.ndarray:
        """(Kd, n·C) the dense columns, each raveled as a residual is."""
        return self.dense.reshape(len(self.dense), self.shape[0] * self.shape[1])

    def products(self, r: np.ndarray) -> np.ndarray:
        """(K,) each column's product with ``r`` (n, C)."""
        r = r.reshape(self.shape)
        out = np.empty(len(self))
        out[~self.one] = self._flat() @ r.ravel()
        out[self.one] = np.einsum("kn,nk->k", self.single, r[:, self.channel])
        return out

    def gram(self) -> np.ndarray:
        """(K, K) the columns' products with each other."""
        flat, one = self._flat(), self.one
        across = np.empty((len(self.dense), len(self.single)))
        for c in np.unique(self.channel):   # channel by channel: not the dense columns copied for each one-channel one
            on = self.channel == c
            across[:, on] = self.dense[:, :, c] @ self.single[on].T
        out = np.empty((len(self), len(self)))
        out[np.ix_(~one, ~one)] = flat @ flat.T
        out[np.ix_(~one, one)] = across
        out[np.ix_(one, ~one)] = across.T
        out[np.ix_(one, one)] = (self.channel[:, None] == self.channel[None, :]) * (self.single @ self.single.T)
        return out

    def combine(self, coef: np.ndarray) -> np.ndarray:
        """(n, C) the columns weighted by ``coef`` (K,) and summed."""
        coef = np.asarray(coef, dtype=float)
        out = np.tensordot(coef[~self.one], self.dense, axes=1) if len(self.dense) else np.zeros(self.shape)
        np.add.at(out.T, self.channel, coef[self.one][:, None] * self.single)
        return out
