"""The motors at the two driven joints and their limits (run units).

One object, :class:`MotorLimits`, says what the motors can give: a peak torque, a maximum
speed and, optionally, a torque-speed envelope (full torque up to a knee speed, then linearly
down to zero at the maximum speed), and what the drives may be asked: a joint acceleration,
a joint jerk and a torque rate (each optional). The time-optimal law plans within it (as
constraint objects, :mod:`dextar.laws.constraints`; with a jerk or torque-rate limit it is
third order, :mod:`dextar.laws.smooth`), programs are sized against it, exciting trajectories
stay within it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._arrays import Array
from .errors import ParameterError


@dataclass(frozen=True)
class MotorLimits:
    """The two motors' limits at the joints (run units): peak torque, maximum speed and,
    optionally, a torque-speed envelope: full torque up to ``knee_speed``, then linearly
    down to zero at ``max_speed``.

    Attributes
    ----------
    peak_torque : (float, float)
        Motor at A, motor at D.
    max_speed : (float, float)
        ``inf`` for none.
    knee_speed : (float, float), optional
        Below ``max_speed``; None for no envelope.
    max_acceleration : (float, float), optional
        Joint accelerations (rad per run time unit squared); None for none.
    max_jerk : (float, float), optional
        Joint jerks (rad per run time unit cubed); None for none.
    max_torque_rate : (float, float), optional
        Rates of change of the motor torques (run torque unit per run time unit); None for
        none.
    """

    peak_torque: tuple[float, float]
    max_speed: tuple[float, float] = (math.inf, math.inf)
    knee_speed: tuple[float, float] | None = None
    max_acceleration: tuple[float, float] | None = None
    max_jerk: tuple[float, float] | None = None
    max_torque_rate: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        t, w = np.asarray(self.peak_torque, float), np.asarray(self.max_speed, float)
        if t.shape != (2,) or not np.all(np.isfinite(t) & (t > 0)):
            raise ParameterError(f"torque limits {self.peak_torque!r} must be two positive "
                                 "numbers")
        if w.shape != (2,) or not np.all(w > 0):
            raise ParameterError(f"speed limits {self.max_speed!r} must be two positive numbers")
        if self.knee_speed is not None:
            k = np.asarray(self.knee_speed, float)
            if k.shape != (2,) or not np.all((k > 0) & (k < w)):
                raise ParameterError(f"knee speeds {self.knee_speed!r} must be positive and below "
                                     f"the maximum speeds {self.max_speed!r}")
        for name in ("max_acceleration", "max_jerk", "max_torque_rate"):
            v = getattr(self, name)
            if v is not None:
                a = np.asarray(v, float)
                if a.shape != (2,) or not np.all(np.isfinite(a) & (a > 0)):
                    raise ParameterError(f"{name.replace('_', ' ')} limits {v!r} must be two "
                                         "positive finite numbers")

    @property
    def third_order(self) -> bool:
        """True when a jerk or torque-rate limit makes a time-optimal law third order."""
        return self.max_jerk is not None or self.max_torque_rate is not None

    @classmethod
    def of(cls, torque_limit: object, speed_limit: object = None) -> MotorLimits:
        """Limits from a torque limit and an optional speed limit, each a number (both motors)
        or a pair."""
        t2 = np.broadcast_to(np.asarray(torque_limit, float), (2,))
        w2 = np.broadcast_to(np.asarray(math.inf if speed_limit is None else speed_limit,
                                        float), (2,))
        return cls((float(t2[0]), float(t2[1])), (float(w2[0]), float(w2[1])))

    def available_torque(self, dq: Array) -> Array:
        """The torque each motor can give at joint rates ``dq`` (..., 2), same shape."""
        peak = np.asarray(self.peak_torque, float)
        if self.knee_speed is None:
            return np.broadcast_to(peak, np.shape(dq)).copy()
        w, k = np.asarray(self.max_speed, float), np.asarray(self.knee_speed, float)
        frac = np.clip((w - np.abs(dq)) / (w - k), 0.0, 1.0)
        return np.asarray(peak * frac)

    def torque_ratio(self, tau: Array, dq: Array) -> float:
        """Largest ``|tau| / available torque`` over samples (n, 2) (``inf`` where a torque is
        asked of a motor that has none left)."""
        avail = self.available_torque(dq)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(avail > 0, np.abs(tau) / avail, np.where(np.abs(tau) > 0, np.inf, 0.0))
        return float(r.max())

    def speed_ratio(self, dq: Array) -> float:
        """Largest ``|qdot| / max speed`` over samples (n, 2)."""
        return float((np.abs(dq) / np.asarray(self.max_speed, float)).max())

    def motion_ratio(self, ddq: Array | None = None, jerk: Array | None = None) -> float:
        """Largest ``|qddot| / max_acceleration`` and ``|qdddot| / max_jerk`` over samples
        (n, 2) (0 for a limit not set or samples not given)."""
        out = 0.0
        for v, lim in ((ddq, self.max_acceleration), (jerk, self.max_jerk)):
            if v is not None and lim is not None and np.size(v):
                out = max(out, float((np.abs(v) / np.asarray(lim, float)).max()))
        return out

    def ratios(self, tau: Array, dq: Array) -> tuple[float, float]:
        """Largest ``|tau| / available torque`` and ``|qdot| / max speed`` over samples (n, 2)."""
        return self.torque_ratio(tau, dq), self.speed_ratio(dq)
