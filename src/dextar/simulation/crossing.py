"""Tracking a motion across the parallel (type 2) singularity curve.

Computed-torque control in the motor angles fails there: the model's mass matrix grows
without bound as the distal rods align, and a controller that inverts the map from torques to
the end-effector's forces asks unbounded torques for any error along the rods' normal, which
no motor can give (Pagis, Bouton, Briot & Martinet, "Enlarging parallel robot workspace
through Type-2 singularity crossing", Control Eng. Practice 39, 2015). Two things change here:

* **the plant** is integrated in the end-effector's coordinates, ``M_P Pddot + h_P = E tau``
  with ``E = A^T B^-1`` (:mod:`dextar.dynamics.closed_chain`), regular through the crossing:
  the motors lose their grip on the rods' normal there and the robot passes on its momentum
  (:func:`dextar.dynamics.forward.task_step`, classical Runge-Kutta under torques held over
  each control period, as a servo drive holds them);
* **the controller** is the planned torques (which meet the degeneracy condition, so they are
  bounded) plus a task-space PD whose force ``W = M_P (Kp e + Kd edot)`` is mapped to torques
  by the damped least-squares inverse ``E^T (E E^T + rho^2 I)^-1`` of ``E`` (the
  singularity-robust inverse of Nakamura & Hanafusa, J. Dyn. Sys. Meas. Control 108, 1986),
  ``rho`` a fraction :data:`SR_DAMPING` of ``E``'s largest singular value: where ``E`` keeps
  full rank it is computed-torque's error feedback; near the crossing the correction along
  the rods' normal, which would need unbounded torque, fades out instead of blowing up, and
  grows back as the robot leaves it. The error is measured on the end-effector (which the
  motor angles cannot tell apart between the two assembly modes), so the loop keeps the
  robot on the planned branch. Bordalba, Porta & Ros ("A singularity-robust LQR controller
  for parallel robots", IROS 2018) reach the same end with an LQR on the full coordinates;
  this is the simpler controller of the same kind.
"""

from __future__ import annotations

import math

import numpy as np

from .._arrays import Array
from ..dynamics.closed_chain import task_state
from ..dynamics.crossing import PlannedTorques, RobotAcrossPath
from ..dynamics.exact import Model
from ..dynamics.forward import task_step
from ..errors import ParameterError, SingularityError
from ..geometry import assembly_mode_name, parse_working_mode
from ..kinematics import (
    assembly_mode,
    direct_kinematics,
    inverse_kinematics,
    joint_velocity,
    task_velocity,
)
from ..paths import Path
from ..trajectory import Trajectory, path_motion
from .control import ControlResult, checked_loop

#: The damped least-squares inverse's damping, a fraction of ``E``'s largest singular value:
#: the feedback along the rods' normal is halved where the normalised distance to the
#: singularity is about this (2.4 mm either side of the DexTAR's crossing).
SR_DAMPING = 0.05
#: The controller's rate (Hz) when the trajectory's samples are further apart.
CONTROL_RATE = 2000.0
#: The plant's longest Runge-Kutta step (s): a quarter of the default control period (the
#: DexTAR's crossing at 20 % mass error tracked to the same 1.19 mm at an eighth).
MAX_STEP = 1.25e-4


def sr_inverse(E: Array, damping: float = SR_DAMPING) -> Array:
    """The damped least-squares inverse ``E^T (E E^T + rho^2 I)^-1`` of a 2x2 matrix,
    ``rho = damping * sigma_max(E)`` (``damping = 0``: the plain inverse)."""
    s_max = float(np.linalg.norm(E, 2))
    rho2 = (damping * s_max) ** 2
    return np.asarray(E.T @ np.linalg.inv(E @ E.T + rho2 * np.eye(2)))


def simulate_crossing(trajectory: Trajectory, controller: Model, plant: Model, *,
                      natural_frequency: float, damping: float = 1.0,
                      torque_limit: float | None = None,
                      initial_error: tuple[float, float] = (0.0, 0.0),
                      tolerance: float | None = None, time_s: float = 1.0,
                      length_mm: float = 1.0, rate: float | None = None,
                      max_step: float | None = None, sr_damping: float = SR_DAMPING
                      ) -> ControlResult:
    """Track ``trajectory`` (a path motion; it may cross the parallel singularity curve, its
    ``crossings``) with the planned torques of ``controller`` and the singularity-robust
    task-space feedback (module doc), on ``plant``.

    Parameters
    ----------
    controller, plant : Model
        The model the controller believes (the feedforward, ``M_P`` and ``E``) and the true
        robot (the assembly modes are the trajectory's: both models are used in full
        coordinates).
    natural_frequency, damping : float
        The task-space loop's ``w`` (rad per run time unit) and ``zeta``: ``Kp = w^2``,
        ``Kd = 2 zeta w``.
    torque_limit : float, optional
        Symmetric saturation of each motor torque.
    initial_error : (float, float)
        The motor angles' error at the start (rad), the end-effector placed by the direct
        kinematics in the start's assembly mode.
    tolerance : float, optional
        The task error (run length unit) within which the motion is followed (default
        :func:`~dextar.simulation.control.tracking_tolerance`).
    rate : float, optional
        The controller's rate (per run time unit): its torques are held over each period.
        Default: the trajectory's samples, subdivided to :data:`CONTROL_RATE` per second.
    max_step : float, optional
        The plant's longest Runge-Kutta step (run time unit; default :data:`MAX_STEP` s).
    sr_damping : float
        :data:`SR_DAMPING` (0: the plain inverse of ``E``, which the tests show asking
        unbounded torques at the crossing).

    Returns
    -------
    ControlResult
        On the trajectory's times (status 0: followed within the tolerance and ended in the
        planned assembly mode; 1: the plant met a serial singularity or left the workspace;
        2: it left the tolerance or ended in the other assembly mode).
    """
    tr = trajectory
    if not isinstance(tr.path, Path):
        raise ParameterError("a crossing is tracked along a task-space path (a joint line "
                             "crosses no parallel singularity)")
    kp, kd, tolerance = checked_loop(plant, natural_frequency, damping, torque_limit,
                                     tolerance)
    signs = parse_working_mode(tr.mode)
    step = MAX_STEP / time_s if max_step is None else max_step
    # the control periods: the trajectory's sample intervals, each cut to the rate
    per_s = CONTROL_RATE * time_s if rate is None else rate
    sub = np.maximum(np.ceil(np.diff(tr.t) * per_s - 1e-9), 1).astype(int)
    ticks = np.concatenate([[tr.t[0]]] + [np.linspace(a, b, m + 1)[1:] for a, b, m in
                                          zip(tr.t[:-1], tr.t[1:], sub, strict=True)])
    mids = 0.5 * (ticks[:-1] + ticks[1:])
    feedforward = PlannedTorques(RobotAcrossPath(controller, tr.path, tr.mode, tr.crossings),
                                 tr.law)(mids)
    Pd, dPd = path_motion(tr.path, tr.law, ticks)[6:8]
    # the start: the planned state, the angles off by the initial error
    q0 = tr.q[0] + np.asarray(initial_error, float)
    P = direct_kinematics(plant.robot, q0, tr.assembly)
    dP = task_velocity(plant.robot, q0, P, tr.dq[0], tol=0.0)
    Ps, dPs = [P], [dP]
    taus, sat = [], []
    stop: str | None = None
    for k in range(len(ticks) - 1):
        st = task_state(controller, signs, P, dP)
        if st is None:
            stop = (f"the controlled robot left the workspace or met a serial (type 1) "
                    f"singularity at t = {ticks[k] * time_s:.6g} s")
            break
        M, _, E, _, _ = st
        W = M @ (kp * (Pd[k] - P) + kd * (dPd[k] - dP))
        tau = feedforward[k] + sr_inverse(E, sr_damping) @ W
        clipped = tau if torque_limit is None else np.clip(tau, -torque_limit, torque_limit)
        taus.append(clipped)
        sat.append(bool(np.any(clipped != tau)))
        try:
            dt = ticks[k + 1] - ticks[k]
            P, dP = task_step(plant, signs, P, dP, clipped, dt, max(1, math.ceil(dt / step)))
        except SingularityError as exc:
            stop = f"the controlled robot met a singularity at t = {ticks[k] * time_s:.6g} s: {exc}"
            break
        Ps.append(P)
        dPs.append(dP)
    reached = len(Ps)  # ticks simulated, with the start
    at_sample = np.concatenate([[0], np.cumsum(sub)])  # each trajectory sample's tick
    n = int(np.searchsorted(at_sample, reached - 1, side="right"))
    idx = at_sample[:n]
    Pt, dPt = np.array(Ps)[idx], np.array(dPs)[idx]
    tau_t = np.array(taus + [taus[-1]] if taus else [np.zeros(2)])[np.minimum(idx,
                                                                            len(taus) - 1)]
    sat_t = np.array(sat + [False])[np.minimum(idx, len(sat))]
    q = inverse_kinematics(plant.robot, Pt, tr.mode, unwrap=True)
    q = q + np.round((tr.q[0] - q[0]) / (2 * np.pi)) * 2 * np.pi  # the plan's turn
    dq = joint_velocity(plant.robot, q, Pt, dPt, tol=0.0)
    task_error = np.linalg.norm(tr.P[:n] - Pt, axis=-1)
    outside = np.flatnonzero(~(task_error <= tolerance))
    left_at = int(outside[0]) if outside.size else None
    end_asm = assembly_mode_name(int(assembly_mode(plant.robot, q[-1], Pt[-1])))
    t = tr.t[:n]
    if stop is not None:
        status, message = 1, stop
    elif left_at is not None:
        k = int(np.argmax(task_error))
        status = 2
        message = (f"the controlled robot left the tolerance {tolerance * length_mm:.4g} mm at "
                   f"t = {t[left_at] * time_s:.6g} s (task error "
                   f"{task_error[left_at] * length_mm:.4g} mm), its largest error "
                   f"{task_error[k] * length_mm:.4g} mm at t = {t[k] * time_s:.6g} s")
    elif end_asm != tr.end_assembly:
        status, message = 2, (f"the controlled robot ended in assembly mode {end_asm}, not "
                              f"{tr.end_assembly} as planned")
    else:
        crossed = "" if not tr.crossings else (
            f", across the parallel singularity curve into assembly mode {end_asm}")
        status, message = 0, (f"the controlled robot followed the whole motion within "
                              f"{tolerance * length_mm:.4g} mm (largest error "
                              f"{float(task_error.max()) * length_mm:.4g} mm){crossed}")
    return ControlResult(t=t, q=q, dq=dq, tau=tau_t, status=status, message=message, P=Pt,
                         joint_error=tr.q[:n] - q, task_error=task_error, saturated=sat_t,
                         torque_limit=torque_limit, tolerance=tolerance, left_at=left_at)
