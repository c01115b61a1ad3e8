"""Computed-torque control of the five-bar along a trajectory, against a plant that differs
from the controller's model.

Control law: ``tau = M_hat(q) (qddot_d + Kd (qdot_d - qdot) + Kp (q_d - q)) + h_hat(q, qdot)``
with ``Kp = w^2``, ``Kd = 2 zeta w``, optionally saturated at ``+-torque_limit``. The plant
integrates its own (true) dynamics, e.g. with masses off by 20 % and an unmodelled payload.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..dynamics.exact import Model, state_dynamics
from ..dynamics.forward import SimResult
from ..errors import (
    AssemblyError,
    ConvergenceError,
    DextarError,
    ParameterError,
    SingularityError,
)
from ..geometry import FiveBar
from ..kinematics import direct_kinematics
from ..trajectory import Trajectory

integrate = lazy_module("scipy.integrate")
interpolate = lazy_module("scipy.interpolate")

#: The default tracking tolerance, a fraction of the robot's reach ``max(l1 + L1, l2 + L2)``:
#: 3 % (4.8 mm on the DexTAR, 9 mm on a 120/180 mm robot). Measured with the default
#: controller (10 Hz, masses 20 % off, an unknown payload) and the examples' own: the
#: examples' motions 0.2-1.5 mm (1.4e-3 to 9.7e-3 of the reach, the time-optimal one the
#: largest), a 120/180/100 mm robot with 0.4 kg at the effector, gravity and friction
#: within 1.5 N m 0.62 mm, 30 random configs at most 0.89 mm (5.6e-3); the same robot
#: saturating at 0.3 N m falls: 170-510 mm (0.57-1.7 of the reach); a 20-turn arc of 30 mm
#: radius in 2 s is left 18 mm behind (0.115): not followed. ``[control].tolerance_mm``
#: sets it.
TRACKING_TOLERANCE = 0.03

#: The plant's integrator (scipy.integrate's solver class of this name): LSODA (Adams, or BDF where dry friction near rest makes the
#: dynamics stiff). RK45 took 220 s on a 1 s arc of a robot falling to rest against 0.02 N m
#: of Coulomb friction (its steps held to the friction's time constant); LSODA 3 s, the same
#: tracking errors to four digits on the examples.
SOLVER = "LSODA"
#: Steps after which the plant's integration is stopped: the simulation is incomplete (a
#: result, :data:`INCOMPLETE`; the files hold the motion up to there).
MAX_STEPS = 100_000

#: ``ControlResult.status`` of each outcome.
FOLLOWED, SINGULARITY_MET, LEFT_TOLERANCE, INCOMPLETE = 0, 1, 2, 3


def checked_loop(plant: Model, natural_frequency: float, damping: float,
                 torque_limit: float | None, tolerance: float | None
                 ) -> tuple[float, float, float]:
    """A tracking loop's settings checked (each positive and finite; exit 2 naming it): its
    gains ``(kp, kd)`` and the tracking tolerance (default :func:`tracking_tolerance`)."""
    if not (natural_frequency > 0 and np.isfinite(natural_frequency)):
        raise ParameterError(f"natural frequency {natural_frequency!r} must be positive")
    if not (damping > 0 and np.isfinite(damping)):
        raise ParameterError(f"damping ratio {damping!r} must be positive")
    if torque_limit is not None and not (torque_limit > 0):
        raise ParameterError(f"torque limit {torque_limit!r} must be positive")
    if tolerance is None:
        tolerance = tracking_tolerance(plant.robot)
    if not (tolerance > 0 and np.isfinite(tolerance)):
        raise ParameterError(f"tracking tolerance {tolerance!r} must be positive")
    return natural_frequency**2, 2.0 * damping * natural_frequency, tolerance


def tracking_tolerance(robot: FiveBar) -> float:
    """The default tracking tolerance (the robot's length unit):
    :data:`TRACKING_TOLERANCE` of its reach."""
    return TRACKING_TOLERANCE * max(robot.l1 + robot.L1, robot.l2 + robot.L2)


@dataclass(frozen=True, kw_only=True)
class ControlResult(SimResult):
    """Tracking: a :class:`~dextar.dynamics.forward.SimResult` on the trajectory's time grid
    (``q, dq`` the plant's, ``tau`` the applied, saturated torques; ``status`` 0 when the
    robot followed the motion within the tolerance, 1 when the plant met a singularity and
    the samples end there, 2 when it left the tolerance, 3 when the simulation is
    incomplete: its integration stopped after :data:`MAX_STEPS` steps, the robot within the
    tolerance until then; ``message`` saying which and when) with

    Attributes
    ----------
    P : ndarray, shape (n, 2)
        The plant's end-effector.
    joint_error : ndarray, shape (n, 2)
        ``q_d - q`` (radians).
    task_error : ndarray, shape (n,)
        ``|P_d - P|`` (run length unit).
    saturated : ndarray of bool, shape (n,)
        Samples where a motor torque was clipped at the limit.
    torque_limit : float or None
        The saturation limit (run torque unit).
    tolerance : float or None
        The task error within which the motion counts as followed (run length unit).
    left_at : int or None
        The first sample whose task error exceeds the tolerance.
    complete : bool
        The samples reach the motion's end (neither a singularity nor the step budget
        stopped the integration).
    """

    P: Array
    joint_error: Array
    task_error: Array
    saturated: Array
    torque_limit: float | None = None
    tolerance: float | None = None
    left_at: int | None = None
    complete: bool = True

    def summary(self) -> dict[str, float]:
        """Tracking figures: task errors (run length unit), joint error (rad), saturation."""
        return {
            "max_task_error": float(self.task_error.max()),
            "rms_task_error": float(np.sqrt(np.mean(self.task_error**2))),
            "final_task_error": float(self.task_error[-1]),
            "max_joint_error_rad": float(np.abs(self.joint_error).max()),
            "saturated_fraction": float(self.saturated.mean()),
        }


def simulate_computed_torque(trajectory: Trajectory, controller: Model, plant: Model, *,
                             natural_frequency: float, damping: float = 1.0,
                             torque_limit: float | None = None,
                             initial_error: tuple[float, float] = (0.0, 0.0),
                             tolerance: float | None = None, time_s: float = 1.0,
                             length_mm: float = 1.0, rtol: float = 1e-8) -> ControlResult:
    """Simulate computed-torque tracking of ``trajectory``.

    Parameters
    ----------
    controller : Model
        The model the controller believes (feed-forward and linearisation).
    plant : Model
        The true robot.
    natural_frequency : float
        Closed-loop natural frequency ``w`` (rad per run time unit).
    damping : float
        Damping ratio ``zeta``.
    torque_limit : float, optional
        Symmetric saturation of each motor torque.
    initial_error : (float, float)
        Initial joint-angle error ``q(0) - q_d(0)`` in radians.
    tolerance : float, optional
        The task error (run length unit) within which the motion is followed (default
        :func:`tracking_tolerance`); past it ``status`` is 2 and the message names the
        time and the error.
    time_s, length_mm : float
        A run time unit in seconds and a run length unit in mm, for the message.
    """
    kp, kd, tolerance = checked_loop(plant, natural_frequency, damping, torque_limit,
                                     tolerance)
    tr = trajectory
    q_d = interpolate.CubicHermiteSpline(tr.t, tr.q, tr.dq, axis=0)
    dq_d = interpolate.CubicHermiteSpline(tr.t, tr.dq, tr.ddq, axis=0)
    ddq_d = dq_d.derivative()

    def control(t: float, q: Array, dq: Array) -> tuple[Array, bool]:
        M, h = state_dynamics(controller, q, dq)
        v = ddq_d(t) + kd * (dq_d(t) - dq) + kp * (q_d(t) - q)
        tau = M @ v + h
        if torque_limit is not None:
            clipped = np.clip(tau, -torque_limit, torque_limit)
            return clipped, bool(np.any(clipped != tau))
        return tau, False

    def rhs(t: float, y: Array) -> Array:
        q, dq = y[:2], y[2:]
        try:  # the plant first: a state it cannot take is a singularity met
            M, h = state_dynamics(plant, q, dq)
            tau, _ = control(t, q, dq)
            acc = np.linalg.solve(M, tau - h)
        except (SingularityError, AssemblyError, ArithmeticError,
                np.linalg.LinAlgError) as exc:
            # (an integrator's trial state exactly at a parallel singularity divides by zero
            # before the tolerance is checked)
            why = str(exc) if isinstance(exc, DextarError) else (
                f"parallel (type 2) singularity: q = ({math.degrees(q[0]):.6g}, "
                f"{math.degrees(q[1]):.6g}) deg")
            raise SingularityError(f"the controlled robot met a singularity at t = "
                                   f"{t * time_s:.6g} s: {why}") from None
        return np.concatenate([dq, acc])

    y0 = np.concatenate([tr.q[0] + np.asarray(initial_error, float), tr.dq[0]])
    dt = float(np.min(np.diff(tr.t)))
    t_end, sol, stop, budget = _integrate(rhs, tr.t, y0, rtol=rtol, max_step=4 * dt,
                                          time_s=time_s)
    n = int(np.searchsorted(tr.t, t_end, side="right"))
    t = tr.t[:n]
    y = sol(t)
    q, dq = y[:2].T, y[2:].T
    taus, sat = zip(*(control(ti, qi, dqi) for ti, qi, dqi in zip(t, q, dq, strict=True)),
                    strict=True)
    P = direct_kinematics(plant.robot, q, plant.assembly)
    saturated = np.array(sat)
    task_error = np.linalg.norm(tr.P[:n] - P, axis=-1)
    outside = np.flatnonzero(~(task_error <= tolerance))
    left_at = int(outside[0]) if outside.size else None
    if stop is not None and not budget:
        status, message = SINGULARITY_MET, stop
    elif left_at is not None:
        k = int(np.argmax(task_error))
        status = LEFT_TOLERANCE
        message = (f"the controlled robot left the tolerance {tolerance * length_mm:.4g} mm at "
                   f"t = {t[left_at] * time_s:.6g} s (task error {task_error[left_at] * length_mm:.4g} "
                   f"mm), its largest error {task_error[k] * length_mm:.4g} mm at "
                   f"t = {t[k] * time_s:.6g} s" + ("" if stop is None else f"; then {stop}"))
    elif stop is not None:
        status = INCOMPLETE
        message = (f"{stop} of the motion's {tr.t[-1] * time_s:.6g} s; until then the "
                   f"controlled robot followed within "
                   f"{tolerance * length_mm:.4g} mm (largest error "
                   f"{float(task_error.max()) * length_mm:.4g} mm)")
    else:
        status, message = 0, (f"the controlled robot followed the whole motion within "
                               f"{tolerance * length_mm:.4g} mm (largest error "
                               f"{float(task_error.max()) * length_mm:.4g} mm)")
    return ControlResult(t=t, q=q, dq=dq, tau=np.array(taus), status=status, message=message,
                         P=P, joint_error=tr.q[:n] - q, task_error=task_error,
                         saturated=saturated, torque_limit=torque_limit, tolerance=tolerance,
                         left_at=left_at, complete=stop is None)


def _integrate(rhs: Callable[[float, Array], Array], t: Array, y0: Array, *, rtol: float,
               max_step: float, time_s: float = 1.0
               ) -> tuple[float, Callable[[Array], Array], str | None, bool]:
    """Step the plant from ``t[0]`` towards ``t[-1]``; a singularity met on the way, or
    :data:`MAX_STEPS` steps, end the integration there (a result, not a failure). Returns
    the last time reached, the dense solution up to it, why it stopped early (None: it did
    not) and whether the step budget stopped it."""
    solver = getattr(integrate, SOLVER)(rhs, float(t[0]), y0, float(t[-1]), rtol=rtol, atol=1e-10,
                  max_step=max_step)
    times, pieces = [float(t[0])], []
    stop: str | None = None
    budget = False
    while solver.status == "running":
        if len(times) > MAX_STEPS:
            stop = (f"the integration was stopped after {MAX_STEPS} steps (its budget) at "
                    f"t = {solver.t * time_s:.6g} s")
            budget = True
            break
        try:
            solver.step()
        except SingularityError as exc:
            stop = str(exc)
            break
        if solver.status == "failed" or solver.t <= times[-1]:
            # (a step that did not advance: it underflowed, e.g. a plant whose inertia is
            # next to nothing against its friction)
            raise ConvergenceError(f"control simulation failed at t = {solver.t * time_s:.6g} s: "
                                   "the integrator's step became too small")
        times.append(solver.t)
        pieces.append(solver.dense_output())
    if not pieces:
        raise SingularityError(f"the controlled robot cannot start: {stop}")
    sol = integrate.OdeSolution(times, pieces)
    return times[-1], (lambda tt: np.asarray(sol(tt))), stop, budget
