"""The output check: the law sampled through the exact model, nine points in every interval,
each kind of limit's largest ratio and each interval's excess (where the transcription is
refined).

Nine samples can miss a peak between them where a ratio bends sharply (the torque over the
envelope near the speed limit: the torque available falls to zero there, so a small change
of speed is a large change of ratio). Each interval's ratios bound the excess between their
samples by a parabola's (its second difference over eight: a ratio with that curvature
exceeds its samples by at most that much between them); where that bound passes the
tolerance, the interval is sampled again :data:`DENSE` times more finely and its ratio taken
from those samples (the bound falls with the square of the spacing)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..._arrays import Array
from ..constraints import Constraint, JointSamples, PathDynamics
from .law import JerkLimitedLaw

#: Check samples per interval (both ends included).
CHECK_PER_INTERVAL = 9
#: How many times more finely an interval is sampled where its samples' curvature says a
#: ratio may pass its tolerance between them.
DENSE = 8
#: The kinds of limit whose ratio is a finite difference between samples (their tolerance
#: is ``rate_tol``).
RATE_KINDS = ("jerk", "torque_rate")


def _samples(t: Array, n: int) -> Array:
    """``n`` times in each interval of the knots ``t`` (both ends), (len(t) - 1, n)."""
    frac = np.linspace(0.0, 1.0, n)
    grid = t[:-1, None] + np.diff(t)[:, None] * frac[None, :]
    grid[:, -1] = t[1:]  # exactly the next interval's first sample: a zero-time pair
    return np.asarray(grid)


def _per_interval(r: Array, M: int, n: int) -> Array:
    """A constraint's sample ratios as (M, n) (a rate's last pair of each interval spans two
    intervals' coincident end and start: zero time, zero rate)."""
    return np.concatenate([r, np.zeros(M * n - len(r))]).reshape(M, n)


def between(r: Array) -> Array:
    """Each interval's largest ratio (M,) with the bound of its excess between samples from
    the ratios ``r`` (M, n): the largest sample plus the largest second difference over
    eight."""
    d2 = np.abs(r[:, :-2] - 2 * r[:, 1:-1] + r[:, 2:]).max(axis=1, initial=0.0)
    return np.asarray(r.max(axis=1) + d2 / 8)


def check(dynamics: PathDynamics, cons: Sequence[Constraint], law: JerkLimitedLaw,
          tol: float, rate_tol: float) -> tuple[dict[str, float], Array]:
    """The largest ratio of each kind on the check samples (denser where they may miss a
    peak, see the module doc), and for each interval (M,) the largest excess of a kind over
    its limit in units of its tolerance (0 where all are within their tolerances)."""
    t = law.knots_t
    M = len(t) - 1
    n = CHECK_PER_INTERVAL
    js = dynamics.samples(law, _samples(t, n).reshape(-1))
    per = [(c, _per_interval(c.sample_ratios(js), M, n)) for c in cons]
    dense: JointSamples | None = None
    m = DENSE * (n - 1) + 1
    # the intervals where a torque, speed or acceleration ratio may pass its tolerance
    # between the samples (a rate's samples are exact: the jerk is constant in an interval)
    near = np.zeros(M, bool)
    for c, r in per:
        if c.kind not in RATE_KINDS:
            near |= between(r) > 1 + tol
    idx = np.flatnonzero(near)
    if idx.size:
        dense = dynamics.samples(law, _samples(t, m)[idx].reshape(-1))
    ratio: dict[str, float] = {}
    excess = np.zeros(M)
    for c, r in per:
        worst = r.max(axis=1)
        if dense is not None and c.kind not in RATE_KINDS:
            worst[idx] = np.maximum(worst[idx],
                                    _per_interval(c.sample_ratios(dense), idx.size, m)
                                    .max(axis=1))
        ratio[c.kind] = max(ratio.get(c.kind, 0.0), float(worst.max(initial=0.0)))
        kt = rate_tol if c.kind in RATE_KINDS else tol
        excess = np.maximum(excess, np.where(worst > 1 + kt, (worst - 1) / kt, 0.0))
    return ratio, excess
