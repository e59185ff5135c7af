"""The measurement noise of a K&C campaign, estimated from the residual of a model (issue 53 item 2):
white, and coloured (a rig's amplifier flicker, its temperature, its vibration: correlated over
seconds), which a white-noise estimate misses and the diagnosis would read as a car's error.

A residual is noise plus the model's error. Differences cancel a model error and keep the noise:

- between successive samples, a smooth model error hardly shows: their spread is the white noise
  (robustly, the median absolute deviation; where the input repeats, of the period differences'
  successive differences, which a repeating error does not move at all);
- in a test whose input repeats (the K&C campaign's triangles, two cycles each), between the samples
  one period P apart, a model error that repeats cancels too (a rig's gain or lag, a car's
  stiffness or geometry), while the noise stays, with its correlation: the autocovariance of
  d(t) = e(t + P) − e(t) is, for noise e of autocovariance γ, 2γ(k) − γ(P + k) − γ(P − k). The
  noise is taken as white plus a first-order autoregressive process, γ(k) = w δ(k) + a φ^|k|
  (φ = exp(−Δt / τ)), fitted to the differences' variogram, which no zero or drift biases
  (non-negative least squares for w and a, τ on a grid).

A mismatch that does not repeat (a car's first loading differing from the next) counts as noise
there: a cause is then judged against a noise it partly makes, which loses sensitivity, never
invents a cause. A test without a repeated input gives the white noise only; the channel's
quantity takes the coloured noise its repeated tests show (a transducer's noise is its own).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy import signal as sps
from scipy.optimize import nnls

from elastokin.diagnosis.kc_layout import Layout
from elastokin.vehicle.scenarios.channels import channel_quantity

#: Lags [samples] of the period differences' variogram fitted: up to three quarters of a difference's length, at most this.
MAX_LAG = 250
#: A quantity's coloured noise is said beyond this share of its white noise (a sampling scatter's well under it).
COLOURED_SAID = 0.3
#: Robust standard deviations at which a period difference is clipped (Gaussian noise: ~1e-4 of its variance).
CLIP = 4.0
#: Correlation times [s] tried for the coloured noise.
CORRELATION_TIMES_S = np.geomspace(0.02, 60.0, 48)
#: How much worse (relative, in the variogram fit's residual norm) a correlation time may fit than the
#: best and still be taken (:func:`_coloured`).
FIT_TOLERANCE = 0.1


@dataclass(frozen=True)
class Segment:
    """A test's rows in :meth:`NoiseModel.covariance_product`: evenly sampled, its noise running on
    from its recording's previous segment."""

    first: int        #: its first row
    end: int          #: past its last row
    dt_s: float       #: its sampling interval [s]
    start_s: float    #: its first row's time through its recording [s]
    recording: int    #: its recording's index


@dataclass(frozen=True)
class NoiseModel:
    """Each compared channel's noise: white plus first-order autoregressive (module docstring)."""

    white: np.ndarray              #: (C,) the white noise's standard deviation [channel unit]
    coloured: np.ndarray           #: (C,) the coloured noise's, what each recording's zero leaves of it [channel unit]
    correlation_time_s: np.ndarray  #: (C,) the coloured noise's correlation time τ [s] (0: none)
    coloured_left: np.ndarray      #: (C,) the share of the coloured noise's variance each recording's zero leaves
    #: the repeated tests' period differences, noise alone: (their sampling interval [s], the channels'
    #: indices, the differences (n, channels) clipped)
    differences: tuple[tuple[float, np.ndarray, np.ndarray], ...] = ()

    @property
    def sigma(self) -> np.ndarray:
        """(C,) the whole noise's standard deviation [channel unit]."""
        return np.sqrt(self.white ** 2 + self.coloured ** 2)

    def covariance_product(self, columns: np.ndarray, channel: int, segments: Sequence[Segment]) -> np.ndarray:
        """JᵀΣJ (K, K) for ``columns`` (K, n) on ``channel`` in units of its noise (:attr:`sigma`), Σ
        its noise's covariance: white, plus the coloured noise's exp(−|tᵢ − tⱼ| / τ) over each
        recording's ``segments`` (its tests' rows in time order: the noise runs on between them),
        whole: the columns are centred in each recording as its zero leaves the noise, and a
        centred column takes the whole noise's covariance, a slow noise's as well (over a recording
        its zero takes most of that noise, not its wander)."""
        sigma = max(float(self.sigma[channel]), 1e-300)
        weighted = (self.white[channel] / sigma) ** 2 * columns
        tau = float(self.correlation_time_s[channel])
        share = (self.coloured[channel] / sigma) ** 2 / max(float(self.coloured_left[channel]), 1e-3)
        if share > 0.0 and tau > 0.0:   # Σ_j exp(−|tᵢ − tⱼ| / τ) c_j
            weighted += share * (_relaxed(columns, segments, tau, False) + _relaxed(columns, segments, tau, True)
                                 - columns)
        return columns @ weighted.T

    def window_dof(self, width: int, dt_s: float) -> np.ndarray:
        """(C,) the degrees of freedom of the mean square of ``width`` successive samples ``dt_s`` [s]
        apart, as many as samples for white noise, fewer for correlated: from the model,
        width / (1 + 2 Σ (1 − k/width) ρ(k)²) for its autocorrelation ρ, or fewer, those of the χ² of
        the same mean and variance (2 mean² / variance) as the windows' mean squares of the period
        differences sampled at that interval (noise alone, whatever its spectrum; but a difference
        cancels what the noise repeats a period apart, so it is the less correlated)."""
        share = self.coloured ** 2 / np.maximum(self.sigma ** 2, 1e-300)
        k = np.arange(1, width)
        with np.errstate(divide="ignore", invalid="ignore"):
            phi = np.where(self.correlation_time_s > 0.0, np.exp(-dt_s / self.correlation_time_s), 0.0)
        rho = share[:, None] * phi[:, None] ** k[None, :]
        out = width / (1.0 + 2.0 * np.sum((1.0 - k / width)[None, :] * rho ** 2, axis=1))
        squares: dict[bytes, tuple[np.ndarray, list[np.ndarray]]] = {}
        for dt, idx, d in self.differences:
            if abs(dt - dt_s) <= 1e-6 * dt_s and len(d) >= 2 * width:
                total = np.vstack([np.zeros((1, d.shape[1])), np.cumsum(d ** 2, axis=0)])
                squares.setdefault(idx.tobytes(), (idx, []))[1].append(((total[width:] - total[:-width]) / width).ravel())
        for idx, means in squares.values():
            m = np.concatenate(means)
            if m.var() > 0.0:
                out[idx] = np.minimum(out[idx], 2.0 * m.mean() ** 2 / m.var())
        return out


def _relaxed(columns: np.ndarray, segments: Sequence[Segment], tau_s: float, backward: bool) -> np.ndarray:
    """Σ_{j ≤ i} exp(−(tᵢ − tⱼ) / ``tau_s``) c_j for each row i of ``columns`` (K, n) over each
    recording's ``segments`` (or Σ_{j ≥ i} if ``backward``): each segment filtered alone, then what
    the recording's earlier segments carry into it decayed over the gap."""
    out = np.zeros_like(columns)
    order = sorted(segments, key=lambda g: (g.recording, g.start_s), reverse=backward)
    carry, recording, edge_s = None, None, 0.0
    for g in order:
        n = g.end - g.first
        if n <= 0:
            continue
        phi = math.exp(-g.dt_s / tau_s) if g.dt_s > 0.0 else 0.0
        seg = columns[:, g.first:g.end]
        filtered = sps.lfilter([1.0], [1.0, -phi], seg[:, ::-1] if backward else seg, axis=1)
        edges_s = (g.start_s, g.start_s + (n - 1) * g.dt_s)   # its first and last rows' times
        near_s, far_s = edges_s[::-1] if backward else edges_s   # the one facing the carry first
        if carry is not None and g.recording == recording:
            filtered += carry[:, None] * (math.exp(-abs(near_s - edge_s) / tau_s) * phi ** np.arange(n))[None, :]
        carry, recording, edge_s = filtered[:, -1].copy(), g.recording, far_s
        out[:, g.first:g.end] = filtered[:, ::-1] if backward else filtered
    return out


def coloured_noise(channels: list[str], noise: NoiseModel) -> dict[str, tuple[float, float, float]]:
    """Per quantity whose noise is coloured beyond :data:`COLOURED_SAID` of its white noise: its white
    and coloured noise [its unit] and the correlation time [s] (its channels share them)."""
    out = {}
    for i, c in enumerate(channels):
        q = channel_quantity(c)
        if q not in out and noise.coloured[i] > COLOURED_SAID * noise.white[i]:
            out[q] = (float(noise.white[i]), float(noise.coloured[i]), float(noise.correlation_time_s[i]))
    return out


def lagged(rows: np.ndarray, samples: np.ndarray, lag: int) -> np.ndarray:
    """The differences of ``rows`` (their input-phase ``samples``) over ``lag`` samples, where both
    are present, each channel's median out (a zero drifting through a recording moves it)."""
    at = np.searchsorted(samples, samples + lag)
    hit = at < len(samples)
    hit[hit] = samples[at[hit]] == samples[hit] + lag
    d = rows[at[hit]] - rows[hit]
    return d - np.median(d, axis=0) if len(d) else d


def white_noise(layout: Layout, residual: np.ndarray) -> np.ndarray:
    """(C,) each channel's white noise [channel unit] from a model's ``residual`` (N, C) over
    ``layout``: the robust spread of its differences between successive samples, which a smooth
    model error hardly moves; where tests repeat their input, of the successive differences of the
    period differences (4 σ² for white noise), which a model error that repeats does not move either
    (in a quick test the error's own step between samples is not small). The median of its
    quantity's channels."""
    width = residual.shape[1]
    steps = [lagged(residual[t.rows], t.samples, 1) for t in layout.tests]
    repeated = [np.diff(lagged(residual[t.rows], t.samples, t.period), axis=0) / math.sqrt(2.0)
                for t in layout.tests if t.period > 0]
    repeated = [d for d in repeated if len(d)]
    d1 = np.vstack([np.zeros((0, width)), *(repeated or steps)])
    per = 1.4826 * np.median(np.abs(d1 - np.median(d1, axis=0)), axis=0) / math.sqrt(2.0) if len(d1) \
        else np.zeros(width)
    family = np.array([channel_quantity(c) for c in layout.channels])
    return np.maximum(np.array([np.median(per[family == f]) for f in family]), 1e-9)


def estimate_noise(layout: Layout, residual: np.ndarray) -> NoiseModel:
    """Each channel's noise from a model's ``residual`` (N, C) over ``layout`` (module docstring):
    the white noise (:func:`white_noise`); the coloured from the tests of a repeated input, per
    quantity (its channels pooled)."""
    width = residual.shape[1]
    white = white_noise(layout, residual)
    family = np.array([channel_quantity(c) for c in layout.channels])
    coloured, tau, left = np.zeros(width), np.zeros(width), np.ones(width)
    spans: dict[int, float] = {}   # each recording's length [s]
    for t in layout.tests:
        k = int(layout.recording[t.rows[0]])
        spans[k] = spans.get(k, 0.0) + float(np.ptp(layout.input_time[t.rows]))
    span = float(np.median(list(spans.values())))
    differences = []
    for f in dict.fromkeys(family):
        idx = np.flatnonzero(family == f)
        share, t, kept = _coloured(layout, residual[:, idx] / white[idx], span)
        left[idx] = _left_by_the_zero(t, span)
        coloured[idx], tau[idx] = white[idx] * np.sqrt(share * left[idx]), t
        differences += [(dt, idx, d) for dt, d in kept]
    return NoiseModel(white, coloured, tau, left, tuple(differences))


def _left_by_the_zero(tau_s: float, span_s: float) -> float:
    """The share of the variance of a first-order autoregressive process of correlation time
    ``tau_s`` [s] left over ``span_s`` [s] once its mean there is taken out (a recording's zero):
    1 − (2τ/T)(1 − (τ/T)(1 − exp(−T/τ)))."""
    if tau_s <= 0.0 or span_s <= 0.0:
        return 1.0
    x = tau_s / span_s
    return max(0.0, 1.0 - 2.0 * x * (1.0 - x * (1.0 - math.exp(-1.0 / x))))


def _coloured(layout: Layout, residual: np.ndarray, span_s: float
              ) -> tuple[float, float, list[tuple[float, np.ndarray]]]:
    """The coloured noise's variance (in units of the white noise's, which ``residual`` is in) and its
    correlation time [s] from the period differences of the repeated tests: their variogram
    v(m) = ½ E[(d(t + m) − d(t))²] = c(0) − c(m), which no zero or drift of a recording biases, fitted
    for the noise's model (module docstring), (0, 0) where none repeats or none is found; and the
    differences (their sampling interval [s], the differences clipped). A slow noise (correlated over
    a period or more) shows in differences a period apart as a drift whose rate alone they tell, not
    its correlation time: of the correlation times that fit the variogram within
    :data:`FIT_TOLERANCE` of the best, the one that leaves the most of the noise over a recording
    of ``span_s`` [s] once its zero is out (:func:`_left_by_the_zero`), which counts it the fewest
    degrees of freedom: the noise is not under-estimated, nor a slow wander taken for a misfit."""
    rows, design, kept = [], [], []
    for t in layout.tests:
        if t.period <= 0:
            continue
        d = lagged(residual[t.rows], t.samples, t.period)
        # clipped at CLIP robust deviations: a start from rest does not repeat (a lag's first samples)
        bound = CLIP * 1.4826 * np.median(np.abs(d), axis=0) if len(d) else 0.0
        d = np.clip(d, -bound, bound)
        lags = min(MAX_LAG, 3 * len(d) // 4)
        if lags < 2:
            continue
        m = np.arange(1, lags + 1)
        dt = float(np.median(np.diff(layout.input_time[t.rows])))
        rows.append(np.array([0.5 * np.mean((d[j:] - d[:len(d) - j]) ** 2) for j in m]))   # the channels pooled
        design.append((m, t.period, dt))
        kept.append((dt, d))
    if not rows:
        return 0.0, 0.0, kept
    target = np.concatenate(rows)
    fits = []
    for tau in CORRELATION_TIMES_S:
        columns = []
        for m, period, dt in design:
            phi = math.exp(-dt / tau)
            c = lambda k: 2.0 * phi ** k - phi ** (period + k) - phi ** np.abs(period - k)
            columns.append(np.column_stack([np.full(len(m), 2.0), c(0) - c(m)]))
        (_, a), norm = nnls(np.vstack(columns), target)
        fits.append((norm, a, float(tau)))
    best = min(norm for norm, _, _ in fits)
    _, share, tau = max((f for f in fits if f[0] <= (1.0 + FIT_TOLERANCE) * best),
                        key=lambda f: (f[1] * _left_by_the_zero(f[2], span_s), f[2]))
    return (share, tau, kept) if share > 0.0 else (0.0, 0.0, kept)
