"""Trajectories: a law of motion sampled along a path, in task space and in joint space.

Joint rates and accelerations come from the velocity and acceleration relations of the
kinematics (``B qdot = A Pdot`` and its derivative), never from finite differences.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ._arrays import Array
from .errors import AssemblyError, ParameterError, SingularityError
from .geometry import (
    FiveBar,
    assembly_mode_name,
    parse_assembly_mode,
    parse_working_mode,
    working_mode_name,
)
from .kinematics import (
    assembly_mode,
    direct_kinematics,
    elbows,
    inverse_kinematics,
    joint_rates,
    parallel_indicator,
    task_acceleration,
    working_mode,
)
from .kinematics.checker import (
    DEFAULT_TOLERANCES,
    PoseDistances,
    Tolerances,
    check_poses,
    check_reach,
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
        Working mode and assembly mode along the motion (at its start, when it crosses the
        parallel singularity curve).
    crossings : tuple of Crossing
        Where the motion crosses the parallel singularity curve (each crossing changes the
        assembly mode), in the order of the path.
    """

    robot: FiveBar
    path: Path | JointLine
    law: Law
    mode: str
    assembly: str
    t: Array
    s: Array
    ds: Array
    dds: Array
    p: Array
    dp: Array
    ddp: Array
    P: Array
    dP: Array
    ddP: Array
    q: Array
    dq: Array
    ddq: Array
    crossings: tuple[Crossing, ...] = ()

    @property
    def end_assembly(self) -> str:
        """The assembly mode at the motion's end (the start's, flipped by each crossing)."""
        return self.crossings[-1].assembly_after if self.crossings else self.assembly

    def columns(self) -> dict[str, Array]:
        """The plan columns: ``t, p, dp, ddp, x, y, dx, dy, ddx, ddy, phi, psi, dphi, dpsi,
        ddphi, ddpsi``."""
        return {
            "t": self.t, "p": self.p, "dp": self.dp, "ddp": self.ddp,
            "x": self.P[:, 0], "y": self.P[:, 1], "dx": self.dP[:, 0], "dy": self.dP[:, 1],
            "ddx": self.ddP[:, 0], "ddy": self.ddP[:, 1],
            "phi": self.q[:, 0], "psi": self.q[:, 1], "dphi": self.dq[:, 0],
            "dpsi": self.dq[:, 1], "ddphi": self.ddq[:, 0], "ddpsi": self.ddq[:, 1],
        }


def path_motion(path: Path, law: Law, t: Array) -> tuple[Array, ...]:
    """Path parameter and end-effector motion at times ``t``.

    Returns ``(s, ds, dds, p, dp, ddp, P, dP, ddP)``; with ``v = |r'(p)|`` and
    ``v' = r' . r'' / v``: ``pdot = sdot / v``, ``pddot = (sddot - v' pdot^2) / v``,
    ``Pdot = r' pdot``, ``Pddot = r'' pdot^2 + r' pddot``.
    """
    s, ds, dds, _ = law.evaluate(t)
    p = path.parameter_at(s)
    r, r1, r2, _ = path.derivatives(p)
    v = np.sqrt(r1[..., 0] * r1[..., 0] + r1[..., 1] * r1[..., 1])
    dv = (r1[..., 0] * r2[..., 0] + r1[..., 1] * r2[..., 1]) / v
    dp = ds / v
    ddp = (dds - dv * dp * dp) / v
    dP = r1 * dp[:, None]
    ddP = r2 * (dp * dp)[:, None] + r1 * ddp[:, None]
    return s, ds, dds, p, dp, ddp, r, dP, ddP


def sample_trajectory(robot: FiveBar, path: Path, law: Law, *, mode: str = "+-",
                      samples: int = 1001, times: Array | None = None,
                      tolerances: Tolerances = DEFAULT_TOLERANCES,
                      units: Units | None = None, checked: bool = True,
                      crossings: Sequence[Crossing] = (), at_arc_length: bool = False
                      ) -> Trajectory:
    """Sample ``law`` along ``path`` and map it to joint space in working mode ``mode``.

    Parameters
    ----------
    robot : FiveBar
    path : Path
    law : Law
        Covers the path's length.
    mode : str
        Working mode (name or alias).
    samples : int
        Number of samples on a uniform grid including ``t = 0`` and ``t = T``.
    times : ndarray, optional
        Explicit sample times (overrides ``samples``).
    tolerances : Tolerances
        The geometry checker's tolerances on the way.
    units : Units, optional
        The run's units, only to state points in mm and times in seconds in an error.
    checked : bool
        Run the geometry checker on the samples (False only for re-sampling a path that was
        checked already, as the time-optimal law's output check does).
    crossings : sequence of Crossing
        The path's crossings of the parallel singularity curve that the motion may make
        (:func:`find_crossings`); the checker refuses any other.
    at_arc_length : bool
        The law is at unit speed (its times are arc lengths, as a path's dynamics samples
        it): an error names the place by its arc length, not by a time.

    Returns
    -------
    Trajectory

    Raises
    ------
    ReachError
        The path leaves the workspace; names the first time and point.
    SingularityError
        The path meets a singularity for this working mode; names the first time and point.
    """
    mode = working_mode_name(parse_working_mode(mode))
    if not abs(law.distance - path.length) <= 1e-9 * abs(path.length):
        raise ParameterError(f"the law covers a distance of {law.distance:.9g} but the path is "
                             f"{path.length:.9g} long")
    t = law.times(samples) if times is None else np.asarray(times, dtype=float)
    s, ds, dds, p, dp, ddp, P, dP, ddP = path_motion(path, law, t)
    words = _Words(units)

    def where(i: int) -> str:
        return words.arc(t[i]) if at_arc_length else f"at {words.time(t[i])} (sample {i})"

    if checked:
        check_reach(robot, P, lambda i: f"the path leaves the workspace {where(i)}",
                    words.point, words.length)
    q = inverse_kinematics(robot, P, mode, unwrap=True)
    crossings = tuple(crossings)
    if checked:
        check_poses(robot, q, P, tolerances=tolerances, where=where, point=words.point,
                    mode=mode, excused=crossing_excused(crossings, s, tolerances)
                    if crossings else None)
    dq, ddq = joint_rates(robot, q, P, dP, ddP, tol=0.0)
    if crossings:
        start = crossings[0].assembly_before
    else:
        start = assembly_mode_name(int(assembly_mode(robot, q[:1], P[:1])[0]))  # the first pose's
    return Trajectory(robot, path, law, mode, start, t, s, ds, dds, p, dp, ddp, P, dP, ddP, q,
                      dq, ddq, crossings)


@dataclass(frozen=True)
class CheckedPath:
    """The poses at which :func:`check_path` checked a path.

    Attributes
    ----------
    p : ndarray, shape (n,)
        Path parameters, equally spaced from start to end.
    P, q : ndarray, shape (n, 2)
        Points and actuator angles (unwrapped along the path, from the principal angles at
        its start).
    distances : PoseDistances
        Normalised distances to both singularity types, (n,) each.
    """

    p: Array
    P: Array
    q: Array
    distances: PoseDistances


def check_path(robot: FiveBar, path: Path, *, mode: str = "+-", samples: int = 2001,
               tolerances: Tolerances = DEFAULT_TOLERANCES,
               units: Units | None = None, crossings: Sequence[Crossing] = ()) -> CheckedPath:
    """Check a path before any law is planned on it: ``samples`` points equally spaced in the
    path parameter, within reach and clear of both singularity types in working mode ``mode``
    (the geometry checker), but for the ``crossings`` of the parallel singularity curve
    given (:func:`find_crossings`). Errors name the path parameter and the point (in mm with
    ``units``).

    Returns
    -------
    CheckedPath
        The poses checked, with their distances to the singularities: a law along the path
        passes the same poses, whatever its timing.

    Raises
    ------
    ReachError, SingularityError
    """
    mode = working_mode_name(parse_working_mode(mode))
    p = np.linspace(path.p0, path.p1, samples)
    P = path.position(p)
    words = _Words(units)
    check_reach(robot, P, lambda i: "the path leaves the workspace "
                + words.along(path, p[i]), words.point, words.length)
    q = inverse_kinematics(robot, P, mode, unwrap=True)
    excused = (crossing_excused(tuple(crossings), path.arc_length(p), tolerances)
               if crossings else None)
    d = check_poses(robot, q, P, tolerances=tolerances, where=lambda i: words.along(path, p[i]),
                    point=words.point, mode=mode, excused=excused)
    return CheckedPath(p, P, q, d)


#: A crossing of the parallel singularity curve must be transversal: the normalised distance
#: ``det A / (L1 L2)`` must change at least this fast per unit of the robot's reach
#: ``max(l1 + L1, l2 + L2)`` along the path (the lines across the DexTAR's curve change by
#: 2-4 per reach; a path that grazes the curve changes at 0 there and is refused: its torques
#: would need a degeneracy condition of higher order).
MIN_CROSSING_SLOPE = 0.05


@dataclass(frozen=True)
class Crossing:
    """Where a path crosses the parallel (type 2) singularity curve of a working mode.

    Attributes
    ----------
    p, s : float
        Path parameter and arc length of the crossing.
    P, q : ndarray, shape (2,)
        The end-effector and the motor angles there (B, C and P aligned).
    normal : ndarray, shape (2,)
        The unit normal to the aligned distal rods: the direction along which the motors
        cannot push the end-effector at the crossing (the degeneracy condition asks the
        end-effector's force to have no component along it).
    slope : float
        ``d(det A / (L1 L2)) / ds`` there (per unit length), nonzero: a transversal crossing.
    assembly_before, assembly_after : str
        The assembly modes on either side.
    """

    p: float
    s: float
    P: Array
    q: Array
    normal: Array
    slope: float
    assembly_before: str
    assembly_after: str

    def window(self, distance: float) -> float:
        """The arc length on either side within which the normalised distance to the
        singularity is below ``distance`` (to first order)."""
        return float(distance / abs(self.slope))


def find_crossings(robot: FiveBar, path: Path, *, mode: str = "+-", samples: int = 2001,
                   units: Units | None = None) -> tuple[Crossing, ...]:
    """The path's crossings of the parallel singularity curve in working mode ``mode``: the
    sign changes of ``det A`` on ``samples`` points equally spaced in the path parameter,
    each refined by bisection to rounding.

    Raises
    ------
    ReachError
        The path leaves the workspace.
    SingularityError
        A crossing that is not transversal (:data:`MIN_CROSSING_SLOPE`).
    """
    mode = working_mode_name(parse_working_mode(mode))
    words = _Words(units)
    p = np.linspace(path.p0, path.p1, samples)
    P = path.position(p)
    check_reach(robot, P, lambda i: "the path leaves the workspace "
                + words.along(path, p[i]), words.point, words.length)

    def indicator(pp: Array) -> Array:
        PP = path.position(pp)
        return parallel_indicator(robot, inverse_kinematics(robot, PP, mode), PP)

    sig = indicator(p)
    sg = np.sign(sig)
    # a sign change between samples i and i + 1 (an exact zero counts with its right side)
    idx = np.flatnonzero((sg[:-1] != sg[1:]) & (sg[:-1] != 0))
    idx = np.array([i for i in idx if not (sg[i + 1] == 0 and i + 2 < samples
                                            and sg[i + 2] == sg[i])], dtype=int)
    if idx.size == 0:
        return ()
    lo, hi = p[idx].copy(), p[idx + 1].copy()
    flo = sig[idx].copy()
    for _ in range(80):  # bisection: the bracket halves to rounding
        mid = 0.5 * (lo + hi)
        fm = indicator(mid)
        left = np.sign(fm) == np.sign(flo)
        lo, flo = np.where(left, mid, lo), np.where(left, fm, flo)
        hi = np.where(left, hi, mid)
    ps = 0.5 * (lo + hi)
    reach = max(robot.l1 + robot.L1, robot.l2 + robot.L2)
    span = path.p1 - path.p0
    out = []
    for k, pk in enumerate(ps):
        delta = 1e-5 * span
        a, b = max(pk - delta, path.p0), min(pk + delta, path.p1)
        fa, fb = indicator(np.array([a, b]))
        slope = float((fb - fa) / (float(path.arc_length(b)) - float(path.arc_length(a))))
        Pk = path.position(np.array([pk]))[0]
        qk = inverse_kinematics(robot, Pk, mode)
        if not abs(slope) * reach >= MIN_CROSSING_SLOPE:
            raise SingularityError(
                f"{words.along(path, pk)}: the path meets the parallel (type 2) singularity "
                f"curve at P = {words.point(Pk)} in working mode {mode} without crossing it "
                f"transversally (the normalised distance changes by {abs(slope) * reach:.3g} "
                f"per reach, below {MIN_CROSSING_SLOPE:g}): no motion passes it with bounded "
                "torques")
        B, _ = elbows(robot, qk)
        u = Pk - B
        normal = np.array([-u[1], u[0]]) / float(np.hypot(u[0], u[1]))
        before = -int(np.sign(sig[idx[k]]))  # assembly sign = -sign(det A)
        out.append(Crossing(float(pk), float(path.arc_length(pk)), Pk, qk, normal, slope,
                            assembly_mode_name(before), assembly_mode_name(-before)))
    return tuple(out)


def crossing_excused(crossings: Sequence[Crossing], s: Array,
                     tolerances: Tolerances = DEFAULT_TOLERANCES) -> Array:
    """The samples at arc lengths ``s`` (n,) (increasing) whose parallel-singularity checks
    a planned crossing excuses: within four times the checker's tolerance of the crossing
    (to first order in its slope), and the sample just past it (the sign change)."""
    s = np.asarray(s, float)
    out = np.zeros(s.shape, bool)
    for c in crossings:
        out |= np.abs(s - c.s) <= 4.0 * c.window(max(tolerances.type2, 1e-12))
        k = int(np.searchsorted(s, c.s, side="left"))
        out[min(k, len(s) - 1)] = True
        if k > 0:
            out[k - 1] = True
    return out


@dataclass(frozen=True)
class _Words:
    """Times, points and lengths in the user's words (mm and s with units, else run units)."""

    units: Units | None

    def time(self, t: float) -> str:
        return f"t = {t:.6g}" if self.units is None else self.units.time_text(t)

    def point(self, P: Array) -> str:
        return f"({P[0]:.6g}, {P[1]:.6g})" if self.units is None else self.units.point_text(P)

    def length(self, x: float) -> str:
        return f"{x:.6g}" if self.units is None else f"{self.units.mm(x):.6g} mm"

    def along(self, path: Path, p: float) -> str:
        """Where the parameter ``p`` is on ``path``: at its arc length from the path's start
        in mm (a blended chain's from the start of its first move; at the parameter itself in
        run units)."""
        if self.units is None:
            return f"at p = {p:.6g}"
        return self.arc(float(path.arc_length(np.array([p]))[0]))

    def arc(self, s: float) -> str:
        """Where the arc length ``s`` is along a path, from its start."""
        if self.units is None:
            return f"at s = {s:.6g} along the path"
        return f"at {self.units.mm(s):.6g} mm along the path (from the start of the motion)"


@dataclass(frozen=True)
class JointLine:
    """A straight line in joint space from ``q0`` to ``q1`` (each (2,), rad), parametrised by
    its length ``s`` in radians: ``q(s) = q0 + s u``, ``u = (q1 - q0) / |q1 - q0|``."""

    q0: tuple[float, float]
    q1: tuple[float, float]

    def __post_init__(self) -> None:
        a, b = np.asarray(self.q0, float), np.asarray(self.q1, float)
        if a.shape != (2,) or b.shape != (2,) or not (np.isfinite(a).all() and
                                                      np.isfinite(b).all()):
            raise ParameterError("a joint line needs two finite joint positions (phi, psi)")
        if np.allclose(a, b, rtol=0.0, atol=1e-12):
            raise ParameterError("a joint line needs two different joint positions")

    @property
    def length(self) -> float:
        """``|q1 - q0|`` (rad)."""
        return float(np.hypot(self.q1[0] - self.q0[0], self.q1[1] - self.q0[1]))

    @property
    def direction(self) -> Array:
        """The unit direction ``u``, shape (2,)."""
        return np.asarray((np.asarray(self.q1, float) - np.asarray(self.q0, float)) / self.length)

    def at(self, s: Array) -> Array:
        """Joint positions at lengths ``s`` (n,), shape (n, 2)."""
        return np.asarray(np.asarray(self.q0, float) + np.asarray(s, float)[:, None]
                          * self.direction)


def sample_joint_trajectory(robot: FiveBar, line: JointLine, law: Law, *, assembly: str = "up",
                            times: Array | None = None, samples: int = 1001,
                            tolerances: Tolerances = DEFAULT_TOLERANCES,
                            units: Units | None = None) -> Trajectory:
    """Sample ``law`` along a joint-space line (a joint move: it may cross serial
    singularities, which is how the working mode changes; it must not come near or cross a
    parallel one, nor change assembly mode).

    Raises
    ------
    SingularityError
        The line meets a parallel singularity; names the time and the joint angles.
    """
    if not abs(law.distance - line.length) <= 1e-9 * abs(line.length):
        raise ParameterError(f"the law covers {law.distance:.9g} but the joint line is "
                             f"{line.length:.9g} rad long")
    t = law.times(samples) if times is None else np.asarray(times, dtype=float)
    s, ds, dds, _ = law.evaluate(t)
    u = line.direction
    q = line.at(s)
    dq, ddq = ds[:, None] * u, dds[:, None] * u
    words = _Words(units)
    sigma = parse_assembly_mode(assembly)

    def where(i: int) -> str:
        return (f"at {words.time(t[i])} (sample {i}), q = ({np.degrees(q[i, 0]):.6g}, "
                f"{np.degrees(q[i, 1]):.6g}) deg")

    B, C = elbows(robot, q)
    gap = np.linalg.norm(B - C, axis=-1)
    bad = (gap > robot.L1 + robot.L2) | (gap < abs(robot.L1 - robot.L2))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise SingularityError(f"{where(i)}: the joint line crosses a parallel (type 2) "
                               f"singularity: the distal rods stretch into line and cannot meet "
                               f"beyond it (|B - C| = {words.length(gap[i])}); with the assembly "
                               "mode fixed, joint space ends there")
    try:
        P = direct_kinematics(robot, q, sigma)
    except AssemblyError as exc:
        raise SingularityError(f"the joint line leaves the assembly: {exc}") from None

    check_poses(robot, q, P, tolerances=tolerances, type1=False, where=where, point=words.point)
    dP, ddP = task_acceleration(robot, q, P, dq, ddq, tol=0.0)
    m = working_mode(robot, q[:1], P[:1])[0]  # at the start (the move may change it)
    mode = working_mode_name((int(m[0]), int(m[1])))
    return Trajectory(robot, line, law, mode, assembly_mode_name(sigma), t, s, ds, dds, s, ds,
                      dds, P, dP, ddP, q, dq, ddq)
