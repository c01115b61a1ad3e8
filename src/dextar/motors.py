"""The motors at the two driven joints and their limits (run units).

One object, :class:`MotorLimits`, says what the motors can give: a peak torque, a maximum
speed and, optionally, a torque-speed envelope (full torque up to a knee speed, then linearly
down to zero at the maximum speed), and what the drives may be asked: a joint acceleration,
a joint jerk and a torque rate (each optional). The time-optimal law plans within it (as
constraint objects, :mod:`dextar.laws.constraints`; with a jerk or torque-rate limit it is
third order, :mod:`dextar.laws.smooth`), programs are sized against it, exciting trajectories
stay within it.

Catalogues (``dextar design``'s ``[design].motors``): a :class:`Catalogue` of :class:`Motor`
entries (at their own shafts) and gear ratios; a :class:`Gearmotor`, a motor behind an ideal
gearbox, gives its joint's :class:`MotorLimits` (torques times the ratio, speeds over it),
its continuous rating and its reflected rotor inertia (the ratio squared times the rotor's).
The file is read by :mod:`dextar.config.catalogue`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._arrays import Array
from .errors import ParameterError


@dataclass(frozen=True)
class MotorLimits:
    """The two motors' limits at the joints, in the units of the model they limit (N m,
    rad/s, rad/s^2, rad/s^3 and N m/s with a model in SI): peak torque,
    maximum speed and, optionally, a torque-speed envelope: full torque up to
    ``knee_speed``, then linearly down to zero at ``max_speed``.

    Attributes
    ----------
    peak_torque : (float, float)
        Motor at A, motor at D (N m in SI).
    max_speed : (float, float)
        ``inf`` for none (rad/s in SI).
    knee_speed : (float, float), optional
        Below ``max_speed``; None for no envelope.
    max_acceleration : (float, float), optional
        Joint accelerations (rad/s^2 in SI; rad per run time unit squared); None for none.
    max_jerk : (float, float), optional
        Joint jerks (rad/s^3 in SI; rad per run time unit cubed); None for none.
    max_torque_rate : (float, float), optional
        Rates of change of the motor torques (N m/s in SI; run torque unit per run time
        unit); None for none.
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


# --- catalogues: motors and gearboxes to choose from -----------------------------------------


@dataclass(frozen=True)
class Motor:
    """A motor of a catalogue, at its own shaft (SI).

    Attributes
    ----------
    name : str
    rated_torque : float
        Continuous (RMS) torque, N m.
    peak_torque : float
        N m, at least the rated torque.
    max_speed : float
        rad/s.
    rotor_inertia : float
        kg m^2.
    mass : float
        kg.
    price : float
        In the catalogue's currency.
    knee_speed : float, optional
        rad/s: full torque up to it, then linearly down to zero at ``max_speed`` (None: full
        torque up to ``max_speed``).
    """

    name: str
    rated_torque: float
    peak_torque: float
    max_speed: float
    rotor_inertia: float
    mass: float
    price: float
    knee_speed: float | None = None

    def __post_init__(self) -> None:
        for key in ("rated_torque", "peak_torque", "max_speed"):
            v = getattr(self, key)
            if not (math.isfinite(v) and v > 0):
                raise ParameterError(f"motor {self.name!r}: {key} {v!r} must be positive")
        for key in ("rotor_inertia", "mass", "price"):
            v = getattr(self, key)
            if not (math.isfinite(v) and v >= 0):
                raise ParameterError(f"motor {self.name!r}: {key} {v!r} must be >= 0")
        if self.peak_torque < self.rated_torque:
            raise ParameterError(f"motor {self.name!r}: peak torque {self.peak_torque:g} N m is "
                                 f"below its rated torque {self.rated_torque:g} N m")
        if self.knee_speed is not None and not 0 < self.knee_speed < self.max_speed:
            raise ParameterError(f"motor {self.name!r}: knee speed {self.knee_speed!r} must be "
                                 f"positive and below the maximum speed {self.max_speed:g}")


@dataclass(frozen=True)
class Gearmotor:
    """A catalogue motor behind an ideal gearbox of ``ratio`` (motor turns per joint turn; no
    loss, no inertia of its own), as its joint sees it: torques times the ratio, speeds over
    it, the rotor's inertia times its square."""

    motor: Motor
    ratio: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.ratio) and self.ratio > 0):
            raise ParameterError(f"gear ratio {self.ratio!r} must be positive")

    @property
    def label(self) -> str:
        """``"NAME, ratio N"``."""
        return f"{self.motor.name}, ratio {self.ratio:g}"

    @property
    def reflected_inertia(self) -> float:
        """``N^2 J_r``: the rotor's inertia at the joint (kg m^2)."""
        return self.ratio**2 * self.motor.rotor_inertia

    @property
    def spin(self) -> float:
        """``N J_r``: the rotor's angular momentum per unit joint rate (the rotor turning the
        joint's way)."""
        return self.ratio * self.motor.rotor_inertia

    @property
    def rms_torque(self) -> float:
        """The continuous torque at the joint, ``N tau_rated`` (N m)."""
        return self.ratio * self.motor.rated_torque

    def limits(self, drive: MotorLimits | None = None) -> MotorLimits:
        """Both joints' limits with this gearmotor on each (SI): peak torque ``N tau_peak``,
        speeds ``omega / N`` (the motor-side speed limit at the joint), the envelope's knee
        likewise; the joint acceleration, jerk and torque-rate limits of ``drive`` (a task's
        ``[motors]``) kept."""
        m, n = self.motor, self.ratio
        knee = None if m.knee_speed is None else (m.knee_speed / n, m.knee_speed / n)
        keep = {} if drive is None else {
            "max_acceleration": drive.max_acceleration, "max_jerk": drive.max_jerk,
            "max_torque_rate": drive.max_torque_rate}
        return MotorLimits((n * m.peak_torque, n * m.peak_torque),
                           (m.max_speed / n, m.max_speed / n), knee, **keep)

    def config_tables(self, drive: MotorLimits | None = None) -> dict[str, dict[str, object]]:
        """``[motors]`` (joint side) and ``[drive]`` (the ratio and the motor's rated torque)
        in config units (N m, rpm), as a model file writes them."""
        m, n, rpm = self.motor, self.ratio, 60.0 / (2.0 * math.pi)
        lim = self.limits(drive)
        motors: dict[str, object] = {"peak_torque": n * m.peak_torque,
                                     "rms_torque": n * m.rated_torque,
                                     "max_speed_rpm": m.max_speed / n * rpm}
        if m.knee_speed is not None:
            motors["knee_speed_rpm"] = m.knee_speed / n * rpm
        for key in ("max_acceleration", "max_jerk", "max_torque_rate"):
            v = getattr(lim, key)
            if v is not None:
                motors[key] = list(v)
        return {"motors": motors, "drive": {"gear_ratio": n, "rated_torque_Nm": m.rated_torque}}


#: How a catalogue's motors are ordered when the smallest that fits is chosen.
ORDERS = ("lightest", "cheapest")


@dataclass(frozen=True)
class Catalogue:
    """Motors to choose from and the gear ratios they may take (every motor with every
    ratio).

    Attributes
    ----------
    motors : tuple of Motor
        Names unique.
    ratios : tuple of float
        Motor turns per joint turn (1 for a direct drive).
    source : str
        Where it was read (named in messages).
    currency : str
        The unit of the prices.
    """

    motors: tuple[Motor, ...]
    ratios: tuple[float, ...] = (1.0,)
    source: str = "the catalogue"
    currency: str = ""

    def __post_init__(self) -> None:
        if not self.motors:
            raise ParameterError(f"{self.source} lists no motor")
        names = [m.name for m in self.motors]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ParameterError(f"{self.source}: motor name {dup[0]!r} is listed twice")
        if not self.ratios:
            raise ParameterError(f"{self.source}: no gear ratio to choose from")
        for r in self.ratios:
            Gearmotor(self.motors[0], r)  # checks the ratio

    def motor(self, name: str) -> Motor:
        """The motor ``name``."""
        for m in self.motors:
            if m.name == name:
                return m
        raise ParameterError(f"{self.source} has no motor {name!r}")

    def ordered(self, order: str) -> list[Motor]:
        """The motors from the smallest: ``"lightest"`` by mass (then price), ``"cheapest"``
        by price (then mass), then by name."""
        if order not in ORDERS:
            raise ParameterError(f"motor order {order!r}: one of {', '.join(ORDERS)}")
        if order == "lightest":
            return sorted(self.motors, key=lambda m: (m.mass, m.price, m.name))
        return sorted(self.motors, key=lambda m: (m.price, m.mass, m.name))
