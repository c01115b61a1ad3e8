"""The output check: the law sampled through the exact model, nine points in every interval,
each kind of limit's largest ratio and each interval's excess (where the transcription is
refined)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..._arrays import Array
from ..constraints import Constraint, PathDynamics, ratios_by_kind
from .law import JerkLimitedLaw

#: Check samples per interval (both ends included).
CHECK_PER_INTERVAL = 9
#: The kinds of limit whose ratio is a finite difference between samples (their tolerance
#: is ``rate_tol``).
RATE_KINDS = ("jerk", "torque_rate")


def check(dynamics: PathDynamics, cons: Sequence[Constraint], law: JerkLimitedLaw,
          tol: float, rate_tol: float) -> tuple[dict[str, float], Array]:
    """The largest ratio of each kind on the check samples, and for each interval (M,) the
    largest excess of a kind over its limit in units of its tolerance (0 where all are
    within their tolerances)."""
    t = law.knots_t
    M = len(t) - 1
    n = CHECK_PER_INTERVAL
    frac = np.linspace(0.0, 1.0, n)
    grid = t[:-1, None] + np.diff(t)[:, None] * frac[None, :]
    grid[:, -1] = t[1:]  # exactly the next interval's first sample: a zero-time pair
    times = grid.reshape(-1)
    js = dynamics.samples(law, times)
    ratio = ratios_by_kind(cons, js)
    excess = np.zeros(M)
    for c in cons:
        kt = rate_tol if c.kind in RATE_KINDS else tol
        if ratio[c.kind] > 1 + kt:
            # each interval's samples (a rate's last pair spans two intervals' coincident
            # end and start: zero time, zero rate)
            r = c.sample_ratios(js)
            r = np.concatenate([r, np.zeros(M * n - len(r))]).reshape(M, n).max(axis=1)
            excess = np.maximum(excess, np.where(r > 1 + kt, (r - 1) / kt, 0.0))
    return ratio, excess
