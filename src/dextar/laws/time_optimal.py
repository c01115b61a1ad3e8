"""Time-optimal law of motion along a path within the limits of the robot's dynamics.

The solver needs the robot's dynamics along the path only through the small
:class:`~dextar.laws.constraints.PathDynamics` interface (implemented for the exact
closed-chain model by :class:`dextar.dynamics.along_path.RobotAlongPath`), so this module,
like every law, sits below the trajectory and dynamics stages; the limits are constraint
objects (:mod:`dextar.laws.constraints`: torque, speed, torque-speed envelope) that a caller
composes. ``dextar.dynamics.time_optimal_law(model, path, ...)`` is the one-call form.

With ``x = sdot^2`` and ``u = sddot`` every constraint is a set of linear rows in ``(u, x)``
at each grid point (or a cap on ``x``); the speed-dependent bounds (viscous friction, the
torque-speed envelope) are tangents at a tangent point, first at the motors' speed limits,
then at the previous iterate's speeds, until the tangent settles (:data:`TANGENT_RTOL`).

The solver is reachability analysis (TOPP-RA, Pham & Pham 2018) with the *interpolation*
discretisation on a grid of arc lengths (equal segments, or finer where the dynamics change
fast): on each segment ``[s_k, s_{k+1}]`` the acceleration ``u_k`` is constant and
the limits are imposed at both ends, at ``(x_k, u_k)`` and at ``(x_k + 2 ds u_k, u_k)``, so
they hold on both sides of every knot, and in between up to the curvature of the dynamics
(second order in the grid step). A backward pass computes the controllable interval of ``x``
at each grid point (a two-variable linear programme solved exactly by Fourier-Motzkin
elimination of ``u``, the static rows precomputed for all points at once), then a forward pass
takes the largest admissible acceleration from rest.

Output check and margin: the settled law is then sampled densely (both ends and seven
interior points of every segment) through the exact model with friction; if a constraint of
a kind (torque, speed) is exceeded by more than ``tol`` (default 1e-3), every constraint of
that kind is tightened by the excess and the problem solved again (a few iterations at most).
The law reports ``status`` (0: the limits hold within ``tol`` on the check samples; 1: they do
not after the iterations, with the excess in ``message``) and ``max_torque_ratio``. When no
motion within the limits exists at all, :class:`~dextar.errors.InfeasibleError` names the
point, the motor and the torque.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from .._arrays import Array, check_whole
from .._compiled import usable
from ..errors import ConfigError, InfeasibleError, ParameterError
from ..motors import MotorLimits
from ..params import Param
from ..units import Units
from .base import Law
from .constraints import (
    Constraint,
    DegeneracyCondition,
    JointSamples,
    PathCoefficients,
    PathDynamics,
    Tangent,
    motor_constraints,
    point_rows,
    ratios_by_kind,
    speed_cap,
)
from .registry import LawType, register_law

try:  # the reachability analysis compiled (_reach.c), built by pip where a C compiler is
    from . import _reach as _compiled
except ImportError:  # pragma: no cover - installed without a C compiler: the Python passes
    _compiled = None  # type: ignore[assignment]  # the module or None, as USE_COMPILED says

#: The compiled passes' interface this module and :mod:`.optimal` (its ``chebval``) call
#: (``REACH_VERSION`` in _reach.c): a build of another version (an old one left in place) is
#: not used.
REACH_VERSION = 2
if not usable(_compiled, REACH_VERSION):
    _compiled = None  # type: ignore[assignment]  # an old build: the Python passes instead

#: Whether the reachability analysis runs compiled (where it was built): False gives the
#: Python passes (the same squared speeds to the last bit; the tests compare the two).
USE_COMPILED = _compiled is not None

#: Greatest number of solves (friction tangent updates and limit margins).
MAX_SOLVES = 8
#: The friction tangent has settled when no speed along the path moves by more than this
#: fraction of the largest between two solves. The iteration converges quadratically, so the
#: law's duration is then within about the square of this of the settled one: over 96 designs
#: of the pick-and-place sweep, 3e-2 moved the cycle times by at most 1.8e-5 relative against
#: 1e-3, far below the grid's own loss (about 1e-3 at 400 segments).
TANGENT_RTOL = 3e-2
#: Rounds of refinement before the limits are tightened: the segments whose check samples
#: exceed a limit are split (the excess between grid points falls with the square of the
#: segment) into as many pieces as bring it to a quarter of the tolerance, at most
#: :data:`SPLIT_MOST` each (a short blend on an equal grid has few points: the law tightened
#: every limit by its excess there, 62 % on a 2 mm blend of 400 segments, three times slower
#: than on a grid fine there).
MAX_SPLIT = 2
SPLIT_MOST = 8
#: The split only where a ratio exceeds 1 by more than this: a smaller excess is tightened
#: away (about half of it lost in duration) for two solves, where a split costs more (the
#: pick-and-place design sweep 16 % slower splitting every excess, for cycles 0-0.15 %
#: shorter).
SPLIT_ABOVE = 1e-2
#: Where the output check samples each segment (fractions of its duration): both ends
#: (the acceleration jumps at the knots) and seven interior points.
CHECK_FRACTIONS = np.concatenate([[1e-9], np.linspace(0.125, 0.875, 7), [1.0 - 1e-9]])


@dataclass(frozen=True)
class TimeOptimalLaw(Law):
    """Piecewise-constant acceleration law found by :func:`solve_time_optimal_law`.

    Attributes
    ----------
    knots_t, knots_s, knots_v : ndarray, shape (N + 1,)
        Time, arc length and speed at the grid points; ``accel`` (N,) on each segment.
    torque_limit, speed_limit : tuple
        The limits of the motors at A and D (speed limit ``inf`` when none).
    max_torque_ratio, max_speed_ratio : float
        Largest ``|tau_i| / limit_i`` and ``|qdot_i| / limit_i`` on the check samples.
    status : int
        0 when the limits hold within the tolerance on the check samples, 1 otherwise, 2
        when not checked (``check=False``: a start for another law).
    message : str
        What the solver did, in words.
    solves : int
        Number of reachability solves (margin and friction iterations).
    """

    distance: float
    duration: float
    knots_t: Array = field(repr=False)
    knots_s: Array = field(repr=False)
    knots_v: Array = field(repr=False)
    accel: Array = field(repr=False)
    torque_limit: tuple[float, float] = (np.inf, np.inf)
    speed_limit: tuple[float, float] = (np.inf, np.inf)
    max_torque_ratio: float = 0.0
    max_speed_ratio: float = 0.0
    status: int = 0
    message: str = ""
    solves: int = 1
    name: str = field(default="time-optimal", init=False)

    def breakpoints(self) -> Array:
        """The grid points, where the acceleration jumps."""
        return self.knots_t[1:-1]

    def report(self, units: Units) -> dict[str, Any]:
        """The torque limits (N m) and the largest torque ratio on the check samples."""
        return {"torque_limit_Nm": [float(units.torque_in_nm(v)) for v in self.torque_limit],
                "max_torque_ratio_check_samples": self.max_torque_ratio}

    def _evaluate(self, t: Array) -> Array:
        k = np.clip(np.searchsorted(self.knots_t, t, side="right") - 1, 0, self.accel.size - 1)
        tau = t - self.knots_t[k]
        u = self.accel[k]
        v = self.knots_v[k]
        s = self.knots_s[k] + v * tau + 0.5 * u * tau * tau
        return np.stack([s, v + u * tau, u, np.zeros_like(t)])


def solve_time_optimal_law(dynamics: PathDynamics, *,
                           torque_limit: tuple[float, float] | None = None,
                           speed_limit: tuple[float, float] | None = None,
                           motors: MotorLimits | None = None,
                           constraints: Sequence[Constraint] | None = None,
                           grid: int | Array = 400, tol: float = 1e-3,
                           units: Units | None = None, check: bool = True) -> TimeOptimalLaw:
    """The fastest rest-to-rest law along a path within motor torque and speed limits.

    Parameters
    ----------
    dynamics : PathDynamics
        The robot along the path (gravity and friction included).
    torque_limit : (float, float)
        ``tau_max`` of the motors at A and D (run torque unit).
    speed_limit : (float, float), optional
        ``|qdot|`` limits of the motors (rad per run time unit).
    motors : MotorLimits, optional
        The limits with a torque-speed envelope (instead of the two above).
    constraints : sequence of Constraint, optional
        The limits as constraint objects (instead of the above; see
        :mod:`dextar.laws.constraints`); one of them must limit the torques.
    grid : int or ndarray, shape (N + 1,)
        Number of equal segments in arc length, or the grid's arc lengths (increasing from 0
        to the path's length; finer where the dynamics change fast, e.g. in a blend). A
        dynamics with an ``adjust_grid(s)`` method moves grid points where it needs them (a
        crossing of the parallel singularity curve:
        :class:`dextar.dynamics.crossing.RobotAcrossPath`), and coefficients with
        ``conditions`` add :class:`~dextar.laws.constraints.DegeneracyCondition` to the
        constraints.
    tol : float
        Allowed relative excess of a torque or speed over its limit on the check samples.
    units : Units, optional
        Only for the words of an error (points in mm, torques in N m).
    check : bool
        False: the reachability analysis' law on the grid as it is (its friction tangent
        settled), not sampled through the exact model, so neither tightened nor refined
        between the grid points (status 2, "not checked"): a start for another law (the
        jerk-limited law's), never a plan.

    Returns
    -------
    TimeOptimalLaw
        With ``status`` and ``message``.

    Raises
    ------
    InfeasibleError
        No motion within the limits exists: names the point (mm), the arc length, the motor
        and the torque needed against the limit.
    ParameterError
        No torque limit, a bad tolerance, or a third-order limit (jerk, torque rate: see
        :func:`~dextar.laws.solve_jerk_limited_law`).
    """
    cons = _constraints(torque_limit, speed_limit, motors, constraints)
    if not (0 < tol < 1):
        raise ParameterError(f"tolerance {tol!r} must be in (0, 1)")
    length = float(dynamics.length)
    s_grid = grid_points(grid, length)
    adjust = getattr(dynamics, "adjust_grid", None)  # grid points a dynamics needs (crossings)
    if adjust is not None:
        s_grid = adjust(s_grid)
    co = dynamics.coefficients(s_grid)
    tmax = np.asarray(_torque_limit(cons), float)
    if co.conditions and not any(isinstance(c, DegeneracyCondition) for c in cons):
        cons = (*cons, DegeneracyCondition())  # a crossing's condition: never left out
    _check_holding(co, tmax, units)
    ds = np.diff(co.s)
    # the tightening of each kind of limit (the message names torque and speed always)
    scales = dict.fromkeys(("torque", "speed", *(c.kind for c in cons)), 1.0)
    law: TimeOptimalLaw | None = None
    ratio: dict[str, float] = {}
    tangent = any(c.needs_tangent(co) for c in cons)  # speed-dependent bounds
    # the tangent points of the speed-dependent bounds, first at the speed limits
    x0 = _first_tangent(speed_cap(cons, co)) if tangent else None
    limits = (_torque_limit(cons), _speed_limit(cons))
    split = 0
    coarse: tuple[PathCoefficients, Array, Array | None] | None = None  # (before a split)
    for solve in range(1, MAX_SOLVES + 1):
        try:
            x = _reachability(co, ds, [c.scaled(scales) for c in cons], x0, units, tmax)
        except InfeasibleError:
            if coarse is not None and all(v == 1.0 for v in scales.values()):
                # the refined grid (its friction tangent interpolated) found none where the
                # grid before found one: back to that grid, and tightening as without a split
                (co, ds, x0), coarse, split = coarse, None, MAX_SPLIT
                continue
            if law is None or all(v == 1.0 for v in scales.values()):
                raise  # no motion within the user's own limits
            # the limits tightened for the grid leave none: the last law, beyond them
            ds = np.diff(law.knots_s)
            break

        tangent_moved = tangent and (x0 is None or np.abs(np.sqrt(x) - np.sqrt(x0)).max()
                                     > TANGENT_RTOL * np.sqrt(x).max())
        bounded = x0 is not None or not tangent  # friction bound in place
        if tangent:
            x0 = x
        if tangent_moved and solve < MAX_SOLVES:
            continue  # the check waits for the friction tangent to settle
        law = _law(length, co.s, x, *limits, solve)
        if not check:
            return _with(law, 0.0, 0.0, 2, "not checked: the reachability analysis' law on "
                         f"the grid of {len(ds)} segments, not sampled between its points")
        dts = np.diff(law.knots_t)
        times = (law.knots_t[:-1, None] + dts[:, None] * CHECK_FRACTIONS[None, :]).reshape(-1)
        js = dynamics.samples(law, times)
        ratio = ratios_by_kind(cons, js)
        law = _with(law, ratio.get("torque", 0.0), ratio.get("speed", 0.0), 0, "")
        if all(r <= 1 + tol for r in ratio.values()):
            break
        if (bounded and split < MAX_SPLIT and solve < MAX_SOLVES
                and max(ratio.values()) > 1 + SPLIT_ABOVE):
            # where the excess is: those segments split (the same limits on a finer grid)
            seg = _segment_ratios(cons, js, len(ds))
            pieces = np.where(seg > 1 + tol, np.clip(np.ceil(np.sqrt(
                4.0 * np.maximum(seg - 1.0, 0.0) / tol)), 2, SPLIT_MOST), 1).astype(int)
            if pieces.max() > 1:
                split += 1
                if coarse is None:
                    coarse = (co, ds, x0)
                s_new = split_segments(co.s, pieces)
                if adjust is not None:
                    s_new = adjust(s_new)
                if x0 is not None:
                    x0 = np.interp(s_new, co.s, x0)
                co = dynamics.coefficients(s_new)
                _check_holding(co, tmax, units)
                ds = np.diff(co.s)
                continue
        if bounded:  # discretisation excess: tighten by it
            for kind, r in ratio.items():
                scales[kind] *= min(1.0, (1 + 0.25 * tol) / max(r, 1e-300))
    assert law is not None
    return _verdict(law, ratio, scales, ds, tol, units)


def _constraints(torque_limit: tuple[float, float] | None,
                 speed_limit: tuple[float, float] | None, motors: MotorLimits | None,
                 constraints: Sequence[Constraint] | None) -> tuple[Constraint, ...]:
    """The constraints of a solve, from whichever form the caller gave."""
    if constraints is not None:
        cons = tuple(constraints)
    elif motors is not None:
        cons = motor_constraints(motors)
    elif torque_limit is not None:
        cons = motor_constraints(MotorLimits.of(torque_limit, speed_limit))
    else:
        raise ParameterError("a time-optimal law needs torque limits (or motors)")
    if not any(c.torque_limit is not None for c in cons):
        raise ParameterError("a time-optimal law needs a torque limit among its constraints")
    third = [c for c in cons if c.order == 3]
    if third:  # (its check measured them, and a refined grid never met them)
        raise ParameterError(
            "a second-order time-optimal law cannot hold a third-order limit ("
            + ", ".join(_third_words(c) for c in third) + "): "
            "dextar.laws.solve_jerk_limited_law plans within it (the registered "
            "time-optimal law takes it when the motors have one)")
    return cons


def _third_words(c: Constraint) -> str:
    """A third-order limit in words, with its values in SI."""
    jerk = getattr(c, "max_jerk", None)
    if jerk is not None:
        return f"max_jerk ({jerk[0]:g}, {jerk[1]:g}) rad/s^3"
    rate = getattr(c, "max_torque_rate", None)
    if rate is not None:
        return f"max_torque_rate ({rate[0]:g}, {rate[1]:g}) N m/s"
    return c.kind


def _torque_limit(cons: Sequence[Constraint]) -> tuple[float, float]:
    """The peak torques of the first torque constraint."""
    return next(t for c in cons if (t := c.torque_limit) is not None)


def _speed_limit(cons: Sequence[Constraint]) -> tuple[float, float]:
    """The lowest speed limit of each motor (``inf`` without one)."""
    w = np.full(2, np.inf)
    for c in cons:
        if c.speed_limit is not None:
            w = np.minimum(w, np.asarray(c.speed_limit, float))
    return float(w[0]), float(w[1])


def _verdict(law: TimeOptimalLaw, ratio: dict[str, float], scales: dict[str, float],
             ds: Array, tol: float, units: Units | None = None) -> TimeOptimalLaw:
    """The settled law with its status and the message in words (the segments' lengths in
    mm with ``units``)."""
    n, length = len(ds), law.distance

    def mm(x: float) -> str:
        return f"{x:.4g}" if units is None else f"{units.mm(x):.4g} mm"

    ok = all(r <= 1 + tol for r in ratio.values())
    where = (f"{n} segments of {mm(ds[0])}" if np.ptp(ds) <= 1e-9 * length else
             f"{n} segments of {mm(ds.min())} to {mm(ds.max())}")
    margin = "" if all(v == 1.0 for v in scales.values()) else (
        "; limits tightened by " + " and ".join(f"{1 - v:.2%} ({k})" for k, v in scales.items())
        + " so that they hold between the grid points")
    extra = "".join(f", {k} ratio {r:.5f}" for k, r in ratio.items()
                    if k not in ("torque", "speed", "degeneracy"))
    ratios = (f"torque ratio {law.max_torque_ratio:.5f}, speed ratio "
              f"{law.max_speed_ratio:.5f}{extra}")
    if ok:
        msg = (f"time-optimal within the limits: {ratios} on the check samples ({where}, "
               f"{law.solves} solve(s)){margin}")
        return _with(law, law.max_torque_ratio, law.max_speed_ratio, 0, msg)
    msg = (f"limits exceeded on the check samples after {law.solves} solves: {ratios} "
           f"(tolerance {1 + tol:g}); refine the grid")
    return _with(law, law.max_torque_ratio, law.max_speed_ratio, 1, msg)


def _segment_ratios(cons: Sequence[Constraint], js: JointSamples, n: int) -> Array:
    """Each segment's largest ratio of a limited quantity to its limit (n,) on the check
    samples (:data:`CHECK_FRACTIONS` of each segment, in order)."""
    out = np.zeros(n)
    for c in cons:
        r = np.asarray(c.sample_ratios(js), float)
        if r.size == n * len(CHECK_FRACTIONS):
            out = np.maximum(out, r.reshape(n, -1).max(axis=1))
    return out


def split_segments(s: Array, pieces: Array) -> Array:
    """The grid ``s`` with segment ``k`` split into ``pieces[k]`` equal ones."""
    many = pieces > 1
    n = pieces[many]
    k = np.repeat(np.flatnonzero(many), n - 1)
    # (each new point's place in its segment, 1 .. n - 1)
    j = np.arange(k.size) - np.repeat(np.cumsum(n - 1) - (n - 1), n - 1) + 1
    return np.sort(np.concatenate([s, s[k] + (s[k + 1] - s[k]) * j / np.repeat(n, n - 1)]))


def _first_tangent(x: Array) -> Array | None:
    """The first tangent points of the speed-dependent bounds: the squared path speeds
    (N + 1,) at which a motor reaches its speed limit (``x``, the speed cap). Every tangent
    bounds ``sqrt(x)`` from above, so the first law is within the limits; from these speeds,
    above the optimum's, the iteration settles in about one solve fewer than from a first
    solve without those bounds (2.8 instead of 3.7 per move over the pick-and-place sweep,
    cycle times as close to the settled ones). None without a finite speed limit (the first
    solve then goes without)."""
    finite = np.isfinite(x)
    if not finite.any():
        return None
    return np.asarray(np.where(finite, x, x[finite].max()))


def grid_points(grid: int | Array, length: float) -> Array:
    """The grid's arc lengths (N + 1,) from a number of equal segments or given points
    (checked: a whole number of at least 10 segments, or at least 11 finite increasing arc
    lengths from 0 to ``length``)."""
    if np.ndim(grid) == 0:
        check_whole(grid, 10, "grid", " segments")
        return np.linspace(0.0, length, int(grid) + 1)
    s = np.asarray(grid, float)
    if s.ndim != 1 or s.size < 11:
        raise ParameterError(f"a grid of arc lengths must have at least 11 points, got shape "
                             f"{s.shape}")
    if not np.all(np.isfinite(s)) or not np.all(np.diff(s) > 0):
        raise ParameterError("a grid of arc lengths must be finite and strictly increasing")
    if abs(s[0]) > 1e-9 * length or abs(s[-1] - length) > 1e-9 * length:
        raise ParameterError(f"a grid of arc lengths must run from 0 to the path's length "
                             f"{length:.6g}, got {s[0]:.6g} to {s[-1]:.6g}")
    s = s.copy()
    s[0], s[-1] = 0.0, length
    return s


def _with(law: TimeOptimalLaw, tr: float, sp: float, status: int, message: str
          ) -> TimeOptimalLaw:
    return TimeOptimalLaw(law.distance, law.duration, law.knots_t, law.knots_s, law.knots_v,
                          law.accel, law.torque_limit, law.speed_limit, tr, sp, status, message,
                          law.solves)


def _describe(co: PathCoefficients, k: int, units: Units | None) -> str:
    if units is None:
        return f"arc length s = {co.s[k]:.6g} (P = ({co.P[k, 0]:.6g}, {co.P[k, 1]:.6g}))"
    return (f"P = {units.point_text(co.P[k])} (arc length s = {units.mm(co.s[k]):.6g} mm)")


def _torque(units: Units | None, value: float) -> str:
    return f"{value:.6g}" if units is None else units.torque_text(value)


def _check_holding(co: PathCoefficients, tmax: Array, units: Units | None) -> None:
    """Gravity alone must be within the limits everywhere on the path (where holding the
    robot still means something: :attr:`PathCoefficients.holdable`)."""
    ratio = np.abs(co.g) / tmax
    if co.holdable is not None:
        ratio = np.where(co.holdable[:, None], ratio, 0.0)
    if ratio.max() > 1.0:
        k, i = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        motor = "A" if i == 0 else "D"
        exc = InfeasibleError(
            f"no motion within the limits: the motor at {motor} needs "
            f"{_torque(units, abs(co.g[k, i]))} to hold the robot still against gravity at "
            f"{_describe(co, int(k), units)}, above its limit {_torque(units, tmax[i])}")
        exc.holding = True  # type: ignore[attr-defined]  # (gravity alone, not the motion)
        raise exc


def _rows(co: PathCoefficients, ds: Array, constraints: Sequence[Constraint],
          x0: Array | None) -> tuple[Array, Array, Array]:
    """Static rows ``Gu u + Gx x <= h`` of every stage, arrays (N, m): the constraints' rows
    at both points of each stage and the speed cap at its first."""
    rows = point_rows(constraints, Tangent(co, x0))
    return _stage_rows(rows.pu, rows.px, rows.ph, speed_cap(constraints, co), ds)


def _stage_rows(pu: Array, px: Array, ph: Array, xmax: Array, ds: Array
                ) -> tuple[Array, Array, Array]:
    """The rows of each stage from the rows at its two points (interpolation scheme): the
    torque rows ``pu u + px X <= ph`` (N + 1, m) at point k with ``X = x`` and at point k + 1
    with ``X = x + 2 ds u`` (``ds`` (N,) the stages' lengths), and ``0 <= x <= xmax`` at point
    k (at point k + 1 the controllable set of the next stage holds them)."""
    n = len(ds)
    one = np.ones((n, 1))
    Gu = np.concatenate([pu[:-1], np.zeros((n, 2)), pu[1:] + 2 * ds[:, None] * px[1:]],
                        axis=1)
    Gx = np.concatenate([px[:-1], one, -one, px[1:]], axis=1)
    h = np.concatenate([ph[:-1], xmax[:-1, None], np.zeros((n, 1)), ph[1:]], axis=1)
    return Gu, Gx, h


def _reachability(co: PathCoefficients, ds: Array, constraints: Sequence[Constraint],
                  x0: Array | None, units: Units | None, tmax: Array) -> Array:
    """Squared speeds ``x`` at the grid points of the fastest admissible motion: the
    controllable sets from rest at the end backward, then the largest acceleration from rest
    at the start forward (``tmax``: the user's torque limits, for the words of an error)."""
    Gu, Gx, h = _rows(co, ds, constraints, x0)

    def unreachable(k: int) -> InfeasibleError:
        return _unreachable(co, k, tmax, units)

    return _passes(Gu, Gx, h, ds, unreachable)


def _passes(Gu: Array, Gx: Array, h: Array, ds: Array,
            unreachable: Callable[[int], InfeasibleError]) -> Array:
    """The squared speeds (N + 1,) from the stages' rows ``Gu u + Gx x <= h`` (N, m) and
    lengths ``ds`` (N,): the elimination and both passes, compiled where they were built
    (:data:`USE_COMPILED`), else in Python; ``unreachable(k)`` is the error where no motion
    passes stage ``k``. A row no motion meets (``h = -inf``) empties its stage; a row that is
    not a number is a constraint's error, named."""
    Gu, Gx, h, ds = (np.asarray(a, dtype=float) for a in (Gu, Gx, h, ds))
    if Gu.ndim != 2 or Gu.shape[1] == 0 or not (Gx.shape == h.shape == Gu.shape) \
            or ds.shape != Gu.shape[:1]:
        raise ParameterError(f"stage rows of shapes {Gu.shape}, {Gx.shape}, {h.shape} and "
                             f"lengths {ds.shape} do not match")
    odd = ~(np.isfinite(Gu) & np.isfinite(Gx)) | np.isnan(h)
    if odd.any():
        k = int(np.flatnonzero(odd.any(axis=1))[0])
        raise ParameterError(f"a limit's row at stage {k} of the time-optimal law is not "
                             "finite (a constraint object's rows)")
    never = (h == -np.inf).any(axis=1)
    if never.any():  # (the backward pass meets the last of them first)
        raise unreachable(int(np.flatnonzero(never)[-1]))
    if USE_COMPILED:
        x = np.empty(len(ds) + 1)
        Gu, Gx, h, ds = (np.ascontiguousarray(a) for a in (Gu, Gx, h, ds))
        k = _compiled.reach(Gu, Gx, h, ds, x)
        if k >= 0:
            raise unreachable(k)
        return x
    st = _stages(Gu, Gx, h, ds)
    K_lo, K_hi = _controllable(st, unreachable)
    return _fastest(st, K_lo, K_hi, unreachable)


#: Coefficients ``m, q`` of bounds ``m y + q`` for the sequential passes, every stage's as
#: flat Python lists, stage ``k``'s at indices ``starts[k]`` to ``starts[k + 1]``.
_Flat = tuple[list[float], list[float], list[int]]


@dataclass(frozen=True)
class _Stages:
    """The stages' rows solved for ``u`` (Fourier-Motzkin elimination), for all stages at
    once, in the form the passes evaluate (floats in lists: faster there than NumPy scalars).

    With ``lo <= x' <= hi`` the next point's controllable set and ``x' = x + 2 ds u``, the
    lower rows (``u >= a x + b``) give bounds on ``x`` linear in ``hi`` and the upper rows
    (``u <= a x + b``) bounds linear in ``lo``; ``x <= m y + q`` and ``x >= m y + q``.
    """

    n: int
    x_lo: list[float]  # the static interval of x: every row of the stage on its own
    x_hi: list[float]
    x_lo0: list[float]  # ... with the upper rows' bounds at lo = 0 (rest reachable next)
    x_hi0: list[float]
    hi_caps: _Flat  # x <= m hi + q
    hi_floors: _Flat  # x >= m hi + q
    upper: _Flat  # u <= a x + b, for the forward pass
    lo_rows: tuple[Array, Array, Array, Array]  # m, q and the masks of x <= / >= m lo + q
    two_ds: list[float]
    half: list[float]  # 1 / (2 ds)

    @cached_property
    def lo_caps_floors(self) -> tuple[_Flat, _Flat]:
        """The bounds linear in ``lo`` (needed only where rest is not reachable next)."""
        m, q, caps, floors = self.lo_rows
        return _flat(m, q, caps), _flat(m, q, floors)


def _stages(Gu: Array, Gx: Array, h: Array, ds: Array) -> _Stages:
    """Rows ``Gu u + Gx x <= h`` (N, m) of the stages of lengths ``ds`` (N,) as
    :class:`_Stages`."""
    tiny = 1e-12 * (np.abs(Gu) + 2 * ds[:, None] * np.abs(Gx))
    up, down, xonly = Gu > tiny, Gu < -tiny, np.abs(Gu) <= tiny
    with np.errstate(divide="ignore", invalid="ignore"):
        alpha = np.where(xonly, 0.0, -Gx / Gu)
        beta = np.where(xonly, 0.0, h / Gu)
        # u <= alpha x + beta (uppers), u >= alpha x + beta (lowers), active rows first
        au, bu = _compact(alpha, beta, up, np.inf)
        al, bl = _compact(alpha, beta, down, -np.inf)
        x_lo, x_hi = _static_interval(au, bu, al, bl, xonly, Gx, h)
        inv2 = (1.0 / (2 * ds))[:, None]
        # lower row vs u <= (hi - x) / (2 ds): cl x <= hi / (2 ds) - bl
        cl = al + inv2
        m_l, q_l = inv2 / cl, -bl / cl
        # u >= (lo - x) / (2 ds) vs upper row: cu x <= bu - lo / (2 ds)
        cu = -inv2 - au
        m_u, q_u = -inv2 / cu, bu / cu
    real_l, real_u = np.isfinite(bl), np.isfinite(bu)  # the compacted rows that are real
    caps, floors = real_u & (cu > 0), real_u & (cu < 0)
    x_lo0 = np.maximum(x_lo, np.where(floors, q_u, -np.inf).max(axis=1, initial=-np.inf))
    x_hi0 = np.minimum(x_hi, np.where(caps, q_u, np.inf).min(axis=1, initial=np.inf))
    return _Stages(len(ds), x_lo.tolist(), x_hi.tolist(), x_lo0.tolist(), x_hi0.tolist(),
                   _flat(m_l, q_l, real_l & (cl > 0)), _flat(m_l, q_l, real_l & (cl < 0)),
                   _flat(au, bu, real_u), (m_u, q_u, caps, floors), (2 * ds).tolist(),
                   inv2[:, 0].tolist())


def _static_interval(au: Array, bu: Array, al: Array, bl: Array, xonly: Array, Gx: Array,
                     h: Array) -> tuple[Array, Array]:
    """The interval of ``x`` each stage allows on its own: every lower row below every upper
    row (pairs of the compacted rows, (N, wu, wl)), and the rows in ``x`` alone (``xonly``);
    empty (``lo = inf``) when some pair or row cannot hold."""
    c = al[:, None, :] - au[:, :, None]
    d = bu[:, :, None] - bl[:, None, :]
    r = d / c
    rx = h / Gx
    x_hi = np.minimum(np.where(c > 0, r, np.inf).min(axis=(1, 2), initial=np.inf),
                      np.where(xonly & (Gx > 0), rx, np.inf).min(axis=1))
    x_lo = np.maximum(np.where(c < 0, r, -np.inf).max(axis=(1, 2), initial=-np.inf),
                      np.where(xonly & (Gx < 0), rx, -np.inf).max(axis=1))
    empty = ((c == 0) & (d < 0)).any(axis=(1, 2)) | (xonly & (Gx == 0) & (h < 0)).any(axis=1)
    return np.where(empty, np.inf, np.maximum(x_lo, 0.0)), x_hi


def _controllable(st: _Stages, unreachable: Callable[[int], InfeasibleError]
                  ) -> tuple[list[float], list[float]]:
    """The backward pass: the controllable interval ``[K_lo, K_hi]`` of ``x`` at each grid
    point, from rest at the end."""
    n = st.n
    hcm, hcq, hcs = st.hi_caps
    hfm, hfq, hfs = st.hi_floors
    K_lo, K_hi = [0.0] * (n + 1), [0.0] * (n + 1)
    big = 1e300  # an unbounded hi stays finite, so that 0 * hi is 0
    for k in range(n - 1, -1, -1):
        lo, hi = K_lo[k + 1], K_hi[k + 1]
        if hi > big:  # (comparisons inline: builtin min and max calls cost more here)
            hi = big
        if lo == 0.0:
            xl, xh = st.x_lo0[k], st.x_hi0[k]
        else:  # x <= m lo + q, x >= m lo + q
            (lcm, lcq, lcs), (lfm, lfq, lfs) = st.lo_caps_floors
            xl, xh = st.x_lo[k], st.x_hi[k]
            for j in range(lcs[k], lcs[k + 1]):
                v = lcm[j] * lo + lcq[j]
                if v < xh:
                    xh = v
            for j in range(lfs[k], lfs[k + 1]):
                v = lfm[j] * lo + lfq[j]
                if v > xl:
                    xl = v
        for j in range(hcs[k], hcs[k + 1]):
            v = hcm[j] * hi + hcq[j]
            if v < xh:
                xh = v
        for j in range(hfs[k], hfs[k + 1]):
            v = hfm[j] * hi + hfq[j]
            if v > xl:
                xl = v
        if xl > xh + 1e-12 * (1.0 + abs(xh)):
            raise unreachable(k)
        v = xh if xh < xl else xl
        K_lo[k], K_hi[k] = (v if v > 0.0 else 0.0), (xh if xh > 0.0 else 0.0)
    if K_lo[0] > 1e-12 * (1.0 + K_hi[0]):
        raise unreachable(0)
    return K_lo, K_hi


def _fastest(st: _Stages, K_lo: list[float], K_hi: list[float],
             unreachable: Callable[[int], InfeasibleError]) -> Array:
    """The forward pass: from rest, the largest acceleration that every row allows and that
    keeps the next point controllable; the squared speeds (N + 1,)."""
    n = st.n
    aum, auq, aus = st.upper
    two_ds, half = st.two_ds, st.half
    x = [0.0] * (n + 1)
    for k in range(n):
        xk = x[k]
        u_hi = (K_hi[k + 1] - xk) * half[k]
        u_lo = (K_lo[k + 1] - xk) * half[k]
        for j in range(aus[k], aus[k + 1]):
            v = aum[j] * xk + auq[j]
            if v < u_hi:
                u_hi = v
        # (the lower rows hold at the largest acceleration: x[k] is controllable, so some
        # acceleration meets every row and reaches K[k + 1], and the largest one does)
        if u_lo > u_hi + 1e-9 * (1.0 + abs(u_hi)):
            raise unreachable(k)
        v = xk + two_ds[k] * u_hi
        if v < K_lo[k + 1]:
            v = K_lo[k + 1]
        x[k + 1] = K_hi[k + 1] if K_hi[k + 1] < v else v
    x[n] = 0.0
    return np.array(x)


def _compact(m: Array, q: Array, active: Array, fill: float) -> tuple[Array, Array]:
    """Per stage (row of the arrays), the active entries first, cut to the largest number of
    active entries; padding ``(0, fill)`` never binds."""
    counts = active.sum(axis=1)
    width = int(counts.max()) if active.size else 0
    rows = np.repeat(np.arange(len(active)), counts)
    place = np.cumsum(active, axis=1)[active] - 1  # each active entry's place in its row
    mm, qq = np.zeros((len(active), width)), np.full((len(active), width), fill)
    mm[rows, place], qq[rows, place] = m[active], q[active]
    return mm, qq


def _flat(m: Array, q: Array, active: Array) -> _Flat:
    """The active coefficients of all stages (rows of the arrays (N, w)) as flat lists."""
    starts = np.concatenate([[0], np.cumsum(active.sum(axis=1))]).tolist()
    return m[active].tolist(), q[active].tolist(), starts


def _unreachable(co: PathCoefficients, k: int, tmax: Array, units: Units | None
                 ) -> InfeasibleError:
    need = np.abs(co.g[k]) + co.coulomb
    with np.errstate(divide="ignore", invalid="ignore"):  # a limit tightened to 0: that motor
        i = int(np.argmax(need / tmax))
    motor = "A" if i == 0 else "D"
    return InfeasibleError(
        f"no motion within the limits passes {_describe(co, k, units)}: the motor at {motor} "
        f"needs up to {_torque(units, need[i])} for gravity and Coulomb friction alone there "
        f"and the rest of its limit {_torque(units, tmax[i])} cannot brake the robot to rest "
        "before the end of the path")


def _law(S: float, s: Array, x: Array, tmax: tuple[float, float],
         wmax: tuple[float, float], solves: int) -> TimeOptimalLaw:
    v = np.sqrt(np.maximum(x, 0.0))
    den = v[:-1] + v[1:]
    if np.any(den <= 0):
        k = int(np.flatnonzero(den <= 0)[0])
        raise InfeasibleError(f"no motion within the limits: the speed must stay zero at arc "
                              f"length s = {s[k]:.6g} (the limits leave no acceleration)")
    dts = 2 * (s[1:] - s[:-1]) / den
    knots_t = np.concatenate([[0.0], np.cumsum(dts)])
    accel = (v[1:] - v[:-1]) / dts  # constant acceleration on each segment
    return TimeOptimalLaw(distance=S, duration=float(knots_t[-1]), knots_t=knots_t, knots_s=s,
                          knots_v=v, accel=accel, torque_limit=tmax, speed_limit=wmax,
                          solves=solves)


def _build(r: Any) -> TimeOptimalLaw:
    """The registered builder: limits from ``[law]`` when given, else from ``[motors]``."""
    p = r.params
    motors = r.motors
    if p.get("torque_limit") is not None:
        motors = MotorLimits.of(p["torque_limit"], p.get("speed_limit_deg_s"))
    elif motors is None:
        raise ConfigError("config key [law].torque_limit is required for a time-optimal law "
                          "(or a [motors] table with peak_torque)")
    return solve_time_optimal_law(r.dynamics, motors=motors, grid=p["grid"], units=r.units)


def _register() -> None:
    register_law(LawType(
        "time-optimal",
        {"torque_limit": Param("pair", "N m", None, "motor torque limits [A, D] (default: "
                               "[motors])", positive=True),
         "speed_limit_deg_s": Param("pair", "deg/s", None, "motor speed limits [A, D] "
                                    "(with [motors]: the lower of the two holds)",
                                    positive=True),
         "grid": Param("integer", "", 400, "segments in arc length", minimum=10,
                       maximum=100_000)},
        _build,
        "the fastest rest-to-rest motion within the motors' torque and speed limits (TOPP-RA)",
        needs_dynamics=True))


_register()
