"""First- and second-order kinematics: ``A(q, P) Pdot = B(q, P) qdot`` and its derivative.

Differentiating the closure ``|P - B|^2 = L1^2`` (and the same for leg 2) gives

* rows of ``A``: ``(P - B)^T`` and ``(P - C)^T``;
* ``B = diag((B - A) x (P - B), (C - D) x (P - C))``.

``det B = 0`` is a serial (type 1) singularity (a leg stretched or folded), ``det A = 0`` a
parallel (type 2) singularity (B, C, P aligned). The normalised distances are the sines of the
angles at the elbows (type 1, the smaller of the two legs) and at P (type 2), in ``[0, 1]``.

Differentiating once more: ``A Pddot - B qddot = b`` with, for leg 1,
``b_1 = -|Pdot - Bdot|^2 - l1 phidot^2 (P - B) . e(phi)`` (``e(phi) = (cos phi, sin phi)``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import Array, as_points, cos_sin, first_index, where
from ..errors import SingularityError
from ..geometry import FiveBar
from .checker import DEFAULT_TOLERANCES

#: Default tolerance on the normalised distances to a singularity (sine of the angle): the
#: geometry checker's, so every stage refuses the same points.
DEFAULT_SINGULARITY_TOL = DEFAULT_TOLERANCES.type2


@dataclass(frozen=True)
class _Frame:
    """Component arrays shared by the first- and second-order relations."""

    c1: Array
    s1: Array
    c2: Array
    s2: Array
    ux: Array  # P - B
    uy: Array
    vx: Array  # P - C
    vy: Array
    b1: Array  # (B - A) x (P - B)
    b2: Array  # (C - D) x (P - C)
    det: Array  # det A = (P - B) x (P - C)


def _frame(robot: FiveBar, q: object, points: object) -> _Frame:
    q = as_points(q, "q")
    P = as_points(points, "points")
    c1, s1 = cos_sin(q[..., 0])
    c2, s2 = cos_sin(q[..., 1])
    half = 0.5 * robot.d
    ux = P[..., 0] - (half + robot.l1 * c1)
    uy = P[..., 1] - robot.l1 * s1
    vx = P[..., 0] - (-half + robot.l2 * c2)
    vy = P[..., 1] - robot.l2 * s2
    b1 = robot.l1 * (c1 * uy - s1 * ux)
    b2 = robot.l2 * (c2 * vy - s2 * vx)
    det = ux * vy - uy * vx
    return _Frame(c1, s1, c2, s2, ux, uy, vx, vy, b1, b2, det)


def velocity_matrices(robot: FiveBar, q: object, points: object) -> tuple[Array, Array]:
    """The matrices ``A`` and ``B`` of ``A Pdot = B qdot``.

    Parameters
    ----------
    q : array_like, shape (..., 2)
        Actuator angles ``(phi, psi)``.
    points : array_like, shape (..., 2)
        End-effector positions matching ``q`` (from direct or inverse kinematics).

    Returns
    -------
    A, B : ndarray, shape (..., 2, 2)
    """
    f = _frame(robot, q, points)
    A = np.stack([np.stack([f.ux, f.uy], -1), np.stack([f.vx, f.vy], -1)], -2)
    zero = np.zeros_like(f.b1)
    B = np.stack([np.stack([f.b1, zero], -1), np.stack([zero, f.b2], -1)], -2)
    return A, B


def singularity_distances(
    robot: FiveBar, q: object, points: object
) -> tuple[Array, Array]:
    """Normalised distances to a serial (type 1) and a parallel (type 2) singularity.

    Returns
    -------
    type1, type2 : ndarray, shape (...,)
        ``min(|b1| / (l1 L1), |b2| / (l2 L2))`` and ``|det A| / (L1 L2)``, both in ``[0, 1]``;
        zero at the singularity.
    """
    f = _frame(robot, q, points)
    return _type1(robot, f), np.abs(f.det) / (robot.L1 * robot.L2)


def parallel_indicator(robot: FiveBar, q: object, points: object) -> Array:
    """Signed ``det A / (L1 L2)``, shape (...,): its sign flips across a parallel singularity,
    so a change of sign between two samples of a motion reveals a crossing between them."""
    return _frame(robot, q, points).det / (robot.L1 * robot.L2)


def _type1(robot: FiveBar, f: _Frame) -> Array:
    return np.minimum(np.abs(f.b1) / (robot.l1 * robot.L1), np.abs(f.b2) / (robot.l2 * robot.L2))


def _raise_if_near(
    kind: int, dist: Array, tol: float, q: object, points: object, context: str = ""
) -> None:
    bad = dist < tol
    if not bad.any():
        return
    idx = first_index(bad)
    qa, Pa = np.asarray(q, float), np.asarray(points, float)
    qq = qa[idx] if qa.ndim > 1 else qa
    pp = Pa[idx] if Pa.ndim > 1 else Pa
    name = (
        "serial (type 1): a leg stretched or folded"
        if kind == 1
        else "parallel (type 2): B, C and P aligned"
    )
    raise SingularityError(
        f"{name} singularity{context or where(idx, dist.shape)}: "
        f"q = ({np.degrees(qq[0]):.6g}, {np.degrees(qq[1]):.6g}) deg, "
        f"P = ({pp[0]:.6g}, {pp[1]:.6g}), normalised distance {float(np.asarray(dist)[idx] if np.ndim(dist) else dist):.3g} "
        f"below tolerance {tol:g}"
    )


def check_singularities(
    robot: FiveBar,
    q: object,
    points: object,
    *,
    tol: float = DEFAULT_SINGULARITY_TOL,
    type1: bool = True,
    type2: bool = True,
) -> None:
    """Raise :class:`SingularityError` for the first sample within ``tol`` of a singularity."""
    f = _frame(robot, q, points)
    if type1:
        _raise_if_near(1, _type1(robot, f), tol, q, points)
    if type2:
        _raise_if_near(2, np.abs(f.det) / (robot.L1 * robot.L2), tol, q, points)


def jacobian(
    robot: FiveBar, q: object, points: object, *, tol: float = DEFAULT_SINGULARITY_TOL
) -> Array:
    """``J = A^-1 B`` (shape (..., 2, 2)): ``Pdot = J qdot``.

    Raises :class:`SingularityError` within ``tol`` of a parallel singularity.
    """
    f = _frame(robot, q, points)
    _raise_if_near(2, np.abs(f.det) / (robot.L1 * robot.L2), tol, q, points)
    inv = 1.0 / f.det
    # A^-1 = [[vy, -uy], [-vx, ux]] / det ; J = A^-1 diag(b1, b2)
    J = np.empty(f.det.shape + (2, 2))
    J[..., 0, 0] = f.vy * f.b1 * inv
    J[..., 0, 1] = -f.uy * f.b2 * inv
    J[..., 1, 0] = -f.vx * f.b1 * inv
    J[..., 1, 1] = f.ux * f.b2 * inv
    return J


def _solve_A(f: _Frame, rx: Array, ry: Array) -> Array:
    inv = 1.0 / f.det
    return np.stack([(f.vy * rx - f.uy * ry) * inv, (f.ux * ry - f.vx * rx) * inv], axis=-1)


def task_velocity(
    robot: FiveBar, q: object, points: object, dq: object, *, tol: float = DEFAULT_SINGULARITY_TOL
) -> Array:
    """End-effector velocity ``Pdot`` (..., 2) from actuator rates ``dq`` (..., 2)."""
    f = _frame(robot, q, points)
    _raise_if_near(2, np.abs(f.det) / (robot.L1 * robot.L2), tol, q, points)
    dq = as_points(dq, "dq")
    return _solve_A(f, f.b1 * dq[..., 0], f.b2 * dq[..., 1])


def joint_velocity(
    robot: FiveBar,
    q: object,
    points: object,
    dpoints: object,
    *,
    tol: float = DEFAULT_SINGULARITY_TOL,
) -> Array:
    """Actuator rates ``qdot`` (..., 2) from end-effector velocity ``dpoints`` (..., 2).

    Raises :class:`SingularityError` within ``tol`` of a serial singularity.
    """
    f = _frame(robot, q, points)
    _check_type1(robot, f, tol, q, points)
    return _rates(f, as_points(dpoints, "dpoints"))


def joint_acceleration(
    robot: FiveBar,
    q: object,
    points: object,
    dq: object,
    dpoints: object,
    ddpoints: object,
    *,
    tol: float = DEFAULT_SINGULARITY_TOL,
) -> Array:
    """Actuator accelerations ``qddot = B^-1 (A Pddot - b)``, shape (..., 2)."""
    f = _frame(robot, q, points)
    _check_type1(robot, f, tol, q, points)
    dq, dP, ddP = (
        as_points(dq, "dq"),
        as_points(dpoints, "dpoints"),
        as_points(ddpoints, "ddpoints"),
    )
    return _accelerations(robot, f, dq, dP, ddP)


def joint_rates(
    robot: FiveBar,
    q: object,
    points: object,
    dpoints: object,
    ddpoints: object,
    *,
    tol: float = DEFAULT_SINGULARITY_TOL,
) -> tuple[Array, Array]:
    """Actuator rates and accelerations ``(qdot, qddot)`` (..., 2) from the end-effector's
    velocity and acceleration: :func:`joint_velocity` and :func:`joint_acceleration` on one
    set of kinematic quantities (the same numbers, computed once)."""
    f = _frame(robot, q, points)
    _check_type1(robot, f, tol, q, points)
    dP, ddP = as_points(dpoints, "dpoints"), as_points(ddpoints, "ddpoints")
    dq = _rates(f, dP)
    return dq, _accelerations(robot, f, dq, dP, ddP)


def _check_type1(robot: FiveBar, f: _Frame, tol: float, q: object, points: object) -> None:
    if tol > 0:  # (a distance is never below a tolerance of zero)
        _raise_if_near(1, _type1(robot, f), tol, q, points)


def _rates(f: _Frame, dP: Array) -> Array:
    """``qdot = B^-1 A Pdot``."""
    return np.stack(
        [
            (f.ux * dP[..., 0] + f.uy * dP[..., 1]) / f.b1,
            (f.vx * dP[..., 0] + f.vy * dP[..., 1]) / f.b2,
        ],
        axis=-1,
    )


def _bias(
    robot: FiveBar, f: _Frame, dq: Array, dP: Array
) -> tuple[Array, Array]:
    """The velocity-product term ``b`` of ``A Pddot - B qddot = b``."""
    w1, w2 = dq[..., 0], dq[..., 1]
    # Pdot - Bdot, Bdot = l1 w1 (-s1, c1)
    ex1 = dP[..., 0] + robot.l1 * w1 * f.s1
    ey1 = dP[..., 1] - robot.l1 * w1 * f.c1
    ex2 = dP[..., 0] + robot.l2 * w2 * f.s2
    ey2 = dP[..., 1] - robot.l2 * w2 * f.c2
    bias1 = -(ex1 * ex1 + ey1 * ey1) - robot.l1 * w1 * w1 * (f.ux * f.c1 + f.uy * f.s1)
    bias2 = -(ex2 * ex2 + ey2 * ey2) - robot.l2 * w2 * w2 * (f.vx * f.c2 + f.vy * f.s2)
    return bias1, bias2


def _accelerations(robot: FiveBar, f: _Frame, dq: Array, dP: Array, ddP: Array) -> Array:
    """``qddot = B^-1 (A Pddot - b)``."""
    bias1, bias2 = _bias(robot, f, dq, dP)
    return np.stack(
        [
            (f.ux * ddP[..., 0] + f.uy * ddP[..., 1] - bias1) / f.b1,
            (f.vx * ddP[..., 0] + f.vy * ddP[..., 1] - bias2) / f.b2,
        ],
        axis=-1,
    )


def task_acceleration(
    robot: FiveBar,
    q: object,
    points: object,
    dq: object,
    ddq: object,
    *,
    tol: float = DEFAULT_SINGULARITY_TOL,
) -> tuple[Array, Array]:
    """End-effector velocity and acceleration ``(Pdot, Pddot)`` from ``q, qdot, qddot``.

    ``Pddot = A^-1 (B qddot + b)``; both arrays of shape (..., 2).
    """
    f = _frame(robot, q, points)
    _raise_if_near(2, np.abs(f.det) / (robot.L1 * robot.L2), tol, q, points)
    dq, ddq = as_points(dq, "dq"), as_points(ddq, "ddq")
    dP = _solve_A(f, f.b1 * dq[..., 0], f.b2 * dq[..., 1])
    bias1, bias2 = _bias(robot, f, dq, dP)
    ddP = _solve_A(f, f.b1 * ddq[..., 0] + bias1, f.b2 * ddq[..., 1] + bias2)
    return dP, ddP
