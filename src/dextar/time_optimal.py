"""Time-optimal law of motion along a path under motor torque and speed limits.

Along the path (arc length ``s``) the joint motion is ``qdot = q' sdot`` and
``qddot = q' sddot + q'' sdot^2``, so with ``x = sdot^2`` and ``u = sddot`` the exact inverse
dynamics become affine:

    tau(s) = a(s) u + b(s) x + c(s),
    a = M q',  b = M q'' + c(q, q'),  c = g(q) + coulomb * sign(q'),

(velocity-product torques are quadratic in the rates). Torque limits ``|tau_i| <= tau_max_i``
and speed limits ``|q'_i| sqrt(x) <= w_max_i`` are then linear in ``(x, u)`` at each point of a
grid in ``s``, and ``x_{k+1} = x_k + 2 ds u_k`` links neighbouring points. The solver follows
the reachability-analysis method (TOPP-RA, Pham & Pham 2018): a backward pass computes, at each
grid point, the interval of ``x`` from which rest at the end remains reachable (a
two-variable linear programme, solved exactly by enumerating vertices), then a forward pass
takes the largest admissible acceleration from rest at the start. Between grid points the
acceleration is constant, so the limits hold exactly at the grid points and up to the
discretisation error in between (reported). Viscous friction is not part of the limits.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from .dynamics import Model, gravity_torques, inverse_dynamics, mass_matrix
from .errors import ConvergenceError, ParameterError
from .laws import Law, UniformLaw
from .paths import Path
from .trajectory import sample_trajectory


@dataclass(frozen=True)
class TimeOptimalLaw(Law):
    """Piecewise-constant acceleration law found by :func:`solve_time_optimal_law`.

    Attributes
    ----------
    knots_t, knots_s, knots_v : ndarray, shape (N + 1,)
        Time, arc length and speed at the grid points; ``accel`` (N,) on each segment.
    torque_limit, speed_limit : tuple
        The limits used (speed limit ``inf`` when none).
    """

    distance: float
    duration: float
    knots_t: np.ndarray = field(repr=False)
    knots_s: np.ndarray = field(repr=False)
    knots_v: np.ndarray = field(repr=False)
    accel: np.ndarray = field(repr=False)
    torque_limit: tuple[float, float] = (np.inf, np.inf)
    speed_limit: tuple[float, float] = (np.inf, np.inf)
    max_torque_ratio: float = 0.0
    name: str = field(default="time-optimal", init=False)

    def _evaluate(self, t: np.ndarray) -> np.ndarray:
        k = np.clip(np.searchsorted(self.knots_t, t, side="right") - 1, 0, self.accel.size - 1)
        tau = t - self.knots_t[k]
        u = self.accel[k]
        v = self.knots_v[k]
        s = self.knots_s[k] + v * tau + 0.5 * u * tau * tau
        return np.stack([s, v + u * tau, u, np.zeros_like(t)])


def _x_range(G: np.ndarray, h: np.ndarray) -> tuple[float, float] | None:
    """Range of ``x`` over the polygon ``G @ (x, u) <= h`` (vertex enumeration), or None."""
    best_lo, best_hi = np.inf, -np.inf
    scale = np.maximum(np.abs(h), 1.0)
    for i, j in itertools.combinations(range(len(h)), 2):
        A = G[[i, j]]
        det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
        if abs(det) < 1e-14 * (np.abs(A).max() ** 2 + 1e-300):
            continue
        x = (h[i] * A[1, 1] - A[0, 1] * h[j]) / det
        u = (A[0, 0] * h[j] - h[i] * A[1, 0]) / det
        if np.all(G @ np.array([x, u]) <= h + 1e-9 * scale):
            best_lo, best_hi = min(best_lo, x), max(best_hi, x)
    if best_lo > best_hi:
        return None
    return best_lo, best_hi


def solve_time_optimal_law(model: Model, path: Path, *, torque_limit: tuple[float, float],
                           speed_limit: tuple[float, float] | None = None, mode: str = "+-",
                           grid: int = 400) -> TimeOptimalLaw:
    """The fastest rest-to-rest law along ``path`` within motor torque and speed limits.

    Parameters
    ----------
    model : Model
        Robot and inertia (gravity and Coulomb friction are included in the limits).
    torque_limit : (float, float)
        ``tau_max`` of the motors at A and D (run units).
    speed_limit : (float, float), optional
        ``|qdot|`` limits of the motors (rad per run time unit).
    grid : int
        Number of segments in arc length.

    Raises
    ------
    ParameterError
        If the limits cannot even hold the robot still somewhere on the path.
    """
    tmax = np.array([float(v) for v in torque_limit])
    if tmax.shape != (2,) or not np.all(tmax > 0):
        raise ParameterError(f"torque limits {torque_limit!r} must be two positive numbers")
    wmax = np.full(2, np.inf) if speed_limit is None else np.array(
        [float(v) for v in speed_limit])
    if wmax.shape != (2,) or not np.all(wmax > 0):
        raise ParameterError(f"speed limits {speed_limit!r} must be two positive numbers")
    if int(grid) < 10:
        raise ParameterError(f"grid = {grid} must be at least 10")
    S = path.length
    n = int(grid)
    # joint path and its derivatives in s: a unit-speed law makes t = s, qdot = q', qddot = q''
    jp = sample_trajectory(model.robot, path, UniformLaw(S, S), mode=mode, samples=n + 1)
    s, q, q1, q2 = jp.t, jp.q, jp.dq, jp.ddq
    quiet = Model(model.robot, model.inertia.with_(gravity=(0.0, 0.0), viscous=(0.0, 0.0),
                                                    coulomb=(0.0, 0.0)), jp.assembly)
    a = np.einsum("nij,nj->ni", mass_matrix(quiet, q), q1)
    b = inverse_dynamics(quiet, q, q1, q2)
    c = gravity_torques(Model(model.robot, model.inertia, jp.assembly), q) + np.array(
        model.inertia.coulomb) * np.sign(q1)
    with np.errstate(divide="ignore"):
        xmax = np.min(np.where(np.abs(q1) > 0, (wmax / np.abs(q1)) ** 2, np.inf), axis=1)
    ds = S / n

    def constraints(k: int) -> tuple[np.ndarray, np.ndarray]:
        # rows over (x, u): a u + b x + c <= tmax, -(a u + b x + c) <= tmax, 0 <= x <= xmax
        G = [[b[k, i], a[k, i]] for i in range(2)] + [[-b[k, i], -a[k, i]] for i in range(2)]
        h = [tmax[i] - c[k, i] for i in range(2)] + [tmax[i] + c[k, i] for i in range(2)]
        G += [[-1.0, 0.0]]
        h += [0.0]
        if np.isfinite(xmax[k]):
            G += [[1.0, 0.0]]
            h += [xmax[k]]
        return np.array(G), np.array(h)

    # backward pass: controllable intervals K_k
    K = np.zeros((n + 1, 2))
    for k in range(n - 1, -1, -1):
        G, h = constraints(k)
        lo, hi = K[k + 1]
        G = np.vstack([G, [[1.0, 2 * ds], [-1.0, -2 * ds]]])
        h = np.concatenate([h, [hi, -lo]])
        rng = _x_range(G, h)
        if rng is None:
            raise ParameterError(
                f"the torque limits {tuple(tmax)} cannot bring the robot to rest at the end of "
                f"the path from s = {s[k]:.6g} (P = ({jp.P[k, 0]:.6g}, {jp.P[k, 1]:.6g})); "
                "gravity or the required decelerations exceed them")
        K[k] = max(rng[0], 0.0), rng[1]
    if K[0, 0] > 1e-12:
        raise ParameterError("rest at the start of the path is not controllable within the "
                             f"limits {tuple(tmax)}")
    # forward pass: greedy largest acceleration that stays controllable
    x = np.zeros(n + 1)
    u = np.zeros(n)
    for k in range(n):
        lo_u, hi_u = (K[k + 1, 0] - x[k]) / (2 * ds), (K[k + 1, 1] - x[k]) / (2 * ds)
        for i in range(2):
            lim_a = (tmax[i] - b[k, i] * x[k] - c[k, i], -tmax[i] - b[k, i] * x[k] - c[k, i])
            if abs(a[k, i]) > 1e-14:
                v1, v2 = lim_a[0] / a[k, i], lim_a[1] / a[k, i]
                lo_u, hi_u = max(lo_u, min(v1, v2)), min(hi_u, max(v1, v2))
        if lo_u > hi_u + 1e-9 * (1 + abs(hi_u)):
            hi_u = lo_u  # numerically empty: stay controllable
        u[k] = hi_u
        x[k + 1] = max(x[k] + 2 * ds * u[k], 0.0)
    x[-1] = 0.0
    u[-1] = (x[-1] - x[-2]) / (2 * ds)
    v = np.sqrt(x)
    dts = 2 * ds / (v[:-1] + v[1:])
    if not np.all(np.isfinite(dts)):
        raise ConvergenceError("time-optimal law: the path cannot be traversed (zero speed "
                               "inside the path)")
    knots_t = np.concatenate([[0.0], np.cumsum(dts)])
    # constant acceleration on each segment, consistent with the knots
    accel = (v[1:] - v[:-1]) / dts
    law = TimeOptimalLaw(distance=S, duration=float(knots_t[-1]), knots_t=knots_t,
                         knots_s=s, knots_v=v, accel=accel,
                         torque_limit=(float(tmax[0]), float(tmax[1])),
                         speed_limit=(float(wmax[0]), float(wmax[1])))
    # the limits hold at the grid points; measure the discretisation excess in between
    # (each segment just after its start, at its middle and just before its end: the
    # acceleration jumps at the knots)
    frac = np.array([1e-9, 0.25, 0.5, 0.75, 1.0 - 1e-9])
    times = (knots_t[:-1, None] + dts[:, None] * frac[None, :]).reshape(-1)
    chk = sample_trajectory(model.robot, path, law, mode=mode, times=times)
    ratio = np.abs(inverse_dynamics(Model(model.robot, model.inertia.with_(
        viscous=(0.0, 0.0)), jp.assembly), chk.q, chk.dq, chk.ddq)) / tmax
    object.__setattr__(law, "max_torque_ratio", float(ratio.max()))
    return law
