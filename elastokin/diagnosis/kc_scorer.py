"""Scoring predictions on a K&C campaign's compared rows (:mod:`elastokin.diagnosis.kc_diagnosis`):
residuals in units of the measured noise, each recording's zero errors removed, the rig's
acquisition, transducers and mechanics fitted with every prediction; errors per test and held out;
the uncertainties of what is fitted on them (:mod:`elastokin.diagnosis.kc_fits`)."""

from __future__ import annotations

import math
from typing import Callable, Mapping, Sequence

import numpy as np

from elastokin.diagnosis.fit_uncertainty import clustered_errors, standard_errors
from elastokin.diagnosis.kc_columns import Columns, OneChannel
from elastokin.diagnosis.kc_lags import PathResponse, Response, fit_response, paths
from elastokin.diagnosis.kc_layout import Layout
from elastokin.diagnosis.kc_noise import Segment, estimate_noise, white_noise
from elastokin.diagnosis.kc_rig_mechanics import RIG
from elastokin.diagnosis.kc_transducers import (INPUT_GAIN, Key, Reading, as_read, bounded_solve, bounds, drift_spread,
                                                held_at_limits, reading)


class Scorer:
    """Residuals in units of the measurement noise (white and coloured, :mod:`elastokin.diagnosis.kc_noise`):
    the prediction through each acquisition path's filter and delay (:mod:`elastokin.diagnosis.kc_lags`,
    estimated on the baseline; what is left of them to first order fitted with every prediction),
    each transducer's error fitted with every prediction (:mod:`elastokin.diagnosis.kc_transducers`),
    each channel's zero error in each recording removed; errors per test."""

    def __init__(self, layout: Layout, baseline: np.ndarray, heldout: np.ndarray,
                 transducers: Mapping[Key, np.ndarray | OneChannel] | None = None,
                 rig_at: Mapping[str, float] | None = None):
        """``baseline`` (N, C): the baseline's rows, the gains' and cross-talks' columns its own
        (:func:`~elastokin.diagnosis.kc_transducers.reading_columns`). ``transducers``: the rows'
        derivative (N, C) with respect to each transducer error fitted
        with every prediction (:mod:`elastokin.diagnosis.kc_transducers`; one channel's alone for a
        :class:`~elastokin.diagnosis.kc_columns.OneChannel`), as the rig's acquisition delivers it (here).
        ``rig_at``: each rig element's value [its unit] the runs were made at beyond the scenarios'
        rigs (default none): its column's coefficient is the change from it, held so that the element
        stays within its bounds, and its reading the value."""
        self.layout, self.heldout, self.baseline = layout, heldout, baseline
        self.held_rows = heldout[layout.test]
        self.paths = paths(layout.channels)
        self.response = Response(layout, self.paths)
        every = np.ones(len(baseline), dtype=bool)
        self.noise = white_noise(layout, layout.measured - baseline)   # the fit's weights, until the noise's model
        self.cutoffs_hz, self.delays_s = fit_response(self.response, layout.measured, baseline,
                                                      lambda r: self._zeroed(r, every, np.mean))
        delivered = self._delivered(baseline)
        #: the measurement noise, white and coloured (:mod:`elastokin.diagnosis.kc_noise`)
        self.noise_model = estimate_noise(layout, layout.measured - delivered)
        self.noise = self.noise_model.sigma
        self._rates, self._taps = self.response.rates(delivered), self.response.taps(delivered)
        self._transducers = {k: self._delivered_column(c) for k, c in (transducers or {}).items()}
        self._columns: dict[bytes, tuple[Columns, np.ndarray, np.ndarray]] = {}
        #: each transducer coefficient's value at no change from the runs (a rig element's: the value they were made at)
        self._at = np.array([(rig_at or {}).get(key[1], 0.0) if key[0] == RIG else 0.0 for key in self._transducers])
        #: the bounds of the transducers' coefficients (a rig input's gain, a rig's mechanics: held within them)
        self._bounds = np.array([bounds(key) for key in self._transducers]).reshape(-1, 2) - self._at[:, None]
        #: the last residual and raw residual (:meth:`_kept`): (the prediction, its rows and zero, the array)
        self._last: dict[str, tuple[np.ndarray, tuple, np.ndarray]] = {}
        #: per selection of rows, the nuisances' coefficients in its last fit (the next one's start)
        self._held: dict[bytes, np.ndarray] = {}

    def _delivered(self, rows: np.ndarray) -> np.ndarray:
        return self.response.apply(rows, self.cutoffs_hz, self.delays_s)

    def _delivered_column(self, column: np.ndarray | OneChannel) -> np.ndarray | OneChannel:
        """A column through the acquisition (linear in the rows, channel by channel)."""
        if not isinstance(column, OneChannel):
            return self._delivered(column)
        rows = np.zeros(self.layout.measured.shape)
        rows[:, column.channel] = column.values
        return OneChannel(column.channel, self._delivered(rows)[:, column.channel].copy())   # not a view holding all channels

    def _zeroed(self, r: np.ndarray, rows: np.ndarray, zero: Callable[..., np.ndarray],
                channel: int | None = None) -> np.ndarray:
        """``r`` (the selected rows; of one ``channel`` alone if given) with each channel's ``zero`` in
        each recording removed, in noise units."""
        rec = self.layout.recording[rows]
        for k in np.unique(rec):
            r[rec == k] -= zero(r[rec == k], axis=0)
        return r / (self.noise if channel is None else self.noise[channel])

    def _nuisance(self, rows: np.ndarray) -> tuple[Columns, np.ndarray, np.ndarray]:
        """On the selected rows, zeroed as the residual is: the columns fitted with every prediction
        (each path's taps (:meth:`elastokin.diagnosis.kc_lags.Response.taps`) on its channels in the
        tests of each sampling rate, then each transducer's), their Gram matrix and its
        pseudo-inverse; cached per selection."""
        key = rows.tobytes()
        if key not in self._columns:
            taps = [c[rows] for c in self._taps]
            # a sample's shift is a time at each sampling rate: the taps of the tests at each rate apart
            steps = np.round(np.array(self.response.steps), 9)[self.layout.test[rows]]
            columns = []
            for idx in self.paths.values():
                for step in np.unique(steps):
                    for tap in taps:
                        own = np.zeros_like(tap)
                        own[np.ix_(steps == step, idx)] = tap[np.ix_(steps == step, idx)]
                        columns.append(self._zeroed(own, rows, np.mean))
            columns += [OneChannel(c.channel, self._zeroed(c.values[rows], rows, np.mean, c.channel))
                        if isinstance(c, OneChannel) else self._zeroed(c[rows], rows, np.mean)
                        for c in self._transducers.values()]
            stack = Columns(columns, (int(rows.sum()), len(self.layout.channels)))
            gram = stack.gram()
            self._columns[key] = (stack, gram, np.linalg.pinv(gram))
        return self._columns[key]

    def _fitted(self, r: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, Columns, np.ndarray]:
        """The residual ``r`` on the selected rows with the nuisance columns fitted out, the columns
        and their coefficients. A transducer's gain or cross-talk is held within a calibrated rig's
        (:data:`~elastokin.diagnosis.kc_transducers.CALIBRATION_BOUND`), a rig's mechanics between none
        and a rig's most (:mod:`elastokin.diagnosis.kc_rig_mechanics`): beyond, one is held at its
        bound and the other columns refitted (:func:`~elastokin.diagnosis.kc_transducers.bounded_solve`),
        what is left being the car's."""
        stack, gram, inverse = self._nuisance(rows)
        if not len(stack):
            return r, stack, np.zeros(0)
        coef = self._solve(rows, len(stack), gram, stack.products(r), self._column_bounds(len(stack)), inverse)
        return r - stack.combine(coef).reshape(r.shape), stack, coef

    def _solve(self, rows: np.ndarray, nuisances: int, matrix: np.ndarray, products: np.ndarray, limits: np.ndarray,
               inverse: np.ndarray | None = None) -> np.ndarray:
        """:func:`~elastokin.diagnosis.kc_transducers.bounded_solve` of the ``nuisances`` on the selected
        ``rows`` (``matrix``'s first columns; any after them: a fit's effects), started from those
        the last fit on these rows held at a limit (the same optimum, in a few steps, not dozens)."""
        key = rows.tobytes()
        last = self._held.get(key)
        start = None if last is None else np.r_[last, np.full(len(products) - nuisances, np.nan)]
        coef = bounded_solve(matrix, products, limits, inverse, start)
        self._held[key] = coef[:nuisances]
        return coef

    def _read(self, coef: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
        """A change (N, C) of the baseline's rows as the transducers read it with the nuisances'
        coefficients ``coef`` (the taps' then the transducers'): the gains' and cross-talks' columns
        are the baseline's rows, so a prediction away from it (a cause's toe change) is read through
        the same errors (:func:`~elastokin.diagnosis.kc_transducers.as_read`)."""
        errors = coef[len(coef) - len(self._transducers):]
        return lambda change: as_read(change, list(self._transducers), errors, self.layout.channels)

    def _kept(self, what: str, predicted: np.ndarray, key: tuple, compute: Callable[[], np.ndarray]) -> np.ndarray:
        """``compute()``, read-only, or the last one of ``what`` if it was for the same ``predicted``
        (the very array) and ``key`` (a screening's fits share their base)."""
        last = self._last.get(what)
        if last is not None and last[0] is predicted and last[1] == key:
            return last[2]
        r = compute()
        r.flags.writeable = False
        self._last[what] = (predicted, key, r)
        return r

    def raw(self, predicted: np.ndarray, rows: np.ndarray, zero: Callable[..., np.ndarray] = np.mean) -> np.ndarray:
        """(n, C) (measured − predicted (N, C)) / noise on the ``rows`` selected (N,) as :meth:`residual`
        has it before the nuisances are fitted out (each recording's ``zero``, their means, removed);
        read-only, the last one kept (:meth:`_kept`)."""
        return self._kept("raw", predicted, (rows.tobytes(), zero),
                          lambda: self._zeroed(self.layout.measured[rows] - self._delivered(predicted)[rows], rows, zero))

    def seen(self, change: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """(n, C) how much a ``change`` (N, C) of any prediction lowers its :meth:`raw` residual (zeroed
        by the recordings' means) on the selected ``rows``: the residual is affine in the prediction."""
        return self._zeroed(self._delivered(change)[rows], rows, np.mean)

    def seen_left(self, change: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """(n, C) what :meth:`seen` of a ``change`` (N, C) leaves once the nuisances, each within its
        bounds, have taken what they can of it, as :meth:`residual` fits them out (what a rig's
        errors leave of a cause's change)."""
        return self._fitted(self.seen(change, rows), rows)[0]

    def fit_effects(self, predicted: np.ndarray, effects: Sequence[np.ndarray], rows: np.ndarray,
                    limits: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
        """The coefficients (E,) of ``effects`` (each (N, C): a change of ``predicted``) fitted on the
        selected ``rows`` jointly with the nuisances, each within its bounds and each effect's within
        ``limits`` (E, 2) (:func:`~elastokin.diagnosis.kc_transducers.bounded_solve`): what the
        prediction moved by them leaves (n, C), and each effect as the residual sees it with the
        nuisances' span projected out (n, C) (its uncertainty's column). Fitted jointly, not each
        effect's residual apart: a transducer's error at its bound in one and within it in the other
        would take a share of the effect (a hardpoint's tilt of camber as the camber heads' gain)."""
        stack, _, inverse = self._nuisance(rows)
        coef, left, seen, cross = self._joint(predicted, effects, rows, limits)
        projected = [d - stack.combine(inverse @ x).reshape(left.shape) for d, x in zip(seen, cross)]
        return coef[len(stack):], left, projected

    def _joint(self, predicted: np.ndarray, effects: Sequence[np.ndarray], rows: np.ndarray, limits: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, list[np.ndarray], np.ndarray]:
        """:meth:`fit_effects`'s fit: the nuisances' and the effects' coefficients (K + E,), what they
        leave (n, C), the effects as the raw residual sees them (each (n, C)) and their products with
        the nuisance columns (E, K). Fitted twice, the second time with the prediction's change from
        the baseline and the effects read through the transducers' errors the first found (:meth:`_read`)."""
        stack, gram, _ = self._nuisance(rows)
        k, m, seen, coef = len(stack), self.raw(predicted, rows), [self.seen(e, rows) for e in effects], None
        for _ in range(2):
            if coef is not None:
                read, change = self._read(coef[:k]), predicted - self.baseline
                m = self.raw(self.baseline + read(change), rows) if change.any() else m   # the screening's: none
                seen = [self.seen(read(e), rows) for e in effects]
            cross = np.array([stack.products(d) for d in seen]).reshape(len(seen), k)
            own = np.array([[float(np.sum(a * b)) for b in seen] for a in seen]).reshape(len(seen), len(seen))
            matrix = np.block([[gram, cross.T], [cross, own]])
            both = np.concatenate([stack.products(m), [float(np.sum(d * m)) for d in seen]])
            coef = self._solve(rows, k, matrix, both, np.vstack([self._column_bounds(k), limits]))
        left = m - stack.combine(coef[:k]).reshape(m.shape) - sum(c * d for c, d in zip(coef[k:], seen))
        return coef, left, seen, cross

    def nuisances(self, rows: np.ndarray) -> tuple[Columns, np.ndarray, np.ndarray, np.ndarray, list[Key | None]]:
        """The nuisance columns on the selected rows as :meth:`residual` fits them out; their Gram
        matrix (K, K); each one's bounds (K, 2); each one's coefficient of no error (K,: a rig
        element's minus the value the runs were made at); each one's key (None for the acquisition's taps)."""
        stack, gram, _ = self._nuisance(rows)
        taps = len(stack) - len(self._transducers)
        return (stack, gram, self._column_bounds(len(stack)), np.concatenate([np.zeros(taps), -self._at]),
                [None] * taps + list(self._transducers))

    def _column_bounds(self, columns: int) -> np.ndarray:
        """(columns, 2) the bounds of every nuisance coefficient: the acquisition's taps free, the
        transducers' and the rig's as :func:`~elastokin.diagnosis.kc_transducers.bounds` says."""
        return np.vstack([np.tile([-np.inf, np.inf], (columns - len(self._transducers), 1)), self._bounds])

    def responses(self, predicted: np.ndarray) -> list[PathResponse]:
        """Each acquisition path's response as fitted beside ``predicted`` (all rows): its filter,
        and its delay with what ``predicted``'s residual still shows of it to first order, with the
        standard uncertainty (the residual's own correlation along time counted)."""
        every = np.ones(len(predicted), dtype=bool)
        r = self.raw(predicted, every, np.mean)
        rates = self._zeroed(self._rates.copy(), every, np.mean)
        out = []
        for (name, idx), cutoff, delay in zip(self.paths.items(), self.cutoffs_hz, self.delays_s):
            d = rates[:, idx]
            dd = float(np.sum(d * d))
            a = float(np.sum(d * r[:, idx])) / dd if dd > 0.0 else 0.0
            std = math.sqrt(self.variances(r[:, idx] - a * d, [d], every, idx)[0])
            out.append(PathResponse(name, tuple(self.layout.channels[i] for i in idx), float(cutoff),
                                    float(delay - a), std))
        return out

    def rig_errors(self, predicted: np.ndarray, effects: Sequence[np.ndarray] = ()) -> list[Reading]:
        """Each rig error (a transducer's, an element of the rig's mechanics) fitted beside
        ``predicted`` (all rows) with the named causes, whose ``effects`` on the rows (N, C) in
        ``predicted`` are refitted with the errors (:meth:`fit_effects`'s fit: a cause that acts on the
        campaign much as an error does leaves both uncertain, and a cause's run a little off its
        value does not leave its change to the errors); with its standard uncertainty (the
        acquisition's taps and the causes fitted with it, the residual's correlation counted)."""
        if not self._transducers:
            return []
        every = np.ones(len(predicted), dtype=bool)
        coef, left, seen, _ = self._joint(predicted, effects, every, np.tile([-np.inf, np.inf], (len(effects), 1)))
        stack = self._nuisance(every)[0]
        first, end = len(stack) - len(self._transducers), len(stack)
        std = np.sqrt(self.variances(left, stack.extended(seen), every))[first:end]
        coef = coef[first:end]
        held = held_at_limits(coef, self._bounds)
        units = dict(zip(self.layout.channels, self.layout.units))
        return drift_spread([reading(key, float(at + c), float(s), bool(h and at + c != 0.0), units.get(key[1], ""))
                             for key, at, c, s, h in zip(self._transducers, self._at, coef, std, held)])

    def rig_errors_under_inputs(self, predicted: np.ndarray, effects: Sequence[np.ndarray],
                                rerun: Callable[[dict[str, float]], Sequence[np.ndarray]]
                                ) -> tuple[list[Reading], np.ndarray]:
        """:meth:`rig_errors`, the rig inputs' gains acting on the named causes' change too: their
        columns are the baseline's, so with causes (``effects`` not empty) and inputs' gains the data
        show (:attr:`~elastokin.diagnosis.kc_transducers.Reading.said`: the others' effect on the change
        is below their uncertainty's on the baseline), ``rerun(factors)`` gives the baseline's and the
        causes' rows (each (N, C)) with each input's command × its factor (the car's through a servo
        reading g high: 1 / (1 + g)), and the errors are read again with the change between them in
        the causes' stead; with the model read (N, C)."""
        readings = self.rig_errors(predicted, effects)
        factors = {g.channel: 1.0 / (1.0 + g.value) for g in readings if g.kind == INPUT_GAIN and g.said}
        if not (effects and factors):
            return readings, predicted
        base, named = rerun(factors)
        predicted = self.baseline + named - base
        return self.rig_errors(predicted, effects), predicted

    def variances(self, residual: np.ndarray, columns: list[np.ndarray] | Columns, rows: np.ndarray,
                  channels: np.ndarray | None = None) -> np.ndarray:
        """The variances of the coefficients of ``columns`` fitted to leave ``residual`` on the selected
        ``rows`` (each (rows, channels) over the same ``channels``, indices, default all, or raveled
        from them row by row; or the nuisances' :class:`~elastokin.diagnosis.kc_columns.Columns`):
        :func:`elastokin.diagnosis.fit_uncertainty.clustered_errors` with the tests as the independent
        units, the samples' correlation taken along time, channel by channel (coloured noise, a smooth
        model error)."""
        tests = self.layout.test[rows]
        along = lambda x: x.reshape(len(tests), -1).T.ravel()   # channel after channel, time running
        dof = residual.size - len(columns)
        noise = self._noise_product(columns, rows, np.arange(len(self.layout.channels)) if channels is None
                                    else np.asarray(channels))
        if isinstance(columns, Columns):
            r = residual.reshape(len(tests), -1)
            scores = np.array([columns.products(np.where((tests == g)[:, None], r, 0.0)) for g in np.unique(tests)])
            return clustered_errors(columns.gram(), scores, along(residual), dof, noise) ** 2
        width = residual.size // len(tests)
        jacobian = np.column_stack([along(c) for c in columns])
        return standard_errors(jacobian, along(residual), np.tile(tests, width), dof, noise) ** 2

    def _noise_product(self, columns: list[np.ndarray] | Columns, rows: np.ndarray, channels: np.ndarray
                       ) -> np.ndarray:
        """JᵀΣJ (K, K) of ``columns`` on the selected ``rows`` and ``channels`` (as :meth:`variances`
        takes them) for the noise model's covariance Σ, channel by channel, each test's rows apart
        (:meth:`elastokin.diagnosis.kc_noise.NoiseModel.covariance_product`)."""
        tests = self.layout.test[rows]
        firsts = np.flatnonzero(np.r_[True, tests[1:] != tests[:-1]])
        ends = np.r_[firsts[1:], len(tests)]
        clock, at = self.layout.clock, np.flatnonzero(rows)
        segments = [Segment(int(a), int(b), self.response.steps[tests[a]], float(clock.time_s[at[a]]),
                            int(clock.recording[at[a]])) for a, b in zip(firsts, ends)]
        out = np.zeros((len(columns), len(columns)))
        for k, c in enumerate(channels):
            if isinstance(columns, Columns):
                # the columns span every channel: channel c's own, at c
                idx = np.r_[np.flatnonzero(~columns.one), np.flatnonzero(columns.one)[columns.channel == c]]
                on = np.vstack([columns.on_channel(c), columns.single[columns.channel == c]])
            else:
                idx = np.arange(len(columns))
                on = np.array([np.reshape(x, (len(tests), len(channels)))[:, k] for x in columns])
            out[np.ix_(idx, idx)] += self.noise_model.covariance_product(on, int(c), segments)
        return out

    def residual(self, predicted: np.ndarray, rows: np.ndarray, zero: Callable[..., np.ndarray] = np.mean
                 ) -> np.ndarray:
        """(measured − predicted) / noise on the selected rows (a boolean mask): the prediction late
        by each path's lag, each channel's ``zero`` over the selected rows of each recording removed
        (its zero error: the mean, in which the residual stays affine in the prediction (the fits),
        or the median, which a misfit confined to a stretch does not move for the rest of its
        recording (the misfits' search)), and what is left of each path's response to first order
        (its taps) and each transducer's error projected out: fitted with whatever the prediction is."""
        return self._kept("residual", predicted, (rows.tobytes(), zero),   # the fits' mismatch: the same base
                          lambda: self._fitted(self.raw(predicted, rows, zero), rows)[0])

    def test_errors(self, predicted: np.ndarray) -> np.ndarray:
        """Per test, the RMS residual (1 = the noise)."""
        r2 = (self.residual(predicted, np.ones(len(predicted), dtype=bool)) ** 2).mean(axis=1)
        return np.array([math.sqrt(r2[t.rows].mean()) for t in self.layout.tests])

    def heldout_error(self, predicted: np.ndarray) -> float:
        """The RMS residual on the held-out tests (1 = the noise)."""
        r = self.residual(predicted, np.ones(len(predicted), dtype=bool))[self.held_rows]
        return float(math.sqrt(np.mean(r ** 2)))
