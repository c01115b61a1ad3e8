"""Trajectories: a law of motion sampled along a path, in task space and in joint space.

Joint rates and accelerations come from the velocity and acceleration relations of the
kinematics (``B qdot = A Pdot`` and its derivative), never from finite differences.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ParameterError, ReachError, SingularityError
from .geometry import FiveBar, assembly_mode_name, parse_working_mode, working_mode_name
from .kinematics import (
    DEFAULT_SINGULARITY_TOL,
    assembly_mode,
    inverse_kinematics,
    joint_acceleration,
    joint_velocity,
    parallel_indicator,
    singularity_distances,
)
from .laws import Law
from .paths import Path
from .units import Units


@dataclass(frozen=True)
class Trajectory:
    """Time samples of a motion.

    Attributes
    ----------
    t : ndarray, shape (n,)
    s, ds, dds : ndarray, shape (n,)
        Arc length along the path and its time derivatives.
    p, dp, ddp : ndarray, shape (n,)
        Path parameter and its time derivatives.
    P, dP, ddP : ndarray, shape (n, 2)
        End-effector position, velocity, acceleration.
    q, dq, ddq : ndarray, shape (n, 2)
        Actuator angles ``(phi, psi)`` (unwrapped, radians), rates and accelerations.
    mode, assembly : str
        Working mode and assembly mode along the motion.
    """

    robot: FiveBar
    path: Path
    law: Law
    mode: str
    assembly: str
    t: np.ndarray
    s: np.ndarray
    ds: np.ndarray
    dds: np.ndarray
    p: np.ndarray
    dp: np.ndarray
    ddp: np.ndarray
    P: np.ndarray
    dP: np.ndarray
    ddP: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray

    def columns(self) -> dict[str, np.ndarray]:
        """The plan columns: ``t, p, dp, ddp, x, y, dx, dy, ddx, ddy, phi, psi, dphi, dpsi,
        ddphi, ddpsi``."""
        return {
            "t": self.t, "p": self.p, "dp": self.dp, "ddp": self.ddp,
            "x": self.P[:, 0], "y": self.P[:, 1], "dx": self.dP[:, 0], "dy": self.dP[:, 1],
            "ddx": self.ddP[:, 0], "ddy": self.ddP[:, 1],
            "phi": self.q[:, 0], "psi": self.q[:, 1], "dphi": self.dq[:, 0],
            "dpsi": self.dq[:, 1], "ddphi": self.ddq[:, 0], "ddpsi": self.ddq[:, 1],
        }


def path_motion(path: Path, law: Law, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """Path parameter and end-effector motion at times ``t``.

    Returns ``(s, ds, dds, p, dp, ddp, P, dP, ddP)``; with ``v = |r'(p)|`` and
    ``v' = r' . r'' / v``: ``pdot = sdot / v``, ``pddot = (sddot - v' pdot^2) / v``,
    ``Pdot = r' pdot``, ``Pddot = r'' pdot^2 + r' pddot``.
    """
    s, ds, dds, _ = law.evaluate(t)
    p = path.parameter_at(s)
    r, r1, r2, _ = path.derivatives(p)
    v = np.linalg.norm(r1, axis=-1)
    dv = np.sum(r1 * r2, axis=-1) / v
    dp = ds / v
    ddp = (dds - dv * dp * dp) / v
    dP = r1 * dp[:, None]
    ddP = r2 * (dp * dp)[:, None] + r1 * ddp[:, None]
    return s, ds, dds, p, dp, ddp, r, dP, ddP


def sample_trajectory(robot: FiveBar, path: Path, law: Law, *, mode: str = "+-",
                      samples: int = 1001, times: np.ndarray | None = None,
                      tol: float = DEFAULT_SINGULARITY_TOL,
                      units: Units | None = None) -> Trajectory:
    """Sample ``law`` along ``path`` and map it to joint space in working mode ``mode``.

    Parameters
    ----------
    samples : int
        Number of samples on a uniform grid including ``t = 0`` and ``t = T``.
    times : ndarray, optional
        Explicit sample times (overrides ``samples``).
    tol : float
        Smallest normalised distance to a singularity accepted on the way.
    units : Units, optional
        The run's units, only to state points in mm and times in seconds in an error.

    Raises
    ------
    ReachError
        The path leaves the workspace; names the first time and point.
    SingularityError
        The path meets a singularity for this working mode; names the first time and point.
    """
    mode = working_mode_name(parse_working_mode(mode))
    if not np.isclose(law.distance, path.length, rtol=1e-9, atol=0.0):
        raise ParameterError(f"the law covers a distance of {law.distance:.9g} but the path is "
                             f"{path.length:.9g} long")
    t = law.times(samples) if times is None else np.asarray(times, dtype=float)
    s, ds, dds, p, dp, ddp, P, dP, ddP = path_motion(path, law, t)
    _check_reach(robot, t, P, units)
    q = inverse_kinematics(robot, P, mode, unwrap=True)
    d1, d2 = singularity_distances(robot, q, P)
    det = parallel_indicator(robot, q, P)
    crossing = np.concatenate([[False], np.sign(det[1:]) != np.sign(det[:-1])])
    for kind, dist in ((1, d1), (2, d2)):
        bad = dist < tol
        if kind == 2:
            bad = bad | crossing
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            what = "serial (type 1)" if kind == 1 else "parallel (type 2)"
            raise SingularityError(
                f"the path meets a {what} singularity in working mode {mode} at "
                f"{_when(t[i], units)} (sample {i}): P = {_point(P[i], units)}, q = "
                f"({np.degrees(q[i, 0]):.6g}, {np.degrees(q[i, 1]):.6g}) deg, normalised "
                f"distance {dist[i]:.3g}" + (f" below {tol:g}" if dist[i] < tol else
                                             ", crossed since the previous sample"))
    dq = joint_velocity(robot, q, P, dP, tol=0.0)
    ddq = joint_acceleration(robot, q, P, dq, dP, ddP, tol=0.0)
    sig = assembly_mode(robot, q, P)
    return Trajectory(robot, path, law, mode, assembly_mode_name(int(sig[0])), t, s, ds, dds,
                      p, dp, ddp, P, dP, ddP, q, dq, ddq)


def check_path(robot: FiveBar, path: Path, *, mode: str = "+-", samples: int = 2001,
               tol: float = DEFAULT_SINGULARITY_TOL, units: Units | None = None) -> None:
    """Check a path before any law is planned on it: every one of ``samples`` points equally
    spaced in the path parameter within reach, and clear of both singularity types in working
    mode ``mode``. Errors name the path parameter and the point (in mm with ``units``).

    Raises
    ------
    ReachError, SingularityError
    """
    mode = working_mode_name(parse_working_mode(mode))
    p = np.linspace(path.p0, path.p1, samples)
    P = path.position(p)
    where = [f"p = {v:.6g}" for v in p]
    try:
        _check_reach(robot, p, P, None)
    except ReachError:
        for leg, pivot in ((1, robot.A), (2, robot.D)):
            rin, rout = robot.reach(leg)
            rho = np.hypot(P[:, 0] - pivot[0], P[:, 1])
            bad = (rho < rin) | (rho > rout)
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                out = max(rin - rho[i], rho[i] - rout)
                by = f"{out:.6g}" if units is None else f"{units.mm(out):.6g} mm"
                raise ReachError(f"the path leaves the workspace at {where[i]}: point "
                                 f"{_point(P[i], units)} is out of reach of leg {leg} by "
                                 f"{by}") from None
    q = inverse_kinematics(robot, P, mode, unwrap=True)
    d1, d2 = singularity_distances(robot, q, P)
    det = parallel_indicator(robot, q, P)
    crossing = np.concatenate([[False], np.sign(det[1:]) != np.sign(det[:-1])])
    for kind, dist in ((1, d1), (2, d2)):
        bad = (dist < tol) | (crossing if kind == 2 else False)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            what = "serial (type 1)" if kind == 1 else "parallel (type 2)"
            raise SingularityError(
                f"the path meets a {what} singularity in working mode {mode} at {where[i]}: "
                f"P = {_point(P[i], units)}, q = ({np.degrees(q[i, 0]):.6g}, "
                f"{np.degrees(q[i, 1]):.6g}) deg, normalised distance {dist[i]:.3g}"
                + (f" below {tol:g}" if dist[i] < tol else ", crossed on the way"))


def _when(t: float, units: Units | None) -> str:
    return f"t = {t:.6g}" if units is None else units.time_text(t)


def _point(P: np.ndarray, units: Units | None) -> str:
    return f"({P[0]:.6g}, {P[1]:.6g})" if units is None else units.point_text(P)


def _check_reach(robot: FiveBar, t: np.ndarray, P: np.ndarray, units: Units | None) -> None:
    for leg, pivot in ((1, robot.A), (2, robot.D)):
        rin, rout = robot.reach(leg)
        rho = np.hypot(P[:, 0] - pivot[0], P[:, 1])
        bad = (rho < rin) | (rho > rout)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            out = max(rin - rho[i], rho[i] - rout)
            by = f"{out:.6g}" if units is None else f"{units.mm(out):.6g} mm"
            raise ReachError(
                f"the path leaves the workspace at {_when(t[i], units)} (sample {i}): point "
                f"{_point(P[i], units)} is out of reach of leg {leg} by {by}")
