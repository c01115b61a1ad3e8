"""A move's law: any registered law built from the move's keys (SI), planned on the robot's
dynamics when the law needs them, or a fixed-shape law with its duration in seconds or
``"fit"``: the shortest duration for which the law stays within the motors (torque, speed,
and the joint acceleration and jerk when set; regula falsi on a bracket)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._arrays import Array
from ..dynamics import Model, gravity_torques, inverse_dynamics
from ..errors import ParameterError
from ..laws import Law, LawRequest, LawType, law_type
from ..laws.constraints import PathDynamics
from ..motors import MotorLimits
from ..params import to_run_units
from ..paths import Path
from ..trajectory import Trajectory
from ..units import SI
from .moves import Move

#: ``traj(law, times) -> Trajectory``: the motion of a law at ``times`` (None: on fixed
#: fractions of its duration).
Sampling = Callable[[Law, Array | None], Trajectory]
#: Samples of a law's check (besides both sides of its breakpoints).
CHECK_SAMPLES = 401


def check_times(law: Law) -> Array:
    """Where a law is checked against the motors: :data:`CHECK_SAMPLES` equally spaced times
    and both sides of every breakpoint (where the acceleration jumps: its peaks are there)."""
    b = law.breakpoints()
    eps = 1e-9 * law.duration
    t = np.concatenate([law.times(CHECK_SAMPLES), b - eps, b + eps])
    return np.sort(np.clip(t, 0.0, law.duration))


def law_values(kind: LawType, mv: Move) -> dict[str, Any]:
    """The law's keys in SI: its declared defaults, then the move's own."""
    defaults = {k: p.default for k, p in kind.params.items()
                if not p.required and p.default is not None and k != "duration"}
    return {**to_run_units(defaults, kind.params, SI), **mv.law_params}


def move_law(mv: Move, path: Path, dynamics: PathDynamics, motors: MotorLimits | None,
             grid: int | Array, traj: Sampling, model: Model) -> Law:
    """The move's law along ``path`` (for a joint move, a :class:`LengthPath` of its joint
    line): a law planned on ``dynamics`` within ``motors`` (its grid ``grid`` unless the move
    sets one), a fixed-shape law with its duration, or the shortest such law within the
    motors (``duration = "fit"``). ``traj(law)`` samples the motion."""
    kind = law_type(mv.law)
    values = law_values(kind, mv)
    if kind.needs_dynamics:
        if "grid" in kind.params and "grid" not in mv.law_params:
            values["grid"] = grid
        return kind.build(LawRequest(path, values, model.inertia.point_mass, dynamics, SI,
                                     motors))
    mass = model.inertia.point_mass
    has_duration = "duration" in kind.params
    optional = has_duration and kind.params["duration"].default is None

    def build(duration: float | None) -> Law:
        v = {k: x for k, x in values.items() if x is not None}
        if duration is not None:
            v["duration"] = duration
        return kind.build(LawRequest(path, v, mass, None, SI))

    if mv.duration != "fit":
        if isinstance(mv.duration, (int, float)):
            return build(float(mv.duration))
        if optional or not has_duration:
            return build(None)
        return build(float(kind.params["duration"].default))
    if motors is None:
        raise ParameterError("duration = \"fit\" needs the motors' limits")
    if not has_duration:
        raise ParameterError(f"law {mv.law!r} has no duration to fit")
    limits = motors

    def shortest(family: Callable[[float], Law], t_min: float) -> float:
        """The shortest ``T >= t_min`` with ``family(T)`` within the motors."""
        def sampled(T: float) -> float:
            law = family(T)
            tr_ = traj(law, check_times(law) if law.breakpoints().size else None)
            tr, sp = limits.ratios(inverse_dynamics(model, tr_.q, tr_.dq, tr_.ddq), tr_.dq)
            return max(tr, sp, limits.motion_ratio(tr_.ddq, _jerk(tr_)))

        ratio = stretched_ratio(family, traj, model, limits) or sampled
        return max(t_min, shortest_within(ratio))

    if kind.fit is not None:
        return kind.fit(LawRequest(path, values, mass, None, SI), shortest)
    return build(shortest(build, 0.0))


def shortest_within(ratio: Callable[[float], float]) -> float:
    """The shortest duration ``T`` (s, to 1e-6 relative) with ``ratio(T) <= 1``: a bracket by
    doubling (or halving), then regula falsi with the Illinois correction, keeping a bracket
    ``ratio(lo) > 1 >= ratio(hi)`` and returning its ``hi``."""
    seen: dict[float, float] = {}

    def r(T: float) -> float:  # the excess over the limits, remembered
        if T not in seen:
            seen[T] = ratio(T) - 1.0
        return seen[T]

    hi = 0.05
    while r(hi) > 0.0:
        hi *= 2.0
        if hi > 1e4:
            raise ParameterError("no duration up to 10^4 s keeps the law within the motors")
    lo = hi / 2.0
    if r(lo) <= 0.0:  # even the first try fits: come down
        while lo > 1e-4 and r(lo) <= 0.0:
            hi, lo = lo, lo / 2.0
    r_lo, r_hi, side = r(lo), r(hi), 0
    for _ in range(100):
        if hi - lo <= 1e-6 * hi:
            break
        if math.isfinite(r_lo) and r_lo > r_hi:  # the secant through the bracket's ends
            mid = hi - r_hi * (hi - lo) / (r_hi - r_lo)
            mid = min(max(mid, lo + 1e-3 * (hi - lo)), hi - 1e-3 * (hi - lo))
        else:
            mid = 0.5 * (lo + hi)
        v = r(mid)
        if v > 0.0:
            lo, r_lo = mid, v
            r_hi = r_hi * 0.5 if side < 0 else r_hi  # Illinois: the stale end's weight halves
            side = -1
        else:
            hi, r_hi = mid, v
            r_lo = r_lo * 0.5 if side > 0 else r_lo
            side = 1
    return hi


def stretched_ratio(build: Callable[[float], Law], traj: Sampling, model: Model,
                    motors: MotorLimits) -> Callable[[float], float] | None:
    """The motors' ratio at any duration ``T`` from one sampling, for a law whose shape only
    stretches with its duration (``s_T(t) = s_1(t / T)``: uniform, min-jerk); None for other
    laws (checked on the law itself). With the joint motion at ``T = 1`` on the same fractions
    of the motion, ``qdot_T = qdot / T`` and ``qddot_T = qddot / T^2``, so the torques are
    ``(M qddot + c(q, qdot)) / T^2 + g(q) + friction(qdot / T)`` exactly."""
    one, two = build(1.0), build(2.0)
    f = np.linspace(0.0, 1.0, 65)
    scale = np.array([1.0, 2.0, 4.0, 8.0])[:, None]
    a, b = one.evaluate(f), two.evaluate(2.0 * f) * scale
    if not np.allclose(a, b, rtol=1e-9, atol=1e-12 * float(np.abs(a).max())):
        return None
    tr = traj(one, check_times(one) if one.breakpoints().size else None)
    q, dq, ddq = tr.q, tr.dq, tr.ddq
    ine = model.inertia
    inertial = inverse_dynamics(Model(model.robot, ine.frictionless(), model.assembly,
                                      tol=model.tol), q, dq, ddq)
    g = gravity_torques(model, q)
    jerk = _jerk(tr)

    def ratio(T: float) -> float:
        dqT = dq / T
        tr, sp = motors.ratios(inertial / (T * T) + g + ine.friction_torques(dqT), dqT)
        return max(tr, sp, motors.motion_ratio(ddq / (T * T), jerk / T**3))

    return ratio


def _jerk(tr: Trajectory) -> Array:
    """The joint jerks (n - 1, 2) between consecutive samples (finite differences)."""
    dt = np.diff(tr.t)
    return np.asarray(np.diff(tr.ddq, axis=0) / np.where(dt > 0, dt, np.inf)[:, None])


@dataclass(frozen=True)
class LengthPath(Path):
    """A stand-in path of a given length (joint moves: their laws only need the length)."""

    total: float
    p0: float = 0.0
    p1: float = 1.0
    constant_curvature: float = 0.0

    def derivatives(self, p: object) -> tuple[Array, Array, Array, Array]:
        """A straight segment of the length."""
        p = self._check_parameter(p)
        z = np.zeros(np.shape(p) + (2,))
        r = z.copy()
        r[..., 0] = p * self.total
        d = z.copy()
        d[..., 0] = self.total
        return r, d, z, z.copy()

    @property
    def length(self) -> float:
        """The length."""
        return self.total
