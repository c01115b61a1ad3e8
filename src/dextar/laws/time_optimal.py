"""Time-optimal law of motion along a path under motor torque and speed limits.

The solver needs the robot's dynamics along the path only through the small
:class:`PathDynamics` interface (implemented for the exact closed-chain model by
:class:`dextar.dynamics.along_path.RobotAlongPath`), so this module, like every law, sits
below the trajectory and dynamics stages. ``dextar.dynamics.time_optimal_law(model, path,
...)`` is the one-call form.

Along the path (arc length ``s``) the joint motion is ``qdot = q' sdot`` and
``qddot = q' sddot + q'' sdot^2``, so with ``x = sdot^2`` and ``u = sddot`` the exact inverse
dynamics are affine in ``(x, u)`` up to friction:

    tau(s) = a(s) u + b(s) x + g(s) + f(s, sdot),
    a = M q',  b = M q'' + c(q, q'),  g = gravity,  f = friction (viscous + Coulomb).

Friction is bounded, not linearised: the regularised Coulomb torque (see
:mod:`dextar.dynamics.friction`) always lies between 0 and ``coulomb * sign(q')``, and the
viscous torque ``viscous q' sqrt(x)`` between 0 and its tangent upper bound at the previous
iterate's speed (the first tangent at the motors' speed limits), so the limits are enforced
for every friction value in that interval (both ends of the interval are rows of the linear
programme); a torque-speed envelope is bounded by the same tangents. Where a joint reverses
along the path the interval is ``[-coulomb, coulomb]``; at the two rest points friction is
zero. The iterates are solved until the tangent settles (:data:`TANGENT_RTOL`).

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
interior points of every segment) through the exact model with friction; if a torque exceeds
its limit by more than ``tol`` (default 1e-3) or a speed its limit, the limits are tightened
by the excess and the problem solved again (a few iterations at most). The law reports ``status`` (0: the
limits hold within ``tol`` on the check samples; 1: they do not after the iterations, with
the excess in ``message``) and ``max_torque_ratio``. When no motion within the limits exists
at all, :class:`~dextar.errors.InfeasibleError` names the point, the motor and the torque.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Protocol

import numpy as np

from .._arrays import Array
from ..errors import InfeasibleError, ParameterError
from ..units import Units
from .base import Law

#: Greatest number of solves (friction tangent updates and limit margins).
MAX_SOLVES = 8
#: The friction tangent has settled when no speed along the path moves by more than this
#: fraction of the largest between two solves. The iteration converges quadratically, so the
#: law's duration is then within about the square of this of the settled one: over 96 designs
#: of the pick-and-place sweep, 3e-2 moved the cycle times by at most 1.8e-5 relative against
#: 1e-3, far below the grid's own loss (about 1e-3 at 400 segments).
TANGENT_RTOL = 3e-2
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
        0 when the limits hold within the tolerance on the check samples, 1 otherwise.
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

    def _evaluate(self, t: Array) -> Array:
        k = np.clip(np.searchsorted(self.knots_t, t, side="right") - 1, 0, self.accel.size - 1)
        tau = t - self.knots_t[k]
        u = self.accel[k]
        v = self.knots_v[k]
        s = self.knots_s[k] + v * tau + 0.5 * u * tau * tau
        return np.stack([s, v + u * tau, u, np.zeros_like(t)])


@dataclass(frozen=True)
class PathCoefficients:
    """The path dynamics on a grid of arc lengths: ``tau = a u + b x + g + f``.

    Attributes
    ----------
    s : ndarray, shape (N + 1,)
        Arc lengths of the grid, increasing from 0 to the path's length.
    P : ndarray, shape (N + 1, 2)
        End-effector positions (for the words of an error).
    a, b, g : ndarray, shape (N + 1, 2)
        ``M q'``, ``M q'' + c(q, q')`` and the gravity torques.
    dq_ds : ndarray, shape (N + 1, 2)
        ``q'``, the joint rates per unit arc length.
    coulomb, viscous : ndarray, shape (2,)
        The motors' friction coefficients.
    """

    s: Array
    P: Array
    a: Array
    b: Array
    g: Array
    dq_ds: Array
    coulomb: Array
    viscous: Array

    @cached_property
    def friction_sides(self) -> tuple[Array, Array]:
        """Where each joint's friction may push up (forward motion, or a reversal near) and
        down: two arrays (N + 1, 2) of 1.0 and 0.0, both 0 at the two rest points (where
        friction is exactly zero)."""
        sg = np.sign(self.dq_ds)
        steady = (sg == np.roll(sg, 1, axis=0)) & (sg == np.roll(sg, -1, axis=0)) & (sg != 0)
        steady[[0, -1]] = (sg[[0, -1]] == sg[[1, -2]]) & (sg[[0, -1]] != 0)
        up = ((steady & (sg > 0)) | ~steady).astype(float)
        down = ((steady & (sg < 0)) | ~steady).astype(float)
        up[[0, -1]] = down[[0, -1]] = 0.0
        return up, down


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
    """

    peak_torque: tuple[float, float]
    max_speed: tuple[float, float] = (math.inf, math.inf)
    knee_speed: tuple[float, float] | None = None

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

    def available_torque(self, dq: Array) -> Array:
        """The torque each motor can give at joint rates ``dq`` (..., 2), same shape."""
        peak = np.asarray(self.peak_torque, float)
        if self.knee_speed is None:
            return np.broadcast_to(peak, np.shape(dq)).copy()
        w, k = np.asarray(self.max_speed, float), np.asarray(self.knee_speed, float)
        frac = np.clip((w - np.abs(dq)) / (w - k), 0.0, 1.0)
        return np.asarray(peak * frac)

    def ratios(self, tau: Array, dq: Array) -> tuple[float, float]:
        """Largest ``|tau| / available torque`` and ``|qdot| / max speed`` over samples (n, 2)."""
        avail = self.available_torque(dq)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(avail > 0, np.abs(tau) / avail, np.where(np.abs(tau) > 0, np.inf, 0.0))
        return float(r.max()), float((np.abs(dq) / np.asarray(self.max_speed, float)).max())


class PathDynamics(Protocol):
    """The robot along a path, as the time-optimal law needs it."""

    @property
    def length(self) -> float:
        """The path's length."""
        ...

    def coefficients(self, s: Array) -> PathCoefficients:
        """The coefficients at the arc lengths ``s`` (N + 1,), from 0 to the length."""
        ...

    def ratios(self, law: Law, times: Array, motors: MotorLimits) -> tuple[float, float]:
        """Largest torque and speed ratios of ``law`` at ``times`` against ``motors`` (exact
        model with gravity and friction)."""
        ...


def solve_time_optimal_law(dynamics: PathDynamics, *,
                           torque_limit: tuple[float, float] | None = None,
                           speed_limit: tuple[float, float] | None = None,
                           motors: MotorLimits | None = None, grid: int | Array = 400,
                           tol: float = 1e-3, units: Units | None = None) -> TimeOptimalLaw:
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
    grid : int or ndarray, shape (N + 1,)
        Number of equal segments in arc length, or the grid's arc lengths (increasing from 0
        to the path's length; finer where the dynamics change fast, e.g. in a blend).
    tol : float
        Allowed relative excess of a torque or speed over its limit on the check samples.
    units : Units, optional
        Only for the words of an error (points in mm, torques in N m).

    Returns
    -------
    TimeOptimalLaw
        With ``status`` and ``message``.

    Raises
    ------
    InfeasibleError
        No motion within the limits exists: names the point (mm), the arc length, the motor
        and the torque needed against the limit.
    """
    if motors is None:
        if torque_limit is None:
            raise ParameterError("a time-optimal law needs torque limits (or motors)")
        t2 = np.broadcast_to(np.asarray(torque_limit, float), (2,))
        w2 = np.broadcast_to(np.asarray(math.inf if speed_limit is None else speed_limit,
                                        float), (2,))
        motors = MotorLimits((float(t2[0]), float(t2[1])), (float(w2[0]), float(w2[1])))
    tmax = np.asarray(motors.peak_torque, float)
    wmax = np.asarray(motors.max_speed, float)
    knee = None if motors.knee_speed is None else np.asarray(motors.knee_speed, float)
    if not (0 < tol < 1):
        raise ParameterError(f"tolerance {tol!r} must be in (0, 1)")
    length = float(dynamics.length)
    s_grid = _grid(grid, length)
    n = len(s_grid) - 1
    co = dynamics.coefficients(s_grid)
    _check_holding(co, tmax, units)
    ds = np.diff(co.s)
    scale_t, scale_w = 1.0, 1.0
    law: TimeOptimalLaw | None = None
    has_viscous = bool(np.any(co.viscous > 0)) or knee is not None  # needs a tangent point
    # the tangent points of the viscous and envelope bounds, first at the speed limits
    x0 = _speed_limits(co, wmax) if has_viscous else None
    for solve in range(1, MAX_SOLVES + 1):
        x = _reachability(co, ds, tmax * scale_t, wmax * scale_w, x0, units,
                          None if knee is None else knee * scale_w)
        tangent_moved = has_viscous and (x0 is None or np.abs(np.sqrt(x) - np.sqrt(x0)).max()
                                         > TANGENT_RTOL * np.sqrt(x).max())
        bounded = x0 is not None or not has_viscous  # friction bound in place
        if has_viscous:
            x0 = x
        if tangent_moved and solve < MAX_SOLVES:
            continue  # the check waits for the friction tangent to settle
        law = _law(length, co.s, x, tmax, wmax, solve)
        dts = np.diff(law.knots_t)
        times = (law.knots_t[:-1, None] + dts[:, None] * CHECK_FRACTIONS[None, :]).reshape(-1)
        tr_ratio, sp_ratio = dynamics.ratios(law, times, motors)
        law = _with(law, tr_ratio, sp_ratio, 0, "")
        if tr_ratio <= 1 + tol and sp_ratio <= 1 + tol:
            break
        if bounded:  # discretisation excess: tighten by it
            scale_t *= min(1.0, (1 + 0.25 * tol) / max(tr_ratio, 1e-300))
            scale_w *= min(1.0, (1 + 0.25 * tol) / max(sp_ratio, 1e-300))
    assert law is not None
    ok = law.max_torque_ratio <= 1 + tol and law.max_speed_ratio <= 1 + tol
    where = (f"{n} segments of {ds[0]:.4g}" if np.ptp(ds) <= 1e-9 * length else
             f"{n} segments of {ds.min():.4g} to {ds.max():.4g}")
    margin = "" if scale_t == 1.0 and scale_w == 1.0 else (
        f"; limits tightened by {1 - scale_t:.2%} (torque) and {1 - scale_w:.2%} (speed) so "
        "that they hold between the grid points")
    if ok:
        msg = (f"time-optimal within the limits: torque ratio {law.max_torque_ratio:.5f}, speed "
               f"ratio {law.max_speed_ratio:.5f} on the check samples ({where}, "
               f"{law.solves} solve(s)){margin}")
        return _with(law, law.max_torque_ratio, law.max_speed_ratio, 0, msg)
    msg = (f"limits exceeded on the check samples after {law.solves} solves: torque ratio "
           f"{law.max_torque_ratio:.5f}, speed ratio {law.max_speed_ratio:.5f} (tolerance "
           f"{1 + tol:g}); refine the grid")
    return _with(law, law.max_torque_ratio, law.max_speed_ratio, 1, msg)


def _speed_limits(co: PathCoefficients, wmax: Array) -> Array | None:
    """The squared path speeds (N + 1,) at which a motor reaches its speed limit: the first
    tangent points of the speed-dependent bounds. Every tangent bounds ``sqrt(x)`` from
    above, so the first law is within the limits; from these speeds, above the optimum's, the
    iteration settles in about one solve fewer than from a first solve without those bounds
    (2.8 instead of 3.7 per move over the pick-and-place sweep, cycle times as close to the
    settled ones). None without a finite speed limit (the first solve then goes without)."""
    x = _speed_cap(co, wmax)
    finite = np.isfinite(x)
    if not finite.any():
        return None
    return np.asarray(np.where(finite, x, x[finite].max()))


def _speed_cap(co: PathCoefficients, wmax: Array) -> Array:
    """The largest squared path speed (N + 1,) within both motors' speed limits (``inf``
    where neither joint moves)."""
    with np.errstate(divide="ignore"):
        return np.asarray(np.min(np.where(co.dq_ds != 0, (wmax / np.abs(co.dq_ds)) ** 2,
                                          np.inf), axis=1))


def _grid(grid: int | Array, length: float) -> Array:
    """The grid's arc lengths (N + 1,) from a number of equal segments or given points."""
    if np.ndim(grid) == 0:
        if int(grid) != grid or int(grid) < 10:
            raise ParameterError(f"grid = {grid} must be a whole number of at least 10 segments")
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
    """Gravity alone must be within the limits everywhere on the path."""
    ratio = np.abs(co.g) / tmax
    if ratio.max() > 1.0:
        k, i = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        motor = "A" if i == 0 else "D"
        raise InfeasibleError(
            f"no motion within the limits: the motor at {motor} needs "
            f"{_torque(units, abs(co.g[k, i]))} to hold the robot still against gravity at "
            f"{_describe(co, int(k), units)}, above its limit {_torque(units, tmax[i])}")


def _friction_bounds(co: PathCoefficients, x0: Array | None
                     ) -> tuple[Array, Array, Array, Array]:
    """Friction ``f`` in ``[phi_lo + psi_lo x, phi_hi + psi_hi x]`` at each grid point,
    arrays (N + 1, 2)."""
    up, down = co.friction_sides
    if x0 is None:
        far_phi, far_psi = np.broadcast_to(co.coulomb, up.shape), np.zeros(up.shape)
    else:  # viscous |f| <= w sqrt(x) <= w (x + x0) / (2 sqrt(x0)), tangent at x0
        r = np.sqrt(np.maximum(x0, 1e-9 * max(float(x0.max()), 1e-300)))[:, None]
        w = co.viscous * np.abs(co.dq_ds)
        far_phi, far_psi = co.coulomb + 0.5 * w * r, 0.5 * w / r
    return -down * far_phi, -down * far_psi, up * far_phi, up * far_psi


def _rows(co: PathCoefficients, ds: Array, tmax: Array, wmax: Array,
          x0: Array | None, knee: Array | None = None) -> tuple[Array, Array, Array]:
    """Static rows ``Gu u + Gx x <= h`` of every stage, arrays (N, m).

    With a torque-speed envelope (``knee``) and a tangent point ``x0``, each motor also has
    ``|tau| + sigma |q'| sqrt(x) <= T + sigma knee`` (``sigma = T / (wmax - knee)``), with
    ``sqrt(x)`` bounded above by its tangent at ``max(x0, x_knee)``: conservative, and exact at
    the tangent point."""
    phi_lo, psi_lo, phi_hi, psi_hi = _friction_bounds(co, x0)
    xmax = _speed_cap(co, wmax)
    # rows at each point over (u, X), X the squared speed at that point: the torque rows,
    # then the speed-only ones (X <= xmax, X >= 0)
    pu = [co.a, -co.a]
    px = [co.b + psi_hi, -(co.b + psi_lo)]
    ph = [tmax - co.g - phi_hi, tmax + co.g + phi_lo]
    if knee is not None and x0 is not None:
        sigma = tmax / (wmax - knee)
        qabs = np.abs(co.dq_ds)
        with np.errstate(divide="ignore"):
            xk = np.where(qabs > 0, (knee / qabs) ** 2, np.inf)
        r = np.sqrt(np.minimum(np.maximum(x0[:, None], xk), 1e300))
        slope = np.where(qabs > 0, sigma * qabs / (2 * r), 0.0)
        offset = np.where(qabs > 0, sigma * qabs * r / 2, 0.0)
        cap = tmax + sigma * knee - offset
        pu += [co.a, -co.a]
        px += [co.b + psi_hi + slope, -(co.b + psi_lo) + slope]
        ph += [cap - co.g - phi_hi, cap + co.g + phi_lo]
    pu_, px_, ph_ = (np.concatenate(v, axis=1) for v in (pu, px, ph))
    return _stage_rows(pu_, px_, ph_, xmax, ds)


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


def _reachability(co: PathCoefficients, ds: Array, tmax: Array, wmax: Array,
                  x0: Array | None, units: Units | None, knee: Array | None = None) -> Array:
    """Squared speeds ``x`` at the grid points of the fastest admissible motion."""
    Gu, Gx, h = _rows(co, ds, tmax, wmax, x0, knee)
    n = Gu.shape[0]
    tiny = 1e-12 * (np.abs(Gu) + 2 * ds[:, None] * np.abs(Gx))
    up, lo_, xonly = Gu > tiny, Gu < -tiny, np.abs(Gu) <= tiny
    with np.errstate(divide="ignore", invalid="ignore"):
        alpha = np.where(xonly, 0.0, -Gx / Gu)
        beta = np.where(xonly, 0.0, h / Gu)
        # u <= alpha x + beta (uppers), u >= alpha x + beta (lowers), active rows first
        au, bu = _compact(alpha, beta, up, np.inf)
        al, bl = _compact(alpha, beta, lo_, -np.inf)
        # static x-interval: every lower below every upper, and the x-only rows
        c = al[:, None, :] - au[:, :, None]
        d = bu[:, :, None] - bl[:, None, :]
        hi_pairs = np.where(c > 0, d / c, np.inf)
        lo_pairs = np.where(c < 0, d / c, -np.inf)
        x_hi = np.minimum(hi_pairs.min(axis=(1, 2), initial=np.inf),
                          np.where(xonly & (Gx > 0), h / Gx, np.inf).min(axis=1))
        x_lo = np.maximum(lo_pairs.max(axis=(1, 2), initial=-np.inf),
                          np.where(xonly & (Gx < 0), h / Gx, -np.inf).max(axis=1))
        empty = ((c == 0) & (d < 0)).any(axis=(1, 2)) | (xonly & (Gx == 0) & (h < 0)).any(axis=1)
    x_lo = np.where(empty, np.inf, np.maximum(x_lo, 0.0))
    inv2 = (1.0 / (2 * ds))[:, None]
    # The controllability rows lo <= x + 2 ds u <= hi combine with the static rows into bounds
    # on x linear in hi (lower rows) or lo (upper rows): x <= m hi + q or x >= m hi + q. The
    # coefficients are precomputed for all stages at once; the pass only evaluates them.
    act_l, act_u = np.isfinite(bl), np.isfinite(bu)  # the compacted rows that are real
    with np.errstate(divide="ignore", invalid="ignore"):
        cl = al + inv2  # lower row vs u <= (hi - x) / (2 ds): cl x <= hi / (2 ds) - bl
        m_l, q_l = inv2 / cl, -bl / cl
        cu = -inv2 - au  # u >= (lo - x) / (2 ds) vs upper row: cu x <= bu - lo / (2 ds)
        m_u, q_u = -inv2 / cu, bu / cu
    lhm, lhq, lhs = _flat(m_l, q_l, act_l & (cl > 0))  # x <= m hi + q
    llm, llq, lls = _flat(m_l, q_l, act_l & (cl < 0))  # x >= m hi + q
    uh, ul = act_u & (cu > 0), act_u & (cu < 0)
    upper: list[tuple[list[float], list[float], list[int]]] = []  # made when lo > 0 first
    aum, auq, aus = _flat(au, bu, act_u)  # u <= a x + b
    XL, XH = x_lo.tolist(), x_hi.tolist()
    # with lo = 0 (rest is reachable, the usual case) the upper rows' bounds are constants
    XL0 = np.maximum(x_lo, np.where(ul, q_u, -np.inf).max(axis=1, initial=-np.inf)).tolist()
    XH0 = np.minimum(x_hi, np.where(uh, q_u, np.inf).min(axis=1, initial=np.inf)).tolist()
    K_lo, K_hi = [0.0] * (n + 1), [0.0] * (n + 1)
    big = 1e300  # an unbounded hi stays finite, so that 0 * hi is 0
    for k in range(n - 1, -1, -1):
        lo, hi = K_lo[k + 1], K_hi[k + 1]
        if hi > big:  # (comparisons inline: builtin min and max calls cost more here)
            hi = big
        if lo == 0.0:
            xl, xh = XL0[k], XH0[k]
        else:
            if not upper:  # x <= m lo + q, x >= m lo + q
                upper += [_flat(m_u, q_u, uh), _flat(m_u, q_u, ul)]
            (uhm, uhq, uhs), (ulm, ulq, uls) = upper
            xl, xh = XL[k], XH[k]
            for j in range(uhs[k], uhs[k + 1]):
                v = uhm[j] * lo + uhq[j]
                if v < xh:
                    xh = v
            for j in range(uls[k], uls[k + 1]):
                v = ulm[j] * lo + ulq[j]
                if v > xl:
                    xl = v
        for j in range(lhs[k], lhs[k + 1]):
            v = lhm[j] * hi + lhq[j]
            if v < xh:
                xh = v
        for j in range(lls[k], lls[k + 1]):
            v = llm[j] * hi + llq[j]
            if v > xl:
                xl = v
        if xl > xh + 1e-12 * (1.0 + abs(xh)):
            raise _unreachable(co, k, tmax, units)
        v = xh if xh < xl else xl
        K_lo[k], K_hi[k] = (v if v > 0.0 else 0.0), (xh if xh > 0.0 else 0.0)
    if K_lo[0] > 1e-12 * (1.0 + K_hi[0]):
        raise _unreachable(co, 0, tmax, units)
    x = [0.0] * (n + 1)
    two_ds, half = (2 * ds).tolist(), inv2[:, 0].tolist()
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
            raise _unreachable(co, k, tmax, units)
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


def _flat(m: Array, q: Array, active: Array) -> tuple[list[float], list[float], list[int]]:
    """The active coefficients of all stages (rows of the arrays (N, w)) as flat Python lists,
    stage ``k``'s at indices ``starts[k]`` to ``starts[k + 1]``, for the sequential passes
    (floats are faster there than NumPy scalars)."""
    starts = np.concatenate([[0], np.cumsum(active.sum(axis=1))]).tolist()
    return m[active].tolist(), q[active].tolist(), starts


def _unreachable(co: PathCoefficients, k: int, tmax: Array, units: Units | None
                 ) -> InfeasibleError:
    need = np.abs(co.g[k]) + co.coulomb
    i = int(np.argmax(need / tmax))
    motor = "A" if i == 0 else "D"
    return InfeasibleError(
        f"no motion within the limits passes {_describe(co, k, units)}: the motor at {motor} "
        f"needs up to {_torque(units, need[i])} for gravity and Coulomb friction alone there "
        f"and the rest of its limit {_torque(units, tmax[i])} cannot brake the robot to rest "
        "before the end of the path")


def _law(S: float, s: Array, x: Array, tmax: Array, wmax: Array,
         solves: int) -> TimeOptimalLaw:
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
                          knots_v=v, accel=accel, torque_limit=(float(tmax[0]), float(tmax[1])),
                          speed_limit=(float(wmax[0]), float(wmax[1])), solves=solves)






def _build(r: Any) -> TimeOptimalLaw:
    """The registered builder: limits from ``[law]`` when given, else from ``[motors]``."""
    from ..errors import ConfigError

    p = r.params
    motors = r.motors
    if p.get("torque_limit") is not None:
        motors = MotorLimits(tuple(p["torque_limit"]),
                             tuple(p.get("speed_limit_deg_s") or (math.inf, math.inf)))
    elif motors is None:
        raise ConfigError("config key [law].torque_limit is required for a time-optimal law "
                          "(or a [motors] table with peak_torque)")
    return solve_time_optimal_law(r.dynamics, motors=motors, grid=p["grid"], units=r.units)


def _register() -> None:
    from ..params import Param
    from .registry import LawType, register_law

    register_law(LawType(
        "time-optimal",
        {"torque_limit": Param("pair", "N m", None, "motor torque limits [A, D] (default: "
                               "[motors])", positive=True),
         "speed_limit_deg_s": Param("pair", "deg/s", None, "motor speed limits [A, D]",
                                    positive=True),
         "grid": Param("integer", "", 400, "segments in arc length", minimum=10,
                       maximum=100_000)},
        _build,
        "the fastest rest-to-rest motion within the motors' torque and speed limits (TOPP-RA)",
        needs_dynamics=True))


_register()
