"""Forward dynamics: integrate ``M(q) qddot = tau(t, q, qdot) - h(q, qdot)`` in the motor
angles (:func:`forward_dynamics`), or ``M_P Pddot + h_P = E tau`` in the end-effector's
coordinates through parallel singularities (:func:`forward_task_dynamics`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..errors import ConvergenceError, ParameterError, SingularityError
from ..geometry import parse_working_mode
from ..kinematics import inverse_kinematics, joint_rates
from .closed_chain import task_dynamics, task_state
from .exact import Model, accelerations, state_dynamics

integrate = lazy_module("scipy.integrate")
interpolate = lazy_module("scipy.interpolate")

TorqueFunction = Callable[[float, Array, Array], Array]


@dataclass(frozen=True)
class SimResult:
    """The result of a simulation stage (forward dynamics, a control loop): the motion, the
    torques applied and the integrator's outcome, as ``scipy.optimize.OptimizeResult`` has it.

    Attributes
    ----------
    t : ndarray, shape (n,)
    q, dq : ndarray, shape (n, 2)
        Joint angles and rates.
    tau : ndarray, shape (n, 2)
        The torques applied.
    status : int
        The integrator's status (0: reached the end; a failure raises instead).
    message : str
        The integrator's message.
    """

    t: Array
    q: Array
    dq: Array
    tau: Array
    status: int
    message: str

    @property
    def success(self) -> bool:
        """True when the integration reached the last time."""
        return self.status == 0


@dataclass(frozen=True, kw_only=True)
class ForwardResult(SimResult):
    """Forward dynamics: a :class:`SimResult` with the accelerations ``ddq`` (n, 2) and the
    number of right-hand-side evaluations ``nfev``."""

    ddq: Array
    nfev: int


def torques_from_samples(t: Array, tau: Array) -> TorqueFunction:
    """A torque function interpolating samples ``tau`` (n, 2) at times ``t`` (n,) by cubic
    splines (open loop: the state is ignored)."""
    t = np.asarray(t, dtype=float)
    tau = np.asarray(tau, dtype=float)
    if tau.shape != (t.size, 2):
        raise ParameterError(f"torque samples must have shape ({t.size}, 2), got {tau.shape}")

    spl = interpolate.CubicSpline(t, tau, axis=0)

    def fn(time: float, _q: Array, _dq: Array) -> Array:
        return np.asarray(spl(time))

    return fn


def forward_dynamics(model: Model, torque: TorqueFunction, q0: object, dq0: object,
                     t_eval: object, *, rtol: float = 1e-10, atol: float = 1e-12,
                     method: str = "DOP853", max_step: float = np.inf) -> ForwardResult:
    """Integrate the motion from ``(q0, dq0)`` under ``torque(t, q, dq)``.

    Parameters
    ----------
    torque : callable
        ``torque(t, q, dq) -> (2,)``; see :func:`torques_from_samples` for sampled torques.
    q0, dq0 : array_like, shape (2,)
    t_eval : array_like, shape (n,)
        Output times, increasing; the integration runs from ``t_eval[0]`` to ``t_eval[-1]``.

    Raises
    ------
    SingularityError
        If the motion reaches a parallel singularity (names the time).
    ConvergenceError
        If the integrator fails.
    """

    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.ndim != 1 or t_eval.size < 2 or np.any(np.diff(t_eval) <= 0):
        raise ParameterError("t_eval must be an increasing sequence of at least two times")
    y0 = np.concatenate([np.asarray(q0, float).reshape(2), np.asarray(dq0, float).reshape(2)])
    if not np.isfinite(y0).all():
        raise ParameterError("initial state must be finite")
    nfev = 0

    def rhs(time: float, y: Array) -> Array:
        nonlocal nfev
        nfev += 1
        q, dq = y[:2], y[2:]
        try:
            M, h = state_dynamics(model, q, dq)
        except SingularityError as exc:
            raise SingularityError(f"forward dynamics at t = {time:.6g}: {exc}") from None
        except ZeroDivisionError:  # a trial state exactly at it: det A = 0 before the check
            raise SingularityError(
                f"forward dynamics at t = {time:.6g}: parallel (type 2) singularity: q = "
                f"({np.degrees(q[0]):.6g}, {np.degrees(q[1]):.6g}) deg") from None
        tau = np.asarray(torque(time, q, dq), dtype=float)
        return np.concatenate([dq, np.linalg.solve(M, tau - h)])

    sol = integrate.solve_ivp(rhs, (t_eval[0], t_eval[-1]), y0, method=method, t_eval=t_eval, rtol=rtol,
                    atol=atol, max_step=max_step)
    if not sol.success:
        raise ConvergenceError(f"forward dynamics failed at t = {sol.t[-1]:.6g}: {sol.message}")
    q, dq = sol.y[:2].T, sol.y[2:].T
    tau = np.array([torque(ti, qi, dqi) for ti, qi, dqi in zip(sol.t, q, dq, strict=True)])
    ddq = accelerations(model, q, dq, tau, t=sol.t)
    return ForwardResult(t=sol.t, q=q, dq=dq, tau=tau, status=int(sol.status),
                         message=str(sol.message), ddq=ddq, nfev=nfev)


@dataclass(frozen=True, kw_only=True)
class TaskForwardResult(ForwardResult):
    """Forward dynamics in the end-effector's coordinates (:func:`forward_task_dynamics`): a
    :class:`ForwardResult` (``q`` by inverse kinematics, unwrapped) with the end-effector's
    motion ``P, dP, ddP`` (n, 2)."""

    P: Array
    dP: Array
    ddP: Array


def task_step(model: Model, signs: tuple[int, int], P: Array, dP: Array, tau: Array,
              dt: float, substeps: int = 4) -> tuple[Array, Array]:
    """The end-effector's state ``(P, dP)`` after ``dt`` under the constant torques ``tau``:
    ``substeps`` classical Runge-Kutta steps of ``M_P Pddot + h_P = E tau``
    (:func:`dextar.dynamics.closed_chain.task_state`), in the working mode of ``signs``.

    Raises
    ------
    SingularityError
        A state out of reach or at a serial singularity (the working mode ends there).
    """
    h = dt / substeps
    tau = np.asarray(tau, float)

    def f(y: Array) -> Array:
        st = task_state(model, signs, y[:2], y[2:])
        if st is None:
            raise SingularityError(f"the end-effector at ({y[0]:.6g}, {y[1]:.6g}) is out of "
                                   "reach or at a serial (type 1) singularity")
        M, hh, E, _, _ = st
        return np.concatenate([y[2:], np.linalg.solve(M, E @ tau - hh)])

    y = np.concatenate([np.asarray(P, float), np.asarray(dP, float)])
    for _ in range(substeps):
        k1 = f(y)
        k2 = f(y + 0.5 * h * k1)
        k3 = f(y + 0.5 * h * k2)
        k4 = f(y + h * k3)
        y = y + (h / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)
    return y[:2], y[2:]


def forward_task_dynamics(model: Model, mode: str, torque: TorqueFunction, P0: object,
                          dP0: object, t_eval: object, *, substeps: int = 4
                          ) -> TaskForwardResult:
    """Integrate the motion from ``(P0, dP0)`` in the end-effector's coordinates, ``M_P Pddot
    + h_P = E tau`` (:func:`dextar.dynamics.closed_chain.task_dynamics`), the motor angles by
    inverse kinematics in working mode ``mode``, the torques held over each interval of
    ``t_eval`` as a servo drive holds them: ``torque(t, q, dq)`` at the interval's middle time
    and its first state; ``substeps`` Runge-Kutta steps per interval (the held torque makes
    each interval's motion smooth).

    Unlike :func:`forward_dynamics` (in the motor angles, whose mass matrix grows without
    bound at a parallel singularity), this passes through parallel (type 2) singularities:
    there ``E`` loses rank but nothing is inverted but ``M_P``, positive definite; the
    assembly mode changes where the motion crosses the curve. It stops at a serial (type 1)
    singularity, where the working mode is no longer defined.

    Raises
    ------
    SingularityError
        The motion reaches a serial singularity or leaves the workspace (names the time).
    """
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.ndim != 1 or t_eval.size < 2 or np.any(np.diff(t_eval) <= 0):
        raise ParameterError("t_eval must be an increasing sequence of at least two times")
    P, dP = np.asarray(P0, float).reshape(2), np.asarray(dP0, float).reshape(2)
    if not (np.isfinite(P).all() and np.isfinite(dP).all()):
        raise ParameterError("initial state must be finite")
    signs = parse_working_mode(mode)
    n = len(t_eval)
    Ps, dPs, taus = np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 2))
    Ps[0], dPs[0] = P, dP
    for k in range(n - 1):
        st = task_state(model, signs, P, dP)
        if st is None:
            raise SingularityError(f"forward dynamics at t = {t_eval[k]:.6g}: the end-effector "
                                   "left the workspace or met a serial (type 1) singularity")
        tau = np.asarray(torque(0.5 * (t_eval[k] + t_eval[k + 1]), st[3], st[4]), float)
        taus[k] = tau
        try:
            P, dP = task_step(model, signs, P, dP, tau, t_eval[k + 1] - t_eval[k], substeps)
        except SingularityError as exc:
            raise SingularityError(f"forward dynamics at t = {t_eval[k]:.6g}: {exc}") from None
        Ps[k + 1], dPs[k + 1] = P, dP
    taus[-1] = taus[-2]
    td = task_dynamics(model, mode, Ps, dPs)
    q = inverse_kinematics(model.robot, Ps, mode, unwrap=True)
    ddP = td.acceleration(taus)
    dq, ddq = joint_rates(model.robot, q, Ps, dPs, ddP, tol=0.0)
    return TaskForwardResult(t=t_eval, q=q, dq=dq, tau=taus, status=0,
                             message="reached the last time", ddq=ddq,
                             nfev=4 * substeps * (n - 1), P=Ps, dP=dPs, ddP=ddP)
