"""The jerk-limited law's result: piecewise-constant path jerk between knots in time."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..._arrays import Array
from ...units import Units
from ..base import Law


@dataclass(frozen=True)
class JerkLimitedLaw(Law):
    """Piecewise-constant jerk law found by :func:`solve_jerk_limited_law`.

    Attributes
    ----------
    knots_t, knots_s, knots_v, knots_a : ndarray, shape (M + 1,)
        Time, arc length, speed and acceleration at the knots (zero speed and acceleration at
        both ends); ``jerk`` (M,) on each interval.
    torque_limit, speed_limit : tuple
        The limits of the motors at A and D (speed limit ``inf`` when none).
    ratios : mapping of str to float
        Largest ratio of each kind of limit on the check samples (``torque``, ``speed``,
        ``acceleration``, ``jerk``, ``torque_rate``).
    second_order_duration : float
        The duration of the second-order (unlimited jerk) law on the same limits (on the
        coarse grid of the start: its reachability analysis, not checked between the grid's
        points).
    status : int
        0 when the limits hold within their tolerances on the check samples, 1 otherwise.
    message : str
    solves : int
        Linear programmes solved.
    """

    distance: float
    duration: float
    knots_t: Array = field(repr=False)
    knots_s: Array = field(repr=False)
    knots_v: Array = field(repr=False)
    knots_a: Array = field(repr=False)
    jerk: Array = field(repr=False)
    torque_limit: tuple[float, float] = (np.inf, np.inf)
    speed_limit: tuple[float, float] = (np.inf, np.inf)
    ratios: Mapping[str, float] = field(default_factory=dict)
    second_order_duration: float = 0.0
    status: int = 0
    message: str = ""
    solves: int = 0
    name: str = field(default="time-optimal", init=False)

    @property
    def max_torque_ratio(self) -> float:
        """Largest ``|tau_i| / limit_i`` on the check samples."""
        return float(self.ratios.get("torque", 0.0))

    def report(self, units: Units) -> dict[str, Any]:
        """The torque limits (N m), the order and the largest ratio of each limit."""
        return {"torque_limit_Nm": [float(units.torque_in_nm(v)) for v in self.torque_limit],
                "max_torque_ratio_check_samples": self.max_torque_ratio, "order": 3,
                "max_ratios_check_samples": dict(self.ratios),
                "second_order_duration": self.second_order_duration}

    def speed_and_acceleration(self, t: object) -> tuple[Array, Array]:
        """``sdot, sddot`` at times ``t`` (:meth:`evaluate`'s, without the arc length and
        the jerk)."""
        k, tau = self._interval(self._within(t))
        return self._rates(k, tau)

    def _interval(self, t: Array) -> tuple[Array, Array]:
        """Each time's interval and its time into it."""
        k = np.clip(np.searchsorted(self.knots_t, t, side="right") - 1, 0, self.jerk.size - 1)
        return k, t - self.knots_t[k]

    def _rates(self, k: Array, tau: Array) -> tuple[Array, Array]:
        """The speed and the acceleration at ``tau`` into the intervals ``k``."""
        j, a = self.jerk[k], self.knots_a[k]
        return self.knots_v[k] + tau * (a + tau * j / 2), a + tau * j

    def _evaluate(self, t: Array) -> Array:
        k, tau = self._interval(t)
        j, a, v = self.jerk[k], self.knots_a[k], self.knots_v[k]
        s = self.knots_s[k] + tau * (v + tau * (a / 2 + tau * j / 6))
        return np.stack([s, *self._rates(k, tau), j])
