"""Pareto front and the design closest to the ideal point."""

from __future__ import annotations

import numpy as np

from .._arrays import Array


def pareto_mask(F: Array) -> Array:
    """True for the rows of ``F`` (n, k), all minimised, that no other row dominates (no worse
    in every objective and better in one). Vectorised per row: O(n^2 k)."""
    F = np.asarray(F, float)
    n = len(F)
    keep = np.ones(n, bool)
    for i in range(n):
        if not keep[i]:
            continue
        no_worse = (F <= F[i]).all(axis=1)
        better = (F < F[i]).any(axis=1)
        if (no_worse & better).any():
            keep[i] = False
    return keep


def closest_to_ideal(F: Array) -> int:
    """Index of the row of ``F`` (n, k) nearest to the ideal point (each objective's best)
    after scaling each objective to [0, 1] over the rows."""
    F = np.asarray(F, float)
    lo, hi = F.min(axis=0), F.max(axis=0)
    span = np.where(hi > lo, hi - lo, 1.0)
    return int(np.argmin((((F - lo) / span) ** 2).sum(axis=1)))
