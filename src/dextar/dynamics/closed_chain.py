"""The closed chain in full coordinates: dynamics that stay bounded through a parallel (type 2)
singularity.

The five-bar's motion is described by ``z = (phi, psi, x, y)``, the motor angles and the
end-effector, tied by the two loop constraints ``Phi_i = (|P - B_i|^2 - L_i^2) / 2 = 0``
(``B_1 = B``, ``B_2 = C``). Their Jacobian is ``Phi_z = [-B | A]`` with ``A`` and ``B`` of the
velocity relation ``A Pdot = B qdot`` (:mod:`dextar.kinematics.velocity`); it keeps full rank
at a parallel singularity, where only ``A`` loses it (``det A = 0``: B, C and P aligned), so
the chain itself is regular there: what is singular is the map from the motors to the
end-effector. With the generalised inertia forces (gravity and friction included) split into
``F_q`` on the motor angles and ``F_P`` on the end-effector (Kane's equations on the partial
velocities in ``z``, :func:`chain_forces`), the equations of motion with the multipliers
``mu`` of the constraints are

    tau = F_q + B mu,        F_P = A^T mu.

* **Inverse dynamics** ``tau = F_q + B A^-T F_P``: the division by ``det A`` is physics, not
  a choice of coordinates. At a singularity ``A^T mu`` spans only the direction of the aligned
  rods, so a motion is possible with finite torques only when ``F_P`` has no component ``n``
  normal to them: the **degeneracy condition** ``n . F_P = 0`` (Briot & Arakelian, "Optimal
  force generation in parallel manipulators for passing through the singular positions",
  IJRR 27(8), 2008; the torque there is the limit of ``B A^-T F_P``, finite where the
  condition holds). :func:`degeneracy_residual` measures it.
* **Task-space dynamics** ``M_P Pddot + h_P = E tau`` with ``E = A^T B^-1`` (eliminating ``mu``
  and ``qddot = B^-1 (A Pddot - bias)``): ``M_P`` is positive definite and ``E`` bounded
  through a parallel singularity (singular only at a serial one), so integrating the motion
  in the end-effector's coordinates (:func:`task_dynamics`) never inverts the singular
  matrix: at the crossing ``E`` loses rank (the motors cannot push P along ``n``) and the
  robot passes on its momentum. The same structure is why a controller must not invert
  ``E`` there (:mod:`dextar.simulation.crossing`).

Every function is vectorised over samples (arrays of shape (..., 2)); the torques of
:func:`chain_torques` agree with :func:`dextar.dynamics.exact.inverse_dynamics` (a second,
independent evaluation: the tests compare them away from the singularity).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._arrays import Array, as_points, cos_sin
from ..kinematics import inverse_kinematics, joint_rates
from .exact import Model
from .friction import friction_torque


@dataclass(frozen=True)
class ChainForces:
    """The generalised forces of the chain's inertia, gravity and friction in ``z``.

    Attributes
    ----------
    q : ndarray, shape (..., 2)
        ``F_q``, on the motor angles (proximal rods, rotors, the distal rods' share at the
        elbows, friction), N m.
    P : ndarray, shape (..., 2)
        ``F_P``, on the end-effector's coordinates (its mass, the distal rods' share at P),
        N.
    A : ndarray, shape (..., 2, 2)
        ``A`` of ``A Pdot = B qdot`` (rows ``(P - B)^T``, ``(P - C)^T``).
    b : ndarray, shape (..., 2)
        The diagonal of ``B``.
    """

    q: Array
    P: Array
    A: Array
    b: Array

    @property
    def det(self) -> Array:
        """``det A``, shape (...,)."""
        return np.asarray(self.A[..., 0, 0] * self.A[..., 1, 1]
                          - self.A[..., 0, 1] * self.A[..., 1, 0])

    def multipliers(self) -> Array:
        """``mu = A^-T F_P`` (..., 2): the forces along the distal rods per unit length
        (unbounded at a parallel singularity unless the degeneracy condition holds)."""
        A, F = self.A, self.P
        det = self.det
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.stack([(A[..., 1, 1] * F[..., 0] - A[..., 1, 0] * F[..., 1]) / det,
                             (A[..., 0, 0] * F[..., 1] - A[..., 0, 1] * F[..., 0]) / det], -1)

    def torques(self) -> Array:
        """``tau = F_q + B A^-T F_P`` (..., 2)."""
        return np.asarray(self.q + self.b * self.multipliers())

    def task_force(self) -> Array:
        """``F_P + A^T B^-1 F_q`` (..., 2): the force at P that the motors must produce
        through ``E = A^T B^-1`` (bounded at a parallel singularity)."""
        g = self.q / self.b
        A = self.A
        return np.stack([self.P[..., 0] + A[..., 0, 0] * g[..., 0] + A[..., 1, 0] * g[..., 1],
                         self.P[..., 1] + A[..., 0, 1] * g[..., 0] + A[..., 1, 1] * g[..., 1]],
                        -1)


def _forces(model: Model, c1: Any, s1: Any, c2: Any, s2: Any, w1: Any, w2: Any, a1: Any,
            a2: Any, Px: Any, Py: Any, ddPx: Any, ddPy: Any, gravity: bool,
            friction: bool) -> tuple[Any, ...]:
    """The arithmetic of :func:`chain_forces` on arrays or plain floats: ``F_q``, ``F_P``,
    ``u = P - B``, ``e = P - C`` and ``b`` component by component."""
    r, ine = model.robot, model.inertia
    l1, l2, L1, L2 = r.l1, r.l2, r.L1, r.L2
    half = 0.5 * r.d
    ux, uy = Px - (half + l1 * c1), Py - l1 * s1
    ex, ey = Px - (l2 * c2 - half), Py - l2 * s2
    ddBx, ddBy = -l1 * (s1 * a1 + c1 * w1 * w1), l1 * (c1 * a1 - s1 * w1 * w1)
    ddCx, ddCy = -l2 * (s2 * a2 + c2 * w2 * w2), l2 * (c2 * a2 - s2 * w2 * w2)
    gx, gy = ine.gravity if gravity else (0.0, 0.0)
    rod1, rod2 = ine.proximal
    rod3, rod4 = ine.distal
    lam3, lam4 = rod3.com / L1, rod4.com / L2
    # the distal rods: their centres' inertia forces, their couples k = I alpha / L^2
    f3x = rod3.mass * (ddBx + lam3 * (ddPx - ddBx) - gx)
    f3y = rod3.mass * (ddBy + lam3 * (ddPy - ddBy) - gy)
    k3 = rod3.inertia * (ux * (ddPy - ddBy) - uy * (ddPx - ddBx)) / (L1 * L1 * L1 * L1)
    f4x = rod4.mass * (ddCx + lam4 * (ddPx - ddCx) - gx)
    f4y = rod4.mass * (ddCy + lam4 * (ddPy - ddCy) - gy)
    k4 = rod4.inertia * (ex * (ddPy - ddCy) - ey * (ddPx - ddCx)) / (L2 * L2 * L2 * L2)
    mP = ine.point_mass
    FPx = mP * (ddPx - gx) + lam3 * f3x + lam4 * f4x - k3 * uy - k4 * ey
    FPy = mP * (ddPy - gy) + lam3 * f3y + lam4 * f4y + k3 * ux + k4 * ex
    FBx, FBy = (1.0 - lam3) * f3x + k3 * uy, (1.0 - lam3) * f3y - k3 * ux
    FCx, FCy = (1.0 - lam4) * f4x + k4 * ey, (1.0 - lam4) * f4y - k4 * ex
    Fq1 = (l1 * (c1 * FBy - s1 * FBx) + (ine.rotor[0] + rod1.about_joint) * a1
           - rod1.mass * rod1.com * (c1 * gy - s1 * gx))
    Fq2 = (l2 * (c2 * FCy - s2 * FCx) + (ine.rotor[1] + rod2.about_joint) * a2
           - rod2.mass * rod2.com * (c2 * gy - s2 * gx))
    if friction and ine.has_friction:
        Fq1 = Fq1 + friction_torque(w1, ine.viscous[0], ine.coulomb[0], ine.coulomb_speed)
        Fq2 = Fq2 + friction_torque(w2, ine.viscous[1], ine.coulomb[1], ine.coulomb_speed)
    b1, b2 = l1 * (c1 * uy - s1 * ux), l2 * (c2 * ey - s2 * ex)
    return Fq1, Fq2, FPx, FPy, ux, uy, ex, ey, b1, b2


def chain_forces(model: Model, q: object, dq: object, ddq: object, P: object, dP: object,
                 ddP: object, *, gravity: bool = True, friction: bool = True) -> ChainForces:
    """The generalised forces ``F_q`` and ``F_P`` of a motion given in full coordinates.

    Parameters
    ----------
    q, dq, ddq : array_like, shape (..., 2)
        Motor angles, rates and accelerations.
    P, dP, ddP : array_like, shape (..., 2)
        The end-effector's position, velocity and acceleration (consistent with ``q``: no
        direct kinematics is solved, so nothing is divided by ``det A``; ``dP`` enters only
        through ``dq``, given).
    gravity, friction : bool
        Include the gravity and the motors' friction.

    Returns
    -------
    ChainForces
    """
    q, dq, ddq, P, dP, ddP = (as_points(x, n) for x, n in (
        (q, "q"), (dq, "dq"), (ddq, "ddq"), (P, "P"), (dP, "dP"), (ddP, "ddP")))
    c1, s1 = cos_sin(q[..., 0])
    c2, s2 = cos_sin(q[..., 1])
    Fq1, Fq2, FPx, FPy, ux, uy, ex, ey, b1, b2 = _forces(
        model, c1, s1, c2, s2, dq[..., 0], dq[..., 1], ddq[..., 0], ddq[..., 1], P[..., 0],
        P[..., 1], ddP[..., 0], ddP[..., 1], gravity, friction)
    A = np.stack([np.stack([ux, uy], -1), np.stack([ex, ey], -1)], -2)
    return ChainForces(np.stack([Fq1, Fq2], -1), np.stack([FPx, FPy], -1), A,
                       np.stack([b1, b2], -1))


def chain_torques(model: Model, q: object, dq: object, ddq: object, P: object, dP: object,
                  ddP: object) -> Array:
    """Motor torques ``F_q + B A^-T F_P`` (..., 2) of a motion in full coordinates (gravity
    and friction included); the same as :func:`dextar.dynamics.exact.inverse_dynamics` away
    from a parallel singularity, and not refused near one (the caller decides)."""
    return chain_forces(model, q, dq, ddq, P, dP, ddP).torques()


def rods_normal(A: Array) -> Array:
    """The unit normal ``n`` (..., 2) to the distal rod BP (``A``'s first row turned by +90
    degrees): at a parallel singularity both rods lie along ``A``'s rows and ``n`` is the
    direction along which the motors cannot push the end-effector."""
    u = A[..., 0, :]
    return np.stack([-u[..., 1], u[..., 0]], -1) / np.hypot(u[..., 0], u[..., 1])[..., None]


def degeneracy_residual(forces: ChainForces) -> Array:
    """``n . F_P`` (...,): the component of the end-effector's force normal to the distal rod
    BP, which the degeneracy condition asks to vanish at a parallel singularity."""
    n = rods_normal(forces.A)
    return np.asarray(n[..., 0] * forces.P[..., 0] + n[..., 1] * forces.P[..., 1])


@dataclass(frozen=True)
class TaskDynamics:
    """The dynamics in the end-effector's coordinates ``M Pddot + h = E tau``.

    Attributes
    ----------
    M : ndarray, shape (..., 2, 2)
        Positive definite (through parallel singularities).
    h : ndarray, shape (..., 2)
        Velocity products, gravity and friction.
    E : ndarray, shape (..., 2, 2)
        ``A^T B^-1``: how the motor torques push the end-effector (rank 1 at a parallel
        singularity, unbounded only at a serial one).
    q, dq : ndarray, shape (..., 2)
        The motor angles (inverse kinematics in the working mode) and rates.
    """

    M: Array
    h: Array
    E: Array
    q: Array
    dq: Array

    def acceleration(self, tau: object) -> Array:
        """``Pddot = M^-1 (E tau - h)`` (..., 2)."""
        rhs = np.einsum("...ij,...j->...i", self.E, np.asarray(tau, float)) - self.h
        return np.asarray(np.linalg.solve(self.M, rhs[..., None])[..., 0])


def task_dynamics(model: Model, mode: str, P: object, dP: object, *,
                  q: Array | None = None) -> TaskDynamics:
    """:class:`TaskDynamics` at the end-effector states ``(P, dP)`` (..., 2) in working mode
    ``mode`` (the motor angles by inverse kinematics, or ``q`` when given: e.g. unwrapped
    along a motion).

    The columns of ``M`` and ``h`` are :meth:`ChainForces.task_force` at unit and zero
    end-effector accelerations (it is affine in them), with ``qddot = B^-1 (A Pddot - bias)``.
    """
    P, dP = as_points(P, "P"), as_points(dP, "dP")
    if q is None:
        q = inverse_kinematics(model.robot, P, mode)
    shape = P.shape[:-1]
    # the three accelerations side by side on a new axis: 0, e_x, e_y
    acc = np.zeros(shape + (3, 2))
    acc[..., 1, 0] = acc[..., 2, 1] = 1.0
    Pk, dPk, qk = (np.broadcast_to(x[..., None, :], shape + (3, 2)) for x in (P, dP, q))
    dq, ddq = joint_rates(model.robot, qk, Pk, dPk, acc, tol=0.0)
    f = chain_forces(model, qk, dq, ddq, Pk, dPk, acc)
    W = f.task_force()
    h = W[..., 0, :]
    M = np.stack([W[..., 1, :] - h, W[..., 2, :] - h], -1)
    A, b = f.A[..., 0, :, :], f.b[..., 0, :]
    E = np.swapaxes(A, -1, -2) / b[..., None, :]
    return TaskDynamics(M, h, E, q, dq[..., 0, :])


def _elbow(x: float, y: float, l: float, L: float, sign: int) -> tuple[float, float] | None:
    """One leg's inverse kinematics on floats: the proximal rod's ``(cos, sin)`` for the point
    ``(x, y)`` from its pivot (as :func:`dextar.kinematics.inverse_kinematics`), None out of
    reach."""
    rho2 = x * x + y * y
    k = 0.5 * (rho2 + (l * l - L * L))
    w2 = (l * l) * rho2 - k * k
    if not (w2 >= -1e-12 * (l * l) * rho2) or rho2 <= 1e-24 * (l + L) ** 2:
        return None
    w = math.sqrt(max(w2, 0.0))
    if sign > 0:
        w = -w
    cx, cy = k * x - w * y, k * y + w * x
    n = math.hypot(cx, cy)
    return cx / n, cy / n


def task_state(model: Model, signs: tuple[int, int], P: Any, dP: Any
               ) -> tuple[Array, Array, Array, Array, Array] | None:
    """:func:`task_dynamics` at one state on plain floats (fast enough for an integrator's
    step): ``M (2, 2), h (2,), E (2, 2), q (2,), dq (2,)`` in the working mode of ``signs``;
    None where the end-effector is out of reach or at a serial singularity (where the working
    mode ends)."""
    r = model.robot
    half = 0.5 * r.d
    Px, Py, vx, vy = float(P[0]), float(P[1]), float(dP[0]), float(dP[1])
    e1 = _elbow(Px - half, Py, r.l1, r.L1, signs[0])
    e2 = _elbow(Px + half, Py, r.l2, r.L2, signs[1])
    if e1 is None or e2 is None:
        return None
    (c1, s1), (c2, s2) = e1, e2
    ux, uy = Px - (half + r.l1 * c1), Py - r.l1 * s1
    ex, ey = Px - (r.l2 * c2 - half), Py - r.l2 * s2
    b1, b2 = r.l1 * (c1 * uy - s1 * ux), r.l2 * (c2 * ey - s2 * ex)
    if abs(b1) <= 1e-9 * r.l1 * r.L1 or abs(b2) <= 1e-9 * r.l2 * r.L2:
        return None
    w1, w2 = (ux * vx + uy * vy) / b1, (ex * vx + ey * vy) / b2
    # the velocity-product terms of A Pddot - B qddot = bias
    gx1, gy1 = vx + r.l1 * w1 * s1, vy - r.l1 * w1 * c1
    gx2, gy2 = vx + r.l2 * w2 * s2, vy - r.l2 * w2 * c2
    bias1 = -(gx1 * gx1 + gy1 * gy1) - r.l1 * w1 * w1 * (ux * c1 + uy * s1)
    bias2 = -(gx2 * gx2 + gy2 * gy2) - r.l2 * w2 * w2 * (ex * c2 + ey * s2)
    W = []
    for ax, ay in ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)):
        a1, a2 = (ux * ax + uy * ay - bias1) / b1, (ex * ax + ey * ay - bias2) / b2
        f = _forces(model, c1, s1, c2, s2, w1, w2, a1, a2, Px, Py, ax, ay, True, True)
        g1, g2 = f[0] / b1, f[1] / b2
        W.append((f[2] + ux * g1 + ex * g2, f[3] + uy * g1 + ey * g2))
    h = np.array(W[0])
    M = np.array([[W[1][0] - h[0], W[2][0] - h[0]], [W[1][1] - h[1], W[2][1] - h[1]]])
    E = np.array([[ux / b1, ex / b2], [uy / b1, ey / b2]])
    q = np.array([math.atan2(s1, c1), math.atan2(s2, c2)])
    return M, h, E, q, np.array([w1, w2])
