"""Forward dynamics: integrate ``M(q) qddot = tau(t, q, qdot) - h(q, qdot)``."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..errors import ConvergenceError, ParameterError, SingularityError
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
