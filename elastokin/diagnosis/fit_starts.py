"""Where a cause's least-squares fit starts and within which bounds, in fit coordinates (the log of
a log parameter, the value of the others).

A sided parameter's effect switches sides at zero (an asymmetry stiffening tension or compression),
a cusp in the cost that a least-squares fit cannot cross, or crosses into the wrong basin: each
side is fitted from its own starts within its own bounds. The sided parameters of one catalogue
family share a side (as the virtual rig draws them and the K&C fits take them), so a cause made of
two families has up to four sides.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from elastokin.diagnosis.catalogue import Cause, Parameter, parts


def fit_bounds(cause: Cause) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of ``cause``'s parameters in fit coordinates."""
    lo = np.array([_coordinate(p, p.bounds[0]) for p in cause.parameters])
    hi = np.array([_coordinate(p, p.bounds[1]) for p in cause.parameters])
    return lo, hi


def _families(cause: Cause) -> list[np.ndarray]:
    """Indices of the sided parameters of each catalogue family ``cause`` is made of (families
    without one left out)."""
    out, first = [], 0
    for part in parts(cause.id):
        sided = [first + k for k, p in enumerate(part.parameters) if p.sided]
        out += [np.array(sided)] if sided else []
        first += len(part.parameters)
    return out


def _family_sides(cause: Cause, Z: np.ndarray) -> np.ndarray:
    """Each point's side per family (True: positive), from the family's first nonzero sided
    parameter (a family all at zero: positive); (len(Z), families)."""
    families = _families(cause)
    sides = []
    for idx in families:
        z = Z[:, idx]
        sides.append(z[np.arange(len(Z)), np.argmax(z != 0.0, axis=1)] >= 0.0)
    return np.array(sides, dtype=bool).reshape(len(families), len(Z)).T


def _one_side_per_family(cause: Cause, Z: np.ndarray) -> np.ndarray:
    """The points of ``Z`` whose families each keep their sided parameters on one side."""
    keep = np.ones(len(Z), dtype=bool)
    for idx in _families(cause):
        keep &= (Z[:, idx] >= 0.0).all(axis=1) | (Z[:, idx] <= 0.0).all(axis=1)
    return Z[keep]


def _points(axes: list[np.ndarray]) -> np.ndarray:
    """Every combination of the values on each axis, one point a row."""
    return np.array(np.meshgrid(*axes, indexing="ij")).reshape(len(axes), -1).T


def corner_starts(cause: Cause) -> np.ndarray:
    """Starting points: the corners of the realistic range (both signs for signed parameters, one
    side per family for sided ones; the middle of the range for a cause of one parameter), then each
    of the family's other forms alone (``Cause.other_forms``) over the corners of the parameters it
    leaves, each point once."""
    axes = []
    for p in cause.parameters:
        pts = np.log(p.draw) if p.log else np.array(p.draw, dtype=float)
        if len(cause.parameters) == 1:
            pts = np.array([pts.mean()])
        axes.append(np.r_[-pts[::-1], pts] if p.signed else pts)
    grids = [_points(axes)]
    for form in cause.other_forms:
        grids.append(_points([np.array([_coordinate(p, form[p.name])]) if p.name in form else axis
                              for p, axis in zip(cause.parameters, axes)]))
    points = _one_side_per_family(cause, np.vstack(grids))
    return points[np.sort(np.unique(points, axis=0, return_index=True)[1])]


def to_fit(cause: Cause, values: dict[str, float]) -> np.ndarray:
    """``values`` of ``cause``'s parameters in fit coordinates."""
    return np.array([_coordinate(p, values[p.name]) for p in cause.parameters])


def _coordinate(p: Parameter, value: float) -> float:
    """A parameter's ``value`` in fit coordinates."""
    return math.log(value) if p.log else value


def side_starts(cause: Cause, values: dict[str, float]) -> np.ndarray:
    """Starting points from ``values``, with each family's sided parameters also on their other side
    (a least-squares fit cannot cross zero to the other effect); a sided parameter at zero starts at
    the weak end of its realistic range, on its family's side (taken from its first nonzero sided
    parameter: ``values`` come from a fit, whose families each keep one side)."""
    z = to_fit(cause, values)
    families = _families(cause)
    for idx, positive in zip(families, _family_sides(cause, z[None])[0]):
        weak = np.array([cause.parameters[i].draw[0] for i in idx])
        z[idx] = np.where(z[idx] == 0.0, weak if positive else -weak, z[idx])
    flips = np.array(list(itertools.product((1.0, -1.0), repeat=len(families))), dtype=float).reshape(
        2 ** len(families), len(families))
    points = np.repeat(z[None], len(flips), axis=0)
    for f, idx in enumerate(families):
        points[:, idx] *= flips[:, f:f + 1]
    return points


def sides_apart(cause: Cause, starts: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(which of ``starts``, lower and upper fit bounds) for each combination of its families' sides
    that the starts take, zero the bound between the sides."""
    if not len(starts):
        raise ValueError(f"{cause.id}: no starting point to fit from")
    lo, hi = fit_bounds(cause)
    keys = _family_sides(cause, starts)
    out = []
    for key in np.unique(keys, axis=0):
        lo_k, hi_k = lo.copy(), hi.copy()
        for idx, positive in zip(_families(cause), key):
            (lo_k if positive else hi_k)[idx] = 0.0
        out.append(((keys == key).all(axis=1), lo_k, hi_k))
    return out
