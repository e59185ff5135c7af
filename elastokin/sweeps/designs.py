"""Where a sweep's runs sit in its parameter space: a full grid, a Latin hypercube, or a Sobol'
sequence arranged for sensitivity indices (Saltelli's matrices A, B and the d matrices A_B^i).

Points are drawn in the unit cube by ``scipy.stats.qmc`` (seeded: the same file gives the same
points) and scaled to each parameter's bounds; run ``k`` of a design is always the same point, so a
resumed sweep finds its runs by number.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

from elastokin.core.documents import Fields

#: The design types of a sweep file.
DESIGNS = ("grid", "latin_hypercube", "sobol")
#: The most runs a sweep may make (a sweep file's typo should not queue a billion runs).
MAX_RUNS = 100_000


@dataclass(frozen=True)
class Design:
    """How the runs are placed: ``grid`` (``levels`` per parameter), ``latin_hypercube`` (``runs``
    points) or ``sobol`` (``base_runs`` points of A and of B, a power of two: base_runs·(d + 2)
    runs in all); ``seed`` draws the random designs."""

    type: str
    levels: int = 0
    runs: int = 0
    base_runs: int = 0
    seed: int = 0

    @classmethod
    def of(cls, f: Fields, dimensions: int) -> "Design":
        """The design of a sweep file's ``design`` mapping (``f``) for ``dimensions`` parameters;
        InputError naming its key when it makes no run, too many, or a Sobol' base that is not a
        power of two."""
        kind = f.choice("type", DESIGNS)
        wanted = {"grid": "levels", "latin_hypercube": "runs", "sobol": "base_runs"}[kind]
        for key in ("levels", "runs", "base_runs"):
            if key != wanted and f.has(key):
                raise f.fail(key, f"a {kind} design takes `{wanted}`, not `{key}`")
        if kind == "grid" and f.has("seed"):
            raise f.fail("seed", "a grid has no random draw: remove `seed`")
        count = int(f.number(wanted, 3 if kind == "grid" else ..., integer=True))
        if count < (2 if kind == "grid" else 1):
            raise f.fail(wanted, f"expected at least {2 if kind == 'grid' else 1}, got {count}")
        if kind == "sobol" and count & (count - 1):
            raise f.fail(wanted, f"expected a power of two (Sobol' points balance in blocks of 2^m), got {count}")
        design = cls(kind, **{wanted: count}, seed=int(f.number("seed", 0, nonneg=True, integer=True)))
        total = run_count(design, dimensions)
        if total > MAX_RUNS:
            raise f.fail(wanted, f"this design makes {total} runs; expected at most {MAX_RUNS}")
        return design


def run_count(design: Design, dimensions: int) -> int:
    """How many runs ``design`` makes with ``dimensions`` parameters."""
    if design.type == "grid":
        return design.levels ** dimensions
    if design.type == "latin_hypercube":
        return design.runs
    return design.base_runs * (dimensions + 2)


def unit_points(design: Design, dimensions: int) -> np.ndarray:
    """(runs, dimensions) points of ``design`` in the unit cube, run by run.

    A grid varies the last parameter fastest; a Sobol' design lists A, then B, then each A_B^i (A
    with column i taken from B), ``base_runs`` rows each (:mod:`elastokin.sweeps.sensitivity` reads them
    in that order).
    """
    if design.type == "grid":
        axis = np.linspace(0.0, 1.0, design.levels)
        return np.array(list(itertools.product(axis, repeat=dimensions)), dtype=float).reshape(-1, dimensions)
    rng = np.random.default_rng(design.seed)
    if design.type == "latin_hypercube":
        return qmc.LatinHypercube(d=dimensions, seed=rng).random(design.runs)
    n = design.base_runs
    ab = qmc.Sobol(d=2 * dimensions, scramble=True, seed=rng).random(n)
    a, b = ab[:, :dimensions], ab[:, dimensions:]
    blocks = [a, b]
    for i in range(dimensions):
        mixed = a.copy()
        mixed[:, i] = b[:, i]
        blocks.append(mixed)
    return np.vstack(blocks)


def design_points(design: Design, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """(runs, d) parameter values of ``design`` between the bounds ``low`` and ``high`` (d each); a
    point on a bound is that bound exactly (the values the sweep file's check built)."""
    u = unit_points(design, len(low))
    return low * (1.0 - u) + high * u
