"""Laws of motion along a path: the arc length ``s(t)`` on ``[0, T]``, from 0 to the path's
length ``S``, with its first three time derivatives.

Laws act on arc length so that "uniform" means constant speed on any path; on the paper's
circle ``s = R p``, so a law in ``s`` is the same law in the polar angle ``p``.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._arrays import Array
from ..errors import ParameterError
from ..params import Param
from ..paths import Path
from ..units import Units
from .registry import LawType, register_law


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0):
        raise ParameterError(f"{name} = {value!r} must be positive and finite")
    return value


class Law(ABC):
    """A law of motion ``s(t)``, ``t`` in ``[0, duration]``, ``s`` from 0 to ``distance``.

    A law is the laws stage's result (:data:`LawResult`): besides evaluating it carries the
    solver's ``status``, ``success`` and ``message`` (closed-form laws always succeed).
    """

    distance: float
    duration: float
    name: str = "law"
    #: Solver outcome, as in ``scipy.optimize.OptimizeResult``: 0 is success. Closed-form
    #: laws always succeed; solved laws (optimal, time-optimal) set their own.
    status: int = 0
    message: str = "closed form"

    @property
    def success(self) -> bool:
        """True when the law was found as asked (``status == 0``)."""
        return self.status == 0

    def breakpoints(self) -> Array:
        """Times inside ``(0, duration)`` where the acceleration jumps (none by default)."""
        return np.empty(0)

    @property
    def torque_limit(self) -> tuple[float, float] | None:
        """The motors' torque limits the law was planned within (run units; None for a law
        that does not plan on the dynamics)."""
        return None

    def report(self, units: Units) -> dict[str, Any]:
        """The law's own quantities for a run's summary (run units unless the key says
        otherwise); none by default."""
        return {}

    def cost_report(self) -> dict[str, float] | None:
        """The paper's functional when the law minimises it (``total``, ``kinetic``,
        ``inertial``); None for the other laws."""
        return None

    @abstractmethod
    def _evaluate(self, t: Array) -> Array:
        """Rows ``s, sdot, sddot, sdddot`` at ``t``, shape (4, ...)."""

    def evaluate(self, t: object) -> Array:
        """``s, sdot, sddot, sdddot`` at times ``t``, stacked in an array of shape (4, ...)."""
        return self._evaluate(self._within(t))

    def _within(self, t: object) -> Array:
        """The times ``t`` as floats clipped to the law's interval (a rounding past an end),
        a :class:`ParameterError` naming a time outside it."""
        t = np.asarray(t, dtype=float)
        T = self.duration
        # (the least and the largest first: a NaN or a time outside is rare)
        if t.size and not (float(t.min()) >= -1e-12 * T and float(t.max()) <= T * (1 + 1e-12)):
            bad = (~np.isfinite(t) | (t < -1e-12 * T) | (t > T * (1 + 1e-12))).reshape(-1)
            if bad.any():  # (none: a duration that is not a number, as before)
                v = t.reshape(-1)[np.flatnonzero(bad)[0]]
                raise ParameterError(f"time t = {v:.6g} outside the law's interval "
                                     f"[0, {T:.6g}]")
        return np.asarray(np.clip(t, 0.0, T))

    def cost_parts(self, path: Path, mass: float, eta: float) -> tuple[float, float]:
        """The functional's kinetic and inertial parts for this law along ``path``."""
        return law_cost(self, path, mass, eta)

    def times(self, samples: int) -> Array:
        """``samples`` equally spaced times from 0 to the duration, shape (samples,)."""
        if int(samples) < 2:
            raise ParameterError(f"samples = {samples} must be at least 2")
        return np.linspace(0.0, self.duration, int(samples))


@dataclass(frozen=True)
class UniformLaw(Law):
    """Constant speed ``S / T``; starts and stops at speed (the paper's Fig. 3)."""

    distance: float
    duration: float
    name: str = field(default="uniform", init=False)

    def __post_init__(self) -> None:
        _positive("distance", self.distance)
        _positive("duration", self.duration)

    def _evaluate(self, t: Array) -> Array:
        v = self.distance / self.duration
        return np.stack([v * t, np.full_like(t, v), np.zeros_like(t), np.zeros_like(t)])


@dataclass(frozen=True)
class MinimumJerkLaw(Law):
    """Rest-to-rest quintic ``s = S (10 u^3 - 15 u^4 + 6 u^5)``, ``u = t / T``: minimum jerk,
    zero velocity and acceleration at both ends."""

    distance: float
    duration: float
    name: str = field(default="min-jerk", init=False)

    def __post_init__(self) -> None:
        _positive("distance", self.distance)
        _positive("duration", self.duration)

    def _evaluate(self, t: Array) -> Array:
        S, T = self.distance, self.duration
        u = t / T
        return np.stack([
            S * u**3 * (10 - 15 * u + 6 * u**2),
            S / T * 30 * u**2 * (1 - u) ** 2,
            S / T**2 * 60 * u * (1 - u) * (1 - 2 * u),
            S / T**3 * 60 * (1 - 6 * u + 6 * u**2),
        ])


class TrapezoidalLaw(Law):
    """Trapezoidal velocity: accelerate at ``amax``, cruise at ``v <= vmax``, decelerate.

    With ``duration=None`` the law is the fastest one within the limits (a triangle when
    ``vmax`` is not reached); with a duration the cruise speed is chosen to arrive at exactly
    that time, which must be feasible with ``amax`` and ``vmax`` (``vmax`` may be ``inf``).
    :meth:`shaped` gives the trapezoid of a duration that accelerates for a given fraction of
    it. Read-only once built.
    """

    name = "trapezoid"

    def __init__(self, distance: float, vmax: float, amax: float,
                 duration: float | None = None) -> None:
        """Plan the profile; raises :class:`ParameterError` when the duration is infeasible."""
        S = _positive("distance", distance)
        vm = float(vmax) if vmax == math.inf else _positive("vmax", vmax)
        a = _positive("amax", amax)
        if duration is None:
            if vm == math.inf:
                raise ParameterError("trapezoid: the fastest law needs a finite vmax")
            v = min(vm, math.sqrt(S * a))
            T = S / v + v / a
        else:
            T = _positive("duration", duration)
            disc = a * a * T * T - 4 * a * S
            if -1e-12 * a * a * T * T <= disc < 0:  # a triangle, up to rounding
                disc = 0.0
            if disc < 0:
                tmin = 2 * math.sqrt(S / a)
                raise ParameterError(f"trapezoid: distance {S:.6g} cannot be covered in "
                                     f"duration {T:.6g} with amax {a:.6g} (needs at least "
                                     f"{tmin:.6g})")
            # the smaller root of v^2 - a T v + a S = 0, without the cancellation of
            # (a T - sqrt(disc)) / 2, which gave v = 0 (no motion at all) where a T^2 >> S
            # (a 1e9 s trapezoid over 123 mm: found by the long-motion fuzz shape)
            v = 2.0 * a * S / (a * T + math.sqrt(disc))
            if v > vm * (1 + 1e-12):
                raise ParameterError(f"trapezoid: duration {T:.6g} needs cruise speed {v:.6g} "
                                     f"above vmax {vm:.6g}")
        self._values = (S, vm, a, T, v)

    distance = property(lambda self: self._values[0], doc="Path length covered.")
    vmax = property(lambda self: self._values[1], doc="Speed limit.")
    amax = property(lambda self: self._values[2], doc="Acceleration.")
    duration = property(lambda self: self._values[3], doc="Motion time.")
    cruise = property(lambda self: self._values[4], doc="Cruise speed.")

    def __repr__(self) -> str:
        return (f"TrapezoidalLaw(distance={self.distance!r}, vmax={self.vmax!r}, "
                f"amax={self.amax!r}, duration={self.duration!r})")

    @classmethod
    def shaped(cls, distance: float, duration: float, accel_fraction: float) -> TrapezoidalLaw:
        """The trapezoid of ``duration`` that accelerates during ``accel_fraction`` of it (in
        (0, 1/2]; 1/3: a third accelerating, a third cruising, a third braking), so its shape
        only stretches with the duration."""
        S, T, rho = (_positive(n, v) for n, v in (("distance", distance),
                                                   ("duration", duration),
                                                   ("accel_fraction", accel_fraction)))
        if rho > 0.5:
            raise ParameterError(f"accel_fraction {rho!r} must be at most 1/2")
        v = S / ((1.0 - rho) * T)
        return cls(S, v * (1.0 + 1e-12), v / (rho * T), T)

    def report(self, units: Units) -> dict[str, Any]:
        """The limits and the cruise speed (run units; ``vmax`` None when none was given:
        a trapezoid of a duration without one)."""
        return {"vmax": self.vmax if math.isfinite(self.vmax) else None, "amax": self.amax,
                "cruise_speed": self.cruise}

    def breakpoints(self) -> Array:
        """The ends of the acceleration and deceleration phases."""
        ta = self.cruise / self.amax
        return np.unique([ta, self.duration - ta])

    def _evaluate(self, t: Array) -> Array:
        a, v, T = self.amax, self.cruise, self.duration
        ta = v / a
        t_dec = T - ta
        s = np.where(t < ta, 0.5 * a * t**2,
                     np.where(t <= t_dec, 0.5 * a * ta**2 + v * (t - ta),
                              self.distance - 0.5 * a * (T - t) ** 2))
        ds = np.where(t < ta, a * t, np.where(t <= t_dec, v, a * (T - t)))
        dds = np.where(t < ta, a, np.where(t <= t_dec, 0.0, -a))
        return np.stack([s, ds, dds, np.zeros_like(t)])


def law_cost(law: Law, path: Path, mass: float, eta: float, *, nodes: int = 2000,
             edges: Array | None = None) -> tuple[float, float]:
    """The two parts of the paper's functional for any law along ``path``:
    ``(m/2) Int |rdot|^2 dt`` and ``(eta m^2 / 2) Int |rddot|^2 dt``, with
    ``|rdot| = sdot`` and ``|rddot|^2 = sddot^2 + kappa^2 sdot^4`` (Gauss-Legendre quadrature
    on ``nodes`` equal panels, or on the given panel ``edges``; exact for polynomial laws of
    degree <= 3 per panel on lines and arcs)."""
    x, w = np.polynomial.legendre.leggauss(8)
    if edges is None:
        edges = np.linspace(0.0, law.duration, nodes + 1)
    h = np.diff(edges)
    t = (0.5 * (edges[:-1] + edges[1:]))[:, None] + 0.5 * h[:, None] * x[None, :]
    s, ds, dds, _ = law.evaluate(t)
    kappa = _curvature_at_s(path, s)
    kin = 0.5 * mass * np.sum(0.5 * h * ((ds**2) @ w))
    acc2 = dds**2 + kappa**2 * ds**4
    inert = 0.5 * eta * mass**2 * np.sum(0.5 * h * (acc2 @ w))
    return float(kin), float(inert)


def _curvature_at_s(path: Path, s: Array) -> Array:
    k = getattr(path, "constant_curvature", None)
    if k is not None:
        return np.full_like(s, k)
    return np.asarray(path.curvature(path.parameter_at(s))[0])


def _trapezoid(r: Any) -> TrapezoidalLaw:
    """The registered trapezoid: the fastest within vmax and amax, or the one of a duration
    (within vmax and amax when given, else a third of it accelerating); errors in the
    config's units."""
    S, p, u = r.path.length, r.params, r.units
    vmax, amax, T = p.get("vmax"), p.get("amax"), p.get("duration")
    speed, accel = u.length_mm / u.time_s, u.length_mm / u.time_s**2
    if T is None and (vmax is None or amax is None):
        raise ParameterError("the trapezoid law needs vmax and amax (the fastest law within "
                             "them) or a duration (or, in a program, duration = \"fit\")")
    if T is not None and amax is None:
        amax = 4.5 * S / T**2  # a third of the time accelerating
    try:
        return TrapezoidalLaw(S, math.inf if vmax is None else vmax, amax, T)
    except ParameterError:
        T_ = float(T) * u.time_s
        tmin = 2 * math.sqrt(S / amax) * u.time_s
        raise ParameterError(
            f"trapezoid: {u.mm(S):.6g} mm cannot be covered in {T_:.6g} s with amax "
            f"{amax * accel:.6g} mm/s^2" + ("" if vmax is None else
                                             f" and vmax {vmax * speed:.6g} mm/s")
            + f" (it needs at least {tmin:.6g} s with that amax)") from None


def _fit_trapezoid(r: Any, shortest: Any) -> TrapezoidalLaw:
    """The shortest trapezoid within the motors and the given vmax and amax: for each
    fraction ``rho`` of the time spent accelerating the shape only stretches with the
    duration, so its shortest duration is a one-dimensional search, bounded below by vmax
    (``T >= S / ((1 - rho) vmax)``) and amax (``T^2 >= S / (rho (1 - rho) amax)``); the
    fraction is chosen by golden-section search (the duration is unimodal in it: the torque
    limits favour a longer acceleration, the speed limits a shorter one)."""
    S, p = r.path.length, r.params
    vmax, amax = p.get("vmax"), p.get("amax")

    def duration(rho: float) -> float:
        t_min = 0.0
        if vmax is not None:
            t_min = max(t_min, S / ((1.0 - rho) * vmax))
        if amax is not None:
            t_min = max(t_min, math.sqrt(S / (rho * (1.0 - rho) * amax)))
        return float(shortest(lambda T: TrapezoidalLaw.shaped(S, T, rho), t_min))

    lo, hi = 0.02, 0.5
    g = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = hi - g * (hi - lo), lo + g * (hi - lo)
    fa, fb = duration(a), duration(b)
    for _ in range(12):  # the fraction to ~1e-3: the duration is flat at its minimum
        if fa <= fb:
            hi, b, fb = b, a, fa
            a = hi - g * (hi - lo)
            fa = duration(a)
        else:
            lo, a, fa = a, b, fb
            b = lo + g * (hi - lo)
            fb = duration(b)
    rho, T = (a, fa) if fa <= fb else (b, fb)
    T_triangle = duration(0.5)  # the bracket's end (no cruise), which the search never meets
    if T_triangle < T:
        rho, T = 0.5, T_triangle
    return TrapezoidalLaw.shaped(S, T, rho)


def _register() -> None:
    duration = Param("number", "s", 1.0, "motion time", positive=True)
    register_law(LawType("uniform", {"duration": duration},
                         lambda r: UniformLaw(r.path.length, r.params["duration"]),
                         "constant speed; starts and stops at speed (the paper's Fig. 3)"))
    register_law(LawType("min-jerk", {"duration": duration},
                         lambda r: MinimumJerkLaw(r.path.length, r.params["duration"]),
                         "rest-to-rest quintic, minimum jerk"))
    register_law(LawType(
        "trapezoid",
        {"vmax": Param("number", "mm/s", None, "cruise speed limit", positive=True),
         "amax": Param("number", "mm/s^2", None, "acceleration", positive=True),
         "duration": Param("number", "s", None, "motion time (default: the fastest within "
                           "vmax and amax)", positive=True)},
        _trapezoid, "trapezoidal speed: accelerate, cruise, decelerate (vmax and amax, or a "
        "duration: then a third accelerating unless amax is given)", fit=_fit_trapezoid))


_register()


#: The result type of the laws stage: the law itself, with ``status``, ``success`` and
#: ``message`` (see :class:`Law`).
LawResult = Law
