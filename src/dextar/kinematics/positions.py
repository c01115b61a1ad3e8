"""Inverse and direct position kinematics of the five-bar, vectorised over samples.

Both solve a circle-circle intersection in the form that needs one square root and no
division by a distance: for a leg with pivot ``O``, proximal length ``l`` and distal length
``L``, and ``u = P - O``, ``k = (l^2 - L^2 + |u|^2) / 2`` and ``w = sqrt(l^2 |u|^2 - k^2)``;
the elbow is ``O + (k u - s w perp(u)) / |u|^2`` where ``s`` is the leg's working-mode sign.
Angles come from ``atan2``, which ignores the common positive factor ``1 / |u|^2``.
Large inputs are processed in cache-sized blocks.
"""

from __future__ import annotations

import numpy as np

from .._arrays import Array, as_points, blocks, cos_sin, cross, flat_index, where
from ..errors import AssemblyError, ReachError
from ..geometry import FiveBar, parse_assembly_mode, parse_working_mode
from .checker import not_a_number


def _leg_solve(
    ux: Array, uy: Array, l: float, L: float, sign: int
) -> tuple[Array, Array, Array]:
    """Angle of the proximal rod of one leg, the squared distance to the pivot and the mask of
    points out of reach (where the angle is meaningless but finite)."""
    rho2 = ux * ux + uy * uy
    k = 0.5 * (rho2 + (l * l - L * L))
    w2 = (l * l) * rho2 - k * k
    # rounding may leave w2 a hair below zero on the boundary (leg stretched): allow it
    # "not >=" is also true for NaN: a point so far that its squares overflow is out of reach
    bad = ~(w2 >= -1e-12 * (l * l) * rho2) | (rho2 <= 1e-24 * (l + L) ** 2)
    w = np.sqrt(np.maximum(w2, 0.0))
    if sign > 0:  # s = +1: elbow to the right of pivot->P, so the perp term enters negated
        w = -w
    # elbow direction (unnormalised): k u + w perp(u), perp(u) = (-uy, ux)
    return np.arctan2(k * uy + w * ux, k * ux - w * uy), rho2, bad


def _reach_error(
    P: Array, shape: tuple[int, ...], i: int, rho2: float, l: float, L: float, leg: int
) -> ReachError:
    if not np.isfinite(P[i]).all():
        return ReachError(f"point ({P[i, 0]:.6g}, {P[i, 1]:.6g})"
                          f"{where(flat_index(i, shape), shape)} {not_a_number(P[i])}")
    rho = float(np.sqrt(rho2))
    rin, rout = abs(l - L), l + L
    out = max(rin - rho, rho - rout, 0.0)
    pivot = "A" if leg == 1 else "D"
    return ReachError(
        f"point ({P[i, 0]:.6g}, {P[i, 1]:.6g}){where(flat_index(i, shape), shape)} is out of "
        f"reach of leg {leg}: |P - {pivot}| = {rho:.6g}, reachable range [{rin:.6g}, "
        f"{rout:.6g}], out by {out:.6g}"
    )


def inverse_kinematics(
    robot: FiveBar, points: object, mode: str | tuple[int, int] = "+-", *, unwrap: bool = False
) -> Array:
    """Actuator angles ``(phi, psi)`` that place the end-effector at ``points``.

    Parameters
    ----------
    robot : FiveBar
    points : array_like, shape (..., 2)
        End-effector positions ``(x, y)`` in the robot's length unit.
    mode : {"++", "+-", "-+", "--"} or (int, int)
        Working mode, signs of ``(B - A) x (P - B)`` and ``(C - D) x (P - C)``.
    unwrap : bool
        Unwrap the angles along axis 0 (a sequence of points) instead of returning them in
        ``(-pi, pi]``.

    Returns
    -------
    q : ndarray, shape (..., 2)
        ``(phi, psi)`` in radians.

    Raises
    ------
    ReachError
        A point out of reach of a leg; the message names the first such point, its index, the
        leg and how far out of reach it is.
    """
    P0 = as_points(points, "points")
    shape = P0.shape[:-1]
    P = P0.reshape(-1, 2)
    s1, s2 = parse_working_mode(mode)
    half = 0.5 * robot.d
    q = np.empty(P.shape)
    for blk in blocks(len(P)):
        x, y = P[blk, 0], P[blk, 1]
        for leg, (dx, l, L, s) in enumerate(
            ((-half, robot.l1, robot.L1, s1), (half, robot.l2, robot.L2, s2))
        ):
            ang, rho2, bad = _leg_solve(x + dx, y, l, L, s)
            if bad.any():
                j = int(np.flatnonzero(bad)[0])
                raise _reach_error(P, shape, blk.start + j, float(rho2[j]), l, L, leg + 1)
            q[blk, leg] = ang
    q = q.reshape(P0.shape)
    # np.unwrap changes nothing when no step reaches pi: the common case, seen at once
    if unwrap and q.ndim > 1 and len(q) > 1 and not np.abs(np.diff(q, axis=0)).max() < np.pi:
        q = np.unwrap(q, axis=0)
    return q


def elbows(robot: FiveBar, q: object) -> tuple[Array, Array]:
    """Elbow positions ``B`` and ``C``, each of shape (..., 2), for angles ``q`` (..., 2)."""
    q = as_points(q, "q")
    half = 0.5 * robot.d
    c1, s1 = cos_sin(q[..., 0])
    c2, s2 = cos_sin(q[..., 1])
    B = np.stack([half + robot.l1 * c1, robot.l1 * s1], axis=-1)
    C = np.stack([-half + robot.l2 * c2, robot.l2 * s2], axis=-1)
    return B, C


def direct_kinematics(robot: FiveBar, q: object, assembly: str | int = "up") -> Array:
    """End-effector position for actuator angles ``q``.

    Parameters
    ----------
    robot : FiveBar
    q : array_like, shape (..., 2)
        ``(phi, psi)`` in radians.
    assembly : {"up", "down"} or {+1, -1}
        Sign of ``(B - C) x (P - C)``; "up" puts P on the left of the direction C -> B.

    Returns
    -------
    P : ndarray, shape (..., 2)

    Raises
    ------
    AssemblyError
        Where the distal rods cannot meet (``|B - C|`` outside ``[|L1 - L2|, L1 + L2]``).
    """
    q0 = as_points(q, "q")
    shape = q0.shape[:-1]
    qf = q0.reshape(-1, 2)
    sigma = parse_assembly_mode(assembly)
    half = 0.5 * robot.d
    L1, L2 = robot.L1, robot.L2
    P = np.empty(qf.shape)
    for blk in blocks(len(qf)):
        c1, s1 = cos_sin(qf[blk, 0])
        c2, s2 = cos_sin(qf[blk, 1])
        cx = robot.l2 * c2 - half
        cy = robot.l2 * s2
        vx = (robot.l1 * c1 + half) - cx
        vy = robot.l1 * s1 - cy
        del2 = vx * vx + vy * vy
        k = 0.5 * (del2 + (L2 * L2 - L1 * L1))
        w2 = (L2 * L2) * del2 - k * k
        # rounding may leave w2 a hair below zero on the boundary (rods aligned): allow it
        bad = ~(w2 >= -1e-12 * (L2 * L2) * del2) | (del2 <= 1e-24 * (L1 + L2) ** 2)
        if bad.any():
            j = int(np.flatnonzero(bad)[0])
            i = blk.start + j
            raise AssemblyError(
                f"distal rods cannot meet for q = ({np.degrees(qf[i, 0]):.6g}, "
                f"{np.degrees(qf[i, 1]):.6g}) deg{where(flat_index(i, shape), shape)}: "
                f"|B - C| = {np.sqrt(del2[j]):.6g} outside [{abs(L1 - L2):.6g}, {L1 + L2:.6g}]"
            )
        w = np.sqrt(np.maximum(w2, 0.0))
        if sigma < 0:
            w = -w
        inv = 1.0 / del2
        P[blk, 0] = cx + (k * vx - w * vy) * inv
        P[blk, 1] = cy + (k * vy + w * vx) * inv
    return P.reshape(q0.shape)


def working_mode(robot: FiveBar, q: object, points: object) -> Array:
    """Working-mode signs ``(s1, s2)`` of configurations, shape (..., 2), entries +1/-1 (0 when
    a leg is exactly stretched or folded)."""
    P = as_points(points, "points")
    B, C = elbows(robot, q)
    u1, v1, u2, v2 = B - robot.A, P - B, C - robot.D, P - C
    s1 = np.sign(cross(u1[..., 0], u1[..., 1], v1[..., 0], v1[..., 1]))
    s2 = np.sign(cross(u2[..., 0], u2[..., 1], v2[..., 0], v2[..., 1]))
    return np.stack([s1, s2], axis=-1).astype(int)


def assembly_mode(robot: FiveBar, q: object, points: object) -> Array:
    """Assembly sign ``sign((B - C) x (P - C))`` of configurations, shape (...,)."""
    P = as_points(points, "points")
    B, C = elbows(robot, q)
    v, u = B - C, P - C
    return np.sign(cross(v[..., 0], v[..., 1], u[..., 0], u[..., 1])).astype(int)
