"""Dynamic balancing of the five-bar: the shaking force and moment of a motion, and the
counterweights that balance the force.

Shaking force and moment. What the moving parts exert on the frame, beyond their weight:

* the shaking force ``F = -M a_G``, ``M`` the moving mass (rods, counterweights, end-effector
  and payload) and ``a_G`` the acceleration of its centre of mass;
* the shaking moment ``N = -dH_O/dt``, ``H_O`` the angular momentum of the moving parts about
  the origin O (the middle of AD, the frame's fixed point the robot's coordinates start
  from): rods, counterweights and point mass, ``sum m (G - O) x v_G + I_G omega``, and the
  parts that spin on the motor axes (rotors), ``spin_k qdot_k``. When the force is balanced
  (``a_G = 0``) the moment is the same about every point.

Rotors: their centres do not move (no shaking force); their spin adds to ``H_O``. A rotor of
inertia ``J_r`` behind a gearbox of ratio ``N`` turns at ``N qdot``: its angular momentum is
``N J_r qdot`` (the joint sees the reflected inertia ``N^2 J_r``). The default ``spin`` is
:attr:`Inertia.rotor`, the parts that turn with their joint (a direct drive); pass ``spin`` for
a gearbox, with its sign for a gearbox that turns the rotor against its joint.

Force balancing (closed form). With the elbows ``B = A + l1 e1``, ``C = D + l2 e2`` and a
distal rod's centre at ``lambda`` of the rod, the mechanism's first moment is

    M r_G = const + H1 e1 + H2 e2 + m_P' P,
    H_k = h_k + m_dk (1 - lambda_k) l_k,   m_P' = m_P + m_d1 lambda_1 + m_d2 lambda_2,

``h_k`` the first moment of proximal rod k about its motor axis (with its counterweight) and
``m_P`` the point mass at P (end-effector and payload). A distal rod enters through its mass
and first moment only, which two point masses ``m (1 - lambda)`` at its elbow and
``m lambda`` at P share exactly: lumping the distal masses at the joints is exact for the
force (not for the moment). The unit vectors of the four rods obey one linear relation with
constant coefficients, the loop ``l1 e1 + L1 e3 - l2 e2 - L2 e4 = D - A``; the method of
linearly independent vectors (Berkof & Lowen 1969; Arakelian & Smith, J. Mech. Des. 127(2),
2005; Arakelian & Briot, *Balancing of Linkages and Robot Manipulators*, Springer 2015) gives
the centre of mass fixed for every motion if and only if

    (a) H_1 = H_2 = 0: each proximal rod's counterweight carries ``m_c r = h_k +
        m_dk (1 - lambda_k) l_k`` (its rod and its elbow's share of the distal rod), and
    (b) m_P' = 0: the masses lumped at P vanish, ``m_P + h_d1 / L1 + h_d2 / L2 = 0`` with
        ``h_dk`` the first moment of distal rod k about its elbow.

(a) alone leaves ``F = -m_P' a_P``: the force of the mass lumped at P, whatever the
counterweights on the proximal rods. (b) needs distal rods whose centres lie behind their
elbows (negative first moments): their masses redistributed, by counterweights on extensions
of the distal rods beyond the elbows (:func:`distal_counterweights`); counterweights on the
proximal rods alone never balance a five-bar that carries a mass at P. The closed form
assumes the centres of mass on the rods' axes (counterweights on the axes), the payload
balanced is the one given, and (b) for a full balance. :func:`balance_force` synthesises (a)
and reports ``m_P'``; :func:`mass_center` checks the result over any motion.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._arrays import Array, as_points, cos_sin
from ..errors import ParameterError
from ..geometry import FiveBar
from ..kinematics import direct_kinematics, elbows, task_acceleration, task_velocity
from .exact import Model
from .inertia import Counterweight, Inertia, Rod


def _cross(ax: Array, ay: Array, bx: Array, by: Array) -> Array:
    return np.asarray(ax * by - ay * bx)


def _pair(value: object, name: str) -> tuple[float, float]:
    """A number (both legs) or a pair, as two floats."""
    v = np.asarray(value, float)
    if v.ndim == 0:
        v = np.broadcast_to(v, (2,))
    if v.shape != (2,):
        raise ParameterError(f"{name} {value!r} must be a number or a pair (leg 1, leg 2)")
    return float(v[0]), float(v[1])


def moving_mass(inertia: Inertia) -> float:
    """``M``: the mass of the moving parts (rods with their counterweights, end-effector and
    payload; rotors turn in place and are left out)."""
    return float(sum(r.mass for r in (*inertia.proximal, *inertia.distal))
                 + inertia.point_mass)


def mass_center(model: Model, q: object) -> Array:
    """The centre of mass of the moving parts (..., 2) at the motor angles ``q`` (..., 2),
    assembled in the model's assembly mode (the robot's units)."""
    q = as_points(q, "q")
    r, ine = model.robot, model.inertia
    B, C = elbows(r, q)
    P = direct_kinematics(r, q, model.assembly)
    first = np.zeros(q.shape)
    for pivot, rod, ang in ((r.A, ine.proximal[0], q[..., 0]), (r.D, ine.proximal[1], q[..., 1])):
        c, s = cos_sin(ang)
        first += rod.mass * pivot + rod.first_moment * np.stack([c, s], -1)
    for elbow, rod, L in ((B, ine.distal[0], r.L1), (C, ine.distal[1], r.L2)):
        lam = rod.com / L
        first += rod.mass * (elbow + lam * (P - elbow))
    first += ine.point_mass * P
    M = moving_mass(ine)
    if M <= 0:
        raise ParameterError("the mechanism has no moving mass: its centre of mass is not "
                             "defined")
    return np.asarray(first / M)


@dataclass(frozen=True)
class Shaking:
    """The shaking force and moment of a motion (the robot's units).

    Attributes
    ----------
    force : ndarray, shape (n, 2)
        ``-M a_G``: the moving parts' inertia force on the frame (their weight left out).
    moment : ndarray, shape (n,)
        ``-dH_O/dt`` about the origin O (the middle of AD), rotors' spin included.
    mass : float
        ``M``, the moving mass.
    """

    force: Array
    moment: Array
    mass: float

    @property
    def force_magnitude(self) -> Array:
        """``|F|`` per sample."""
        return np.asarray(np.hypot(self.force[..., 0], self.force[..., 1]))

    def summary(self, t: object) -> dict[str, float]:
        """Peak and RMS over the motion sampled at times ``t`` (n,) (the RMS by the
        trapezoidal rule over time, as the motors' RMS torque is):
        ``shaking_force``, ``rms_shaking_force``, ``shaking_moment``,
        ``rms_shaking_moment``."""
        tt = np.asarray(t, float).reshape(-1)
        f, m = self.force_magnitude.reshape(-1), np.abs(self.moment).reshape(-1)
        return {"shaking_force": float(f.max()), "rms_shaking_force": time_rms(tt, f),
                "shaking_moment": float(m.max()), "rms_shaking_moment": time_rms(tt, m)}


def time_rms(t: Array, x: Array) -> float:
    """``sqrt(int x^2 dt / T)`` by the trapezoidal rule (``|x|`` for a single sample)."""
    if len(t) < 2 or not t[-1] > t[0]:
        return float(np.abs(x).max()) if len(x) else 0.0
    sq = x * x
    integral = float(np.sum(0.5 * (sq[1:] + sq[:-1]) * np.diff(t)))
    return float(np.sqrt(max(integral, 0.0) / (t[-1] - t[0])))


def shaking(model: Model, q: object, dq: object, ddq: object, *, P: object = None,
            spin: object = None) -> Shaking:
    """The shaking force ``-M a_G`` and the shaking moment ``-dH_O/dt`` about the origin O of
    the motion ``q, dq, ddq`` (each (n, 2)), in the robot's units.

    Parameters
    ----------
    model : Model
    q, dq, ddq : array_like, shape (n, 2)
    P : array_like, shape (n, 2), optional
        The end-effector's positions, when known (else by direct kinematics in the model's
        assembly mode).
    spin : number or (float, float), optional
        Angular momentum per unit joint rate of the parts spinning on each motor axis: the
        model's rotor inertia by default (they turn with the joint); ``N J_r`` for a rotor
        ``J_r`` behind a gearbox of ratio ``N`` (negative for a gearbox that reverses).

    Returns
    -------
    Shaking
    """
    qq = as_points(q, "q")
    w = as_points(dq, "dq").reshape(qq.shape)
    a = as_points(ddq, "ddq").reshape(qq.shape)
    r, ine = model.robot, model.inertia
    Pp = direct_kinematics(r, qq, model.assembly) if P is None else as_points(P, "P")
    _, ddP = task_acceleration(r, qq, Pp, w, a, tol=0.0)
    B, C = elbows(r, qq)
    spins = ine.rotor if spin is None else _pair(spin, "spin")
    ox = np.zeros(qq.shape[:-1])
    Fx, Fy, dH = ox.copy(), ox.copy(), ox.copy()
    accel_elbow = []
    for k, (pivot, rod, l) in enumerate(((r.A, ine.proximal[0], r.l1),
                                         (r.D, ine.proximal[1], r.l2))):
        c, s = cos_sin(qq[..., k])
        wk, ak = w[..., k], a[..., k]
        # e'' = a e_perp - w^2 e
        ex2, ey2 = -s * ak - c * wk * wk, c * ak - s * wk * wk
        accel_elbow.append((l * ex2, l * ey2))
        h = rod.first_moment
        Fx -= h * ex2
        Fy -= h * ey2
        # m (G - O) x a_G + I_G alpha = (pivot - O) x h e'' + J alpha
        dH += _cross(pivot[0], pivot[1], h * ex2, h * ey2) + (rod.about_joint + spins[k]) * ak
    for (elbow, (abx, aby), rod, L) in ((B, accel_elbow[0], ine.distal[0], r.L1),
                                        (C, accel_elbow[1], ine.distal[1], r.L2)):
        lam = rod.com / L
        ux, uy = Pp[..., 0] - elbow[..., 0], Pp[..., 1] - elbow[..., 1]
        rx, ry = ddP[..., 0] - abx, ddP[..., 1] - aby
        agx, agy = abx + lam * rx, aby + lam * ry
        alpha = _cross(ux, uy, rx, ry) / (L * L)
        Fx -= rod.mass * agx
        Fy -= rod.mass * agy
        gx, gy = elbow[..., 0] + lam * ux, elbow[..., 1] + lam * uy
        dH += rod.mass * _cross(gx, gy, agx, agy) + rod.inertia * alpha
    mP = ine.point_mass
    Fx -= mP * ddP[..., 0]
    Fy -= mP * ddP[..., 1]
    dH += mP * _cross(Pp[..., 0], Pp[..., 1], ddP[..., 0], ddP[..., 1])
    return Shaking(np.stack([Fx, Fy], -1), -dH, moving_mass(ine))


def angular_momentum(model: Model, q: object, dq: object, *, spin: object = None) -> Array:
    """``H_O`` (..., ) of the moving parts about the origin O at the state ``q, dq`` (each
    (..., 2)): what :func:`shaking`'s moment is the rate of (for checks by finite
    differences)."""
    qq = as_points(q, "q")
    w = as_points(dq, "dq").reshape(qq.shape)
    r, ine = model.robot, model.inertia
    P = direct_kinematics(r, qq, model.assembly)
    dP = task_velocity(r, qq, P, w, tol=0.0)
    B, C = elbows(r, qq)
    spins = ine.rotor if spin is None else _pair(spin, "spin")
    H = np.zeros(qq.shape[:-1])
    vel_elbow = []
    for k, (pivot, rod, l) in enumerate(((r.A, ine.proximal[0], r.l1),
                                         (r.D, ine.proximal[1], r.l2))):
        c, s = cos_sin(qq[..., k])
        wk = w[..., k]
        vel_elbow.append((-l * s * wk, l * c * wk))
        h = rod.first_moment
        H += _cross(pivot[0], pivot[1], -h * s * wk, h * c * wk) + (
            rod.about_joint + spins[k]) * wk
    for (elbow, (vbx, vby), rod, L) in ((B, vel_elbow[0], ine.distal[0], r.L1),
                                        (C, vel_elbow[1], ine.distal[1], r.L2)):
        lam = rod.com / L
        ux, uy = P[..., 0] - elbow[..., 0], P[..., 1] - elbow[..., 1]
        rx, ry = dP[..., 0] - vbx, dP[..., 1] - vby
        omega = _cross(ux, uy, rx, ry) / (L * L)
        gx, gy = elbow[..., 0] + lam * ux, elbow[..., 1] + lam * uy
        H += rod.mass * _cross(gx, gy, vbx + lam * rx, vby + lam * ry) + rod.inertia * omega
    H += ine.point_mass * _cross(P[..., 0], P[..., 1], dP[..., 0], dP[..., 1])
    return H


@dataclass(frozen=True)
class ForceBalance:
    """The proximal counterweights of :func:`balance_force` and what they leave.

    Attributes
    ----------
    counterweights : (Counterweight, Counterweight)
        On rods AB and DC: ``m_c r = h_k + m_dk (1 - lambda_k) l_k`` (condition (a)).
    inertia : Inertia
        The inertia given with these counterweights (they replace any it had).
    residual_mass : float
        ``m_P'``, the mass lumped at P: the centre of mass moves as ``m_P' P / M`` and the
        shaking force is ``-m_P' a_P``. Zero (to rounding) for a full balance.
    mass : float
        ``M``, the moving mass with the counterweights.
    """

    counterweights: tuple[Counterweight, Counterweight]
    inertia: Inertia
    residual_mass: float
    mass: float

    @property
    def full(self) -> bool:
        """True when the force is fully balanced: ``|m_P'|`` within 1e-12 of the masses
        (rounding)."""
        return abs(self.residual_mass) <= 1e-12 * max(self.mass, 1e-300)


def residual_mass(robot: FiveBar, inertia: Inertia) -> float:
    """``m_P' = m_P + h_d1 / L1 + h_d2 / L2``: the mass lumped at P (condition (b) wants it
    zero)."""
    d1, d2 = inertia.distal
    return float(inertia.point_mass + d1.first_moment / robot.L1 + d2.first_moment / robot.L2)


def balance_force(robot: FiveBar, inertia: Inertia, distance: object, *,
                  counterweight_inertia: object = 0.0) -> ForceBalance:
    """The counterweights on the proximal rods that keep the centre of mass of every leg's
    proximal rod and its elbow's share of the distal rod on the motor axis (condition (a) of
    the module doc), at ``distance`` behind each motor axis.

    Parameters
    ----------
    robot : FiveBar
    inertia : Inertia
        Its counterweights, if any, are replaced.
    distance : number or (float, float)
        Behind each motor axis, > 0 (the robot's length unit).
    counterweight_inertia : number or (float, float)
        Each counterweight's inertia about its own centre.

    Returns
    -------
    ForceBalance
        A full balance when the distal rods make ``m_P' = 0`` (see
        :func:`distal_counterweights`); otherwise the force left is ``-m_P' a_P``.

    Raises
    ------
    ParameterError
        A distance not positive, or a leg already past balance (its rod's centre of mass
        behind the axis by more than the elbow's share: a counterweight would need a negative
        mass).
    """
    r = _pair(distance, "counterweight distance")
    ic = _pair(counterweight_inertia, "counterweight inertia")
    if not all(v > 0 and np.isfinite(v) for v in r):
        raise ParameterError(f"counterweight distance {distance!r} must be positive")
    bare = inertia.bare_proximal
    cws = []
    for k, (rod, dist, l, L) in enumerate(zip(bare, inertia.distal, (robot.l1, robot.l2),
                                              (robot.L1, robot.L2), strict=True)):
        need = rod.first_moment + dist.mass * (1.0 - dist.com / L) * l
        if need < -1e-12 * (abs(rod.first_moment) + dist.mass * l + 1e-300):
            raise ParameterError(
                f"leg {k + 1}: rod {'AB' if k == 0 else 'DC'} is already past balance (first "
                f"moment {rod.first_moment:g} about the axis, elbow share "
                f"{need - rod.first_moment:g}): a counterweight behind the axis cannot "
                "balance it")
        cws.append(Counterweight(max(need, 0.0) / r[k], r[k], ic[k] if need > 0 else 0.0))
    pair = (cws[0], cws[1])
    balanced = inertia.with_counterweights(pair)
    return ForceBalance(pair, balanced, residual_mass(robot, balanced), moving_mass(balanced))


def distal_counterweights(robot: FiveBar, inertia: Inertia, distance: object, *,
                          share: float = 0.5, counterweight_inertia: object = 0.0
                          ) -> tuple[Inertia, tuple[Counterweight, Counterweight]]:
    """Counterweights on extensions of the distal rods behind their elbows (at ``distance``
    behind B and behind C) that make the mass lumped at P zero (condition (b)): distal rod 1
    takes ``share`` of ``m_P'``, rod 2 the rest. Returns the inertia whose distal rods carry
    them (folded: :meth:`Rod.with_counterweight`) and the two counterweights.

    Raises
    ------
    ParameterError
        A distance not positive, a share outside [0, 1], or a rod that would need a negative
        counterweight (its share of ``m_P'`` is negative).
    """
    r = _pair(distance, "distal counterweight distance")
    ic = _pair(counterweight_inertia, "distal counterweight inertia")
    if not all(v > 0 and np.isfinite(v) for v in r):
        raise ParameterError(f"distal counterweight distance {distance!r} must be positive")
    if not 0.0 <= share <= 1.0:
        raise ParameterError(f"share {share!r} must be within [0, 1]")
    mP = inertia.point_mass
    out: list[Counterweight] = []
    rods: list[Rod] = []
    for k, (rod, L, part) in enumerate(zip(inertia.distal, (robot.L1, robot.L2),
                                           (share, 1.0 - share), strict=True)):
        need = rod.first_moment + part * mP * L  # m_c r so that h_d / L + part m_P = 0
        if need < 0:
            raise ParameterError(f"distal rod {k + 1} is already behind its elbow beyond its "
                                 f"share of the mass at P (first moment {rod.first_moment:g})")
        cw = Counterweight(need / r[k], r[k], ic[k] if need > 0 else 0.0)
        out.append(cw)
        rods.append(rod.with_counterweight(cw))
    return inertia.with_(distal=(rods[0], rods[1])), (out[0], out[1])


def shaking_summary_si(model: Model, t: Array, q: Array, dq: Array, ddq: Array, *,
                       P: Array | None = None, spin: object = None) -> dict[str, Any]:
    """The design metrics of a motion in SI (the model in m, kg, s): ``shaking_force_N``,
    ``rms_shaking_force_N`` (peak and RMS of ``|F|``), ``shaking_moment_Nm``,
    ``rms_shaking_moment_Nm`` (of ``|N|`` about O)."""
    s = shaking(model, q, dq, ddq, P=P, spin=spin).summary(t)
    return {"shaking_force_N": s["shaking_force"], "rms_shaking_force_N": s["rms_shaking_force"],
            "shaking_moment_Nm": s["shaking_moment"],
            "rms_shaking_moment_Nm": s["rms_shaking_moment"]}
