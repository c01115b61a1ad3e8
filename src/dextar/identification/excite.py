"""Exciting trajectories: periodic joint motions that make the base regressor well conditioned.

Each motor follows a finite Fourier series (Swevers et al., 1997) of ``N`` harmonics of the
base frequency ``f``, ``w = 2 pi f``:

    q_k(t) = q0_k + sum_l [a_kl sin(l w t) - b_kl (cos(l w t) - 1)] / (l w),
    qdot_k = sum_l a_kl cos(l w t) + b_kl sin(l w t),

periodic with period ``1 / f``. With ``sum_l a_kl = 0`` and ``sum_l l b_kl = 0`` (imposed by
the last harmonic's coefficients) it starts and ends each period at rest in ``q0``. The
coefficients minimise the condition number of the stacked base regressor (columns scaled to
unit norm) on a time grid of one period (SLSQP from a few random starts), subject to staying
:data:`MARGIN` away from both singularity types (so in the working and assembly modes of the
start) and, given motors, within their peak torque and maximum speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from .._arrays import Array
from ..dynamics.exact import Model, inverse_dynamics
from ..dynamics.regressor import regressor
from ..errors import ParameterError
from ..kinematics import direct_kinematics, elbows, inverse_kinematics
from ..kinematics.checker import pose_distances
from ..laws import MotorLimits
from .base import BaseParameters, base_parameters

#: Smallest normalised distance to either singularity type along an exciting trajectory.
MARGIN = 0.15
#: Time samples per period of the highest harmonic in the optimisation grid.
GRID_PER_HARMONIC = 12


@dataclass(frozen=True)
class FourierTrajectory:
    """A periodic joint trajectory (see the module doc).

    Attributes
    ----------
    q0 : ndarray, shape (2,)
        Rest pose (rad).
    a, b : ndarray, shape (2, N)
        Fourier coefficients of the joint rates (rad/s); they satisfy the rest conditions.
    base_hz : float
    """

    q0: Array
    a: Array
    b: Array
    base_hz: float

    @staticmethod
    def from_free(q0: Array, x: Array, harmonics: int, base_hz: float) -> FourierTrajectory:
        """The trajectory of the free coefficients ``x`` (4 (N - 1),): ``a`` and ``b`` of
        harmonics 1 to N-1 per motor; the N-th from the rest conditions."""
        n = harmonics
        x = np.asarray(x, float).reshape(2, 2, n - 1)
        ls = np.arange(1, n + 1)
        a = np.concatenate([x[0], -x[0].sum(axis=1, keepdims=True)], axis=1)
        bl = -(x[1] * ls[:-1]).sum(axis=1, keepdims=True) / n
        b = np.concatenate([x[1], bl], axis=1)
        return FourierTrajectory(np.asarray(q0, float), a, b, float(base_hz))

    @property
    def period(self) -> float:
        """Period (s)."""
        return 1.0 / self.base_hz

    def evaluate(self, t: Array) -> tuple[Array, Array, Array]:
        """``q, qdot, qddot`` (each (n, 2)) at times ``t`` (n,)."""
        t = np.asarray(t, float)
        w = 2 * math.pi * self.base_hz
        lw = w * np.arange(1, self.a.shape[1] + 1)
        arg = t[:, None] * lw[None, :]
        s, c = np.sin(arg), np.cos(arg)
        q = self.q0 + (s / lw) @ self.a.T - ((c - 1.0) / lw) @ self.b.T
        dq = c @ self.a.T + s @ self.b.T
        ddq = (-s * lw) @ self.a.T + (c * lw) @ self.b.T
        return q, dq, ddq


@dataclass(frozen=True)
class ExcitationResult:
    """An optimised exciting trajectory.

    Attributes
    ----------
    trajectory : FourierTrajectory
    condition_number : float
        Of the base regressor over one period (unit-norm columns).
    periods : int
        Whole periods in the requested duration.
    min_type1_distance, min_type2_distance : float
    peak_torque : ndarray, shape (2,)
        Predicted by the model.
    peak_speed : ndarray, shape (2,)
    status : int
        0 success; 1 the optimiser stopped without converging (the best point found is kept).
    message : str
    """

    trajectory: FourierTrajectory
    condition_number: float
    periods: int
    min_type1_distance: float
    min_type2_distance: float
    peak_torque: Array
    peak_speed: Array
    status: int
    message: str

    @property
    def duration(self) -> float:
        """Duration (s): whole periods."""
        return self.periods * self.trajectory.period


def rest_pose(model: Model, mode: str, resolution: int = 61) -> Array:
    """The pose (2,) of the working mode ``mode`` farthest from both singularity types (on a
    grid of the reachable region)."""
    r = model.robot
    R = max(r.l1 + r.L1, r.l2 + r.L2) + 0.5 * r.d
    xs = np.linspace(-R, R, resolution)
    X, Yg = np.meshgrid(xs, xs)
    P = np.stack([X.ravel(), Yg.ravel()], -1)
    rin1, rout1 = r.reach(1)
    rin2, rout2 = r.reach(2)
    dA = np.hypot(*(P - r.A).T)
    dD = np.hypot(*(P - r.D).T)
    P = P[(dA > rin1) & (dA < rout1) & (dD > rin2) & (dD < rout2)]
    q = inverse_kinematics(r, P, mode)
    d = pose_distances(r, q, P)
    # the pose must assemble in the model's assembly mode
    Pa = direct_kinematics(r, q, model.assembly)
    same = np.hypot(*(Pa - P).T) < 1e-9 * R
    score = np.where(same, np.minimum(d.type1, d.type2), -1.0)
    i = int(np.argmax(score))
    if score[i] <= MARGIN:
        raise ParameterError(f"no pose of working mode {mode} is {MARGIN:g} away from both "
                             "singularity types in this assembly mode: nothing to excite")
    return np.asarray(q[i])


def _feasibility(model: Model, q: Array) -> tuple[Array, Array, Array] | None:
    """Distances (type 1, type 2) of the poses q (n, 2) and the assembly slack; None where
    the rods cannot meet."""
    r = model.robot
    B, C = elbows(r, q)
    d2 = ((B - C) ** 2).sum(axis=1)
    slack = np.minimum((r.L1 + r.L2) ** 2 - d2, d2 - (r.L1 - r.L2) ** 2)
    if (slack <= 0).any():
        return None
    P = direct_kinematics(r, q, model.assembly)
    d = pose_distances(r, q, P)
    return d.type1, d.type2, d.type2_signed


def _within(model: Model, motors: MotorLimits, q: Array, dq: Array, ddq: Array) -> bool:
    """True when the motion needs no more than the motors give (torque and speed)."""
    tau = inverse_dynamics(model, q, dq, ddq)
    return bool((np.abs(tau) <= motors.available_torque(dq)).all()
                and (np.abs(dq) <= np.asarray(motors.max_speed)).all())


def design_excitation(model: Model, mode: str, *, harmonics: int = 5, base_hz: float = 0.2,
                      duration: float = 20.0, motors: MotorLimits | None = None,
                      seed: int = 0, starts: int = 3, q0: Array | None = None,
                      base: BaseParameters | None = None) -> ExcitationResult:
    """Optimise an exciting trajectory for ``model`` in working mode ``mode``.

    Parameters
    ----------
    model : Model
        The prior model (SI), for the regressor and the predicted torques.
    mode : str
        Working mode to stay in.
    harmonics : int
        Harmonics per motor (at least 2).
    base_hz : float
        Base frequency (Hz); the period is ``1 / base_hz``.
    duration : float
        Requested duration (s), rounded up to whole periods.
    motors : MotorLimits, optional
        Peak torque and maximum speed to stay within (SI).
    seed : int
        Seed of the random starts.
    starts : int
        Random starts of the optimiser.
    q0 : ndarray, shape (2,), optional
        Rest pose (default: :func:`rest_pose`).
    base : BaseParameters, optional

    Returns
    -------
    ExcitationResult
    """
    if not (isinstance(harmonics, int) and 2 <= harmonics <= 20):
        raise ParameterError(f"--harmonics {harmonics!r} must be an integer from 2 to 20")
    if not (math.isfinite(base_hz) and 0 < base_hz <= 10):
        raise ParameterError(f"--base-hz {base_hz!r} must be in (0, 10] Hz")
    if not (math.isfinite(duration) and 0 < duration <= 3600):
        raise ParameterError(f"--duration {duration!r} must be in (0, 3600] s")
    base = base or base_parameters(model)
    q0 = rest_pose(model, mode) if q0 is None else np.asarray(q0, float)
    n = harmonics
    m = GRID_PER_HARMONIC * n
    t = np.arange(m) / (m * base_hz)
    peak = None if motors is None else np.asarray(motors.peak_torque, float)
    vmax = None if motors is None else np.asarray(motors.max_speed, float)
    cache: dict[bytes, tuple[float, Array]] = {}

    nlim = 0 if motors is None else 4

    def evaluate(x: Array) -> tuple[float, Array]:
        """Log condition number and the constraint values (>= 0 when feasible) of ``x``."""
        key = x.tobytes()
        if key not in cache:
            cache[key] = _score(FourierTrajectory.from_free(q0, x, n, base_hz))
        return cache[key]

    def _score(tr: FourierTrajectory) -> tuple[float, Array]:
        q, dq, ddq = tr.evaluate(t)
        f = _feasibility(model, q)
        if f is None:  # the rods cannot meet somewhere
            return 1e3, -np.ones(2 * m + nlim)
        cons = [f[0] - MARGIN, f[1] - MARGIN]
        if f[1].min() < 0.1 * MARGIN:  # too near a parallel singularity for the dynamics
            return 1e3, np.concatenate(cons + [-np.ones(nlim)])
        Yb = base.columns(regressor(model, q, dq, ddq)).reshape(-1, base.size)
        norms = np.linalg.norm(Yb, axis=0)
        cost = 1e3
        if (norms > 0).all():
            sv = np.linalg.svd(Yb / norms, compute_uv=False)
            cost = float(np.log(sv[0] / max(sv[-1], 1e-300)))
        if motors is not None and peak is not None and vmax is not None:
            tau = inverse_dynamics(model, q, dq, ddq)
            cons.append((motors.available_torque(dq) - np.abs(tau)).min(axis=0) / peak)
            cons.append(np.where(np.isfinite(vmax), 1.0 - np.abs(dq).max(axis=0) / vmax, 1.0))
        return cost, np.concatenate(cons)

    rng = np.random.default_rng(seed)
    best: tuple[float, Array, bool] | None = None
    for _ in range(max(starts, 1)):
        x = rng.normal(size=4 * (n - 1))
        # shrink the start until it is feasible
        for _k in range(60):
            if (evaluate(x)[1] > 0).all():
                break
            x = 0.7 * x
        else:
            continue
        r = optimize.minimize(lambda x: evaluate(x)[0], x, method="SLSQP",
                              constraints=[{"type": "ineq", "fun": lambda x: evaluate(x)[1]}],
                              options={"maxiter": 100, "ftol": 1e-3})
        xs = r.x if (evaluate(r.x)[1] >= 0).all() else x
        cost = evaluate(xs)[0]
        if best is None or cost < best[0]:
            best = (cost, xs, bool(r.success))
    if best is None:
        raise ParameterError("no feasible exciting trajectory: the rest pose is too close to a "
                             "singularity or the motors are too weak to hold it")
    # the optimiser saw a coarse grid: check a fine one, shrinking the motion about the rest
    # pose until every sample is within the margins and the motors
    tt = np.linspace(0.0, 1.0 / base_hz, 40 * m, endpoint=False)
    x = best[1]
    for _ in range(200):
        tr = FourierTrajectory.from_free(q0, x, n, base_hz)
        q, dq, ddq = tr.evaluate(tt)
        f = _feasibility(model, q)
        if f is not None and min(f[0].min(), f[1].min()) >= MARGIN and (
                motors is None or _within(model, motors, q, dq, ddq)):
            break
        x = 0.98 * x
    else:  # pragma: no cover - the rest pose itself is feasible
        raise ParameterError("no exciting trajectory stays within the margins and motors")
    Yb = base.columns(regressor(model, q, dq, ddq)).reshape(-1, base.size)
    s = np.linalg.svd(Yb / np.linalg.norm(Yb, axis=0), compute_uv=False)
    tau = inverse_dynamics(model, q, dq, ddq)
    periods = max(1, int(math.ceil(duration * base_hz - 1e-9)))
    ok = best[2]
    assert f is not None
    return ExcitationResult(tr, float(s[0] / s[-1]), periods, float(f[0].min()),
                            float(f[1].min()), np.abs(tau).max(axis=0),
                            np.abs(dq).max(axis=0), 0 if ok else 1,
                            "optimised" if ok else "the optimiser stopped before converging; "
                            "the best feasible trajectory found is kept")
