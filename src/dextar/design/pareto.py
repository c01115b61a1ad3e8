"""Pareto front and the design closest to the ideal point."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._arrays import Array
from .space import DesignSpace


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


@dataclass(frozen=True)
class Choice:
    """The feasible designs of a sweep, their objectives, the Pareto set and the chosen one.

    Attributes
    ----------
    feasible : list of dict
        The feasible rows, in design order.
    F : ndarray, shape (n_feasible, k)
        Their objectives (minimised).
    pareto : ndarray of bool, shape (n_feasible,)
    best : int
        Index (into ``feasible``) of the Pareto design closest to the ideal point; -1 when
        no design is feasible.
    """

    feasible: list[dict[str, Any]]
    F: Array
    pareto: Array
    best: int

    @property
    def pareto_rows(self) -> list[dict[str, Any]]:
        """The Pareto designs' rows."""
        return [r for r, p in zip(self.feasible, self.pareto, strict=True) if p]

    @property
    def best_row(self) -> dict[str, Any] | None:
        """The chosen design's row (None when no design is feasible)."""
        return self.feasible[self.best] if self.best >= 0 else None


def choose(rows: list[dict[str, Any]], space: DesignSpace) -> Choice:
    """The Pareto set of the feasible ``rows`` on the space's objectives and the design
    closest to the ideal point among them."""
    feasible = [r for r in rows if r["feasible"]]
    if not feasible:
        return Choice([], np.empty((0, len(space.objectives))), np.zeros(0, bool), -1)
    F = space.objective_values(feasible)
    mask = pareto_mask(F)
    idx = np.flatnonzero(mask)
    return Choice(feasible, F, mask, int(idx[closest_to_ideal(F[idx])]))
