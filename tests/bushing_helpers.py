"""Shared helpers for the bushing tests: closed forms of the discrete STS (annex C) and paths."""

from __future__ import annotations

import numpy as np

from elastokin.bushings import BushingBank, ChannelParams, load_parameter_set, to_si


def channel(name: str, model: str | None = None) -> ChannelParams:
    """SI channel of a shipped parameter set."""
    return load_parameter_set(name).channel(model)


def simulate(ch: ChannelParams, e_m: np.ndarray, dt_s: float) -> np.ndarray:
    """Force history [N] of one channel along a deflection history [m]."""
    return BushingBank([ch]).run(e_m, dt_s)[0]


def sts_first_loading(ch: ChannelParams, x_m: np.ndarray) -> np.ndarray:
    """Closed-form first-loading force of the discrete STS [N] (annex C).

    Slider i starts slipping when the ladder force reaches i·Ff; with i−1 sliders slipping the
    ladder tangent is Kpa·Kr/((i−1)·Kpa + Kr) (C.8).
    """
    out = np.empty_like(x_m)
    for j, x in enumerate(np.abs(x_m)):
        pos, ladder, i = 0.0, 0.0, 1
        while True:
            kt = ch.Kpa * ch.Kr / ((i - 1) * ch.Kpa + ch.Kr)
            span = (i * ch.Ff - ladder) / kt if i <= ch.n_cells else np.inf
            if pos + span >= x:
                ladder += kt * (x - pos)
                break
            pos += span
            ladder = i * ch.Ff
            i += 1
        out[j] = np.sign(x_m[j]) * (ch.K0 * x + ladder)
    return out


def triangle(amplitudes_m: list[float], n_per_mm: int = 4000, start_m: float = 0.0) -> np.ndarray:
    """Piecewise-linear path through the given turning points, sampled uniformly in displacement."""
    pts = [start_m] + list(amplitudes_m)
    segs = []
    for a, b in zip(pts[:-1], pts[1:]):
        n = max(2, int(abs(b - a) * 1e3 * n_per_mm))
        segs.append(np.linspace(a, b, n, endpoint=False))
    segs.append(np.array([pts[-1]]))
    return np.concatenate(segs)


def inline(model: str, **values: float) -> ChannelParams:
    """SI channel from thesis-unit values (N, mm, s)."""
    return to_si(model, values, "translation", source="test")
