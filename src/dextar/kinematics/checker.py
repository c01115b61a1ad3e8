"""The one geometry checker: reach, distance to both singularity types, crossings and joint
limits, with every tolerance named in one place (:class:`Tolerances`).

Inverse kinematics, trajectories, paths, the workspace map and everything built on them call
:func:`check_poses`, so a point passes or fails the same way wherever it is checked.

Distances are normalised: type 1 (serial) is the smaller sine of the angle at an elbow,
``|(B - A) x (P - B)| / (l L)``; type 2 (parallel) is the sine of the angle at P,
``|(P - B) x (P - C)| / (L1 L2)``. Both are 0 at the singularity and at most 1.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from ..errors import ParameterError, ReachError, SingularityError
from ..geometry import FiveBar

#: Relative slack on the reach annulus, for points on its boundary up to rounding.
REACH_SLACK = 1e-12


@dataclass(frozen=True)
class Tolerances:
    """Tolerances of the geometry checker (normalised distances, in [0, 1]).

    Attributes
    ----------
    type1 : float
        Smallest distance to a serial singularity (a leg stretched or folded) accepted.
    type2 : float
        Smallest distance to a parallel singularity (B, C, P aligned) accepted.
    """

    type1: float = 1e-3
    type2: float = 1e-3

    def __post_init__(self) -> None:
        for name in ("type1", "type2"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and 0.0 <= v <= 1.0):
                raise ParameterError(f"tolerance {name} = {v!r} must be in [0, 1]")


#: The tolerances used when none are given.
DEFAULT_TOLERANCES = Tolerances()


@dataclass(frozen=True)
class PoseDistances:
    """Normalised distances of poses to the singularities, arrays of shape (n,).

    ``type2_signed`` changes sign across a parallel singularity, so a change between two
    samples of a motion reveals a crossing between them.
    """

    type1: Array
    type2: Array
    type2_signed: Array


def reach_violation(robot: FiveBar, P: Array) -> tuple[Array, Array]:
    """How far each point (n, 2) is out of reach of each leg (n, 2), 0 when within reach
    (up to :data:`REACH_SLACK` of the leg's reach), and ``|P - pivot|`` (n, 2)."""
    out = np.zeros(P.shape)
    rho = np.empty(P.shape)
    for k, pivot in enumerate((robot.A, robot.D)):
        rin, rout = robot.reach(k + 1)
        r = np.hypot(P[:, 0] - pivot[0], P[:, 1] - pivot[1])
        rho[:, k] = r
        slack = REACH_SLACK * rout
        out[:, k] = np.where(np.isfinite(r), np.maximum(np.maximum(rin - r, r - rout) - slack,
                                                        0.0), np.inf)
    return out, rho


def pose_distances(robot: FiveBar, q: Array, P: Array) -> PoseDistances:
    """Normalised distances of the poses ``(q, P)`` (each (n, 2)) to both singularities."""
    c1, s1 = np.cos(q[:, 0]), np.sin(q[:, 0])
    c2, s2 = np.cos(q[:, 1]), np.sin(q[:, 1])
    half = 0.5 * robot.d
    ux, uy = P[:, 0] - (half + robot.l1 * c1), P[:, 1] - robot.l1 * s1
    vx, vy = P[:, 0] - (-half + robot.l2 * c2), P[:, 1] - robot.l2 * s2
    b1 = np.abs(robot.l1 * (c1 * uy - s1 * ux)) / (robot.l1 * robot.L1)
    b2 = np.abs(robot.l2 * (c2 * vy - s2 * vx)) / (robot.l2 * robot.L2)
    det = (ux * vy - uy * vx) / (robot.L1 * robot.L2)
    return PoseDistances(np.minimum(b1, b2), np.abs(det), det)


def not_a_number(P: Array) -> str:
    """Why a point that is not finite is no point: ``"is not a number (x is NaN)"``."""
    bad = [f"{c} is {'NaN' if np.isnan(v) else 'infinite'}"
           for c, v in zip("xy", np.asarray(P, float), strict=False) if not np.isfinite(v)]
    return f"is not a number ({' and '.join(bad)})"


def check_reach(robot: FiveBar, P: Array, where: Callable[[int], str],
                point: Callable[[Array], str], length: Callable[[float], str]) -> None:
    """Raise :class:`ReachError` for the first point (n, 2) out of reach of a leg.

    ``where(i)`` names the sample (a time, a path parameter, an index), ``point(P)`` and
    ``length(x)`` put a point and a distance in the user's words.
    """
    finite = np.isfinite(P).all(axis=-1)
    if not finite.all():
        i = int(np.flatnonzero(~finite)[0])
        raise ReachError(f"{where(i)}: point {point(P[i])} {not_a_number(P[i])}")
    out, rho = reach_violation(robot, P)
    bad = out > 0
    if bad.any():
        i, leg = (int(v) for v in np.argwhere(bad)[0])
        rin, rout = robot.reach(leg + 1)
        raise ReachError(f"{where(i)}: point {point(P[i])} is out of reach of leg {leg + 1} by "
                         f"{length(float(out[i, leg]))} (|P - {'AD'[leg]}| = "
                         f"{length(float(rho[i, leg]))}, reach {length(rin)} to "
                         f"{length(rout)})")


def check_poses(robot: FiveBar, q: Array, P: Array, *,
                tolerances: Tolerances = DEFAULT_TOLERANCES, type1: bool = True,
                type2: bool = True, crossings: bool = True,
                joint_limits: Array | None = None, where: Callable[[int], str],
                point: Callable[[Array], str], mode: str = "",
                excused: Array | None = None) -> PoseDistances:
    """Check a sequence of poses ``(q, P)`` (each (n, 2)) and return their distances.

    Raises :class:`SingularityError` for the first pose within the tolerance of a singularity
    (or, with ``crossings``, a parallel singularity crossed between two samples) and
    :class:`ReachError` for a joint outside ``joint_limits`` ((2, 2) rows ``[min, max]`` in
    rad). ``where(i)`` and ``point(P)`` word the sample and the point. ``excused`` (n,) marks
    the samples whose parallel-singularity checks are skipped: those at a planned crossing
    of the parallel singularity curve (:func:`dextar.trajectory.find_crossings`), which the
    law makes under the degeneracy condition.
    """
    d = pose_distances(robot, q, P)
    in_mode = f" in working mode {mode}" if mode else ""
    checks = []
    if type1:
        checks.append((1, d.type1 < tolerances.type1, d.type1, tolerances.type1))
    if type2:
        crossed = np.zeros(len(P), bool)
        if crossings and len(P) > 1:
            s = np.sign(d.type2_signed)
            crossed[1:] = s[1:] != s[:-1]
        bad2 = (d.type2 < tolerances.type2) | crossed
        if excused is not None:
            bad2 &= ~np.asarray(excused, bool)
        checks.append((2, bad2, d.type2, tolerances.type2))
    first = [(int(np.flatnonzero(bad)[0]), kind, dist, tol) for kind, bad, dist, tol in checks
             if bad.any()]
    if first:
        i, kind, dist, tol = min(first)
        what = ("serial (type 1) singularity: a leg stretched or folded" if kind == 1
                else "parallel (type 2) singularity: B, C and P aligned")
        why = (f"normalised distance {dist[i]:.3g} below {tol:g}" if dist[i] < tol
               else "crossed since the previous sample")
        raise SingularityError(f"{where(i)}: the motion meets a {what}{in_mode}: P = "
                               f"{point(P[i])}, q = ({np.degrees(q[i, 0]):.6g}, "
                               f"{np.degrees(q[i, 1]):.6g}) deg, {why}")
    if joint_limits is not None:
        lim = np.asarray(joint_limits, float)
        bad = (q < lim[:, 0]) | (q > lim[:, 1])
        if bad.any():
            i, k = (int(v) for v in np.argwhere(bad)[0])
            name = ("phi", "psi")[k]
            raise ReachError(f"{where(i)}: joint {name} = {np.degrees(q[i, k]):.6g} deg is "
                             f"outside its limits [{np.degrees(lim[k, 0]):.6g}, "
                             f"{np.degrees(lim[k, 1]):.6g}] deg at P = {point(P[i])}")
    return d
