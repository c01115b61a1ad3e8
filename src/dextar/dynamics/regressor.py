"""The exact dynamics written linear in the inertial and friction parameters.

``tau = Y(q, qdot, qddot) theta`` with ``Y`` of shape (..., 2, 15) and ``theta`` the standard
parameters below. Each rod enters through its mass ``m``, first moment ``h = m c`` and inertia
about its proximal joint ``J = I + m c^2`` (the proximal rods' masses only through ``J`` and
``h``, the rotor inertia added to the proximal ``J``); the point mass at P through ``m_P``;
each motor's friction through its viscous and Coulomb coefficients (the Coulomb column is
``tanh(qdot / v_s)``, the regularisation speed being fixed).

Counterweights. A counterweight of mass ``m_c`` at ``r`` behind a motor axis, with inertia
``I_c`` about its centre, is part of its proximal rod's rigid body
(:meth:`~dextar.dynamics.Rod.with_counterweight`): it adds ``I_c + m_c r^2`` to ``J_A`` (or
``J_D``) and takes ``m_c r`` off ``h_AB`` (or ``h_DC``); its mass, like the rod's, is not in
the torques. So the regressor is unchanged, an identification identifies each proximal rod
with its counterweight (``J`` and ``h`` of the pair: the data cannot tell them apart), and a
counterweight added or changed after an identification shifts those two parameters by these
amounts.

Derivation (the same virtual-power decomposition as :mod:`dextar.dynamics.exact`): a distal
rod BP loads B and P with ``f = m (B'' - g) + (h / L)(P'' - B'')`` and the couple of its
rotary inertia; projected on the partial velocities, with ``T_X(F)`` the torques of a force
``F`` at X (``J_X^T F``) and ``(T_P - T_B)(u) = 0`` along the rod ``u = P - B``,

    Y_m = T_B(B'' - g),
    Y_h = [T_B(P'' - B'') + (T_P - T_B)(B'' - g)] / L,
    Y_J = (T_P - T_B)(alpha perp(u)) / L^2.

The columns are checked against :func:`dextar.dynamics.inverse_dynamics` in the tests
(``Y theta`` equals the torques to rounding for any parameters).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from .exact import Model, _run
from .friction import friction_torque
from .inertia import Inertia


@dataclass(frozen=True)
class StandardParameter:
    """One standard parameter: its ``name``, its ``meaning`` in the model's words and its SI
    ``unit``; ``nonnegative`` when physics requires it to be >= 0."""

    name: str
    meaning: str
    unit: str
    nonnegative: bool


#: The standard parameters, in the order of the regressor's columns. The order is also the
#: preference of the base-parameter reduction: a column that depends on earlier ones is
#: lumped into them (the distal masses into the proximal parameters).
STANDARD: tuple[StandardParameter, ...] = (
    StandardParameter("J_A", "rotor A + proximal rod AB (with its counterweight) about A",
                      "kg m^2", True),
    StandardParameter("h_AB", "first moment of rod AB (with its counterweight) about A (m c)",
                      "kg m", False),
    StandardParameter("J_D", "rotor D + proximal rod DC (with its counterweight) about D",
                      "kg m^2", True),
    StandardParameter("h_DC", "first moment of rod DC (with its counterweight) about D (m c)",
                      "kg m", False),
    StandardParameter("m_P", "point mass at P (end-effector + payload)", "kg", True),
    StandardParameter("J_BP", "distal rod BP about B", "kg m^2", True),
    StandardParameter("h_BP", "first moment of rod BP about B (m c)", "kg m", False),
    StandardParameter("J_CP", "distal rod CP about C", "kg m^2", True),
    StandardParameter("h_CP", "first moment of rod CP about C (m c)", "kg m", False),
    StandardParameter("m_BP", "mass of distal rod BP", "kg", True),
    StandardParameter("m_CP", "mass of distal rod CP", "kg", True),
    StandardParameter("fv_A", "viscous friction of motor A", "N m s/rad", True),
    StandardParameter("fc_A", "Coulomb friction of motor A", "N m", True),
    StandardParameter("fv_D", "viscous friction of motor D", "N m s/rad", True),
    StandardParameter("fc_D", "Coulomb friction of motor D", "N m", True),
)
NAMES: tuple[str, ...] = tuple(p.name for p in STANDARD)
#: Column of each standard parameter.
INDEX: dict[str, int] = {n: i for i, n in enumerate(NAMES)}


def standard_parameters(inertia: Inertia) -> Array:
    """The standard parameters ``theta`` (15,) of ``inertia`` (its units)."""
    p1, p2 = inertia.proximal
    d1, d2 = inertia.distal
    values = {
        "J_A": inertia.rotor[0] + p1.about_joint, "h_AB": p1.mass * p1.com,
        "J_D": inertia.rotor[1] + p2.about_joint, "h_DC": p2.mass * p2.com,
        "m_P": inertia.point_mass,
        "J_BP": d1.about_joint, "h_BP": d1.mass * d1.com,
        "J_CP": d2.about_joint, "h_CP": d2.mass * d2.com,
        "m_BP": d1.mass, "m_CP": d2.mass,
        "fv_A": inertia.viscous[0], "fc_A": inertia.coulomb[0],
        "fv_D": inertia.viscous[1], "fc_D": inertia.coulomb[1]}
    return np.array([values[n] for n in NAMES])


def _perp_torques(o: dict[str, Array], Fx: Array, Fy: Array) -> tuple[Array, Array]:
    """``T_P(F)``: torques of a force F at P (``b_k (...) / det``)."""
    t1 = o["b1"] * (o["ey"] * Fx - o["ex"] * Fy) * o["idet"]
    t2 = o["b2"] * (o["ux"] * Fy - o["uy"] * Fx) * o["idet"]
    return t1, t2


_KEYS = ("c1", "s1", "c2", "s2", "ux", "uy", "ex", "ey", "b1", "b2", "idet", "ddPx", "ddPy",
         "ddBx", "ddBy", "ddCx", "ddCy", "alpha3", "alpha4")


def regressor(model: Model, q: object, dq: object, ddq: object, *,
              t: object = None) -> Array:
    """The regressor ``Y`` with ``inverse_dynamics(model, q, dq, ddq) = Y @ theta``.

    Parameters
    ----------
    model : Model
        Geometry, assembly mode, gravity and the Coulomb regularisation speed (its masses are
        not used).
    q, dq, ddq : array_like, shape (..., 2)
        Actuator angles, rates and accelerations.
    t : array_like, optional
        Sample times, only to name the time in an error.

    Returns
    -------
    Y : ndarray, shape (..., 2, 15)
        Row 0 the torque of motor A, row 1 of motor D; columns in the order of
        :data:`STANDARD`.
    """
    o = _run(model, q, dq, ddq, gravity=False, friction=False, t=t, keys=_KEYS)
    r, ine = model.robot, model.inertia
    l1, l2, L1, L2 = r.l1, r.l2, r.L1, r.L2
    gx, gy = ine.gravity
    qq = np.asarray(q, float)
    w = np.asarray(dq, float).reshape(qq.shape)
    a = np.asarray(ddq, float).reshape(qq.shape)
    shape = o["c1"].shape
    Y = np.zeros(shape + (2, len(STANDARD)))
    zero = np.zeros(shape)
    c1, s1, c2, s2 = o["c1"], o["s1"], o["c2"], o["s2"]

    def TB(Fx: Array, Fy: Array) -> Array:
        return np.asarray(l1 * (c1 * Fy - s1 * Fx))

    def TC(Fx: Array, Fy: Array) -> Array:
        return np.asarray(l2 * (c2 * Fy - s2 * Fx))

    col = INDEX
    # proximal rods and rotors
    Y[..., 0, col["J_A"]] = a[..., 0]
    Y[..., 0, col["h_AB"]] = -(c1 * gy - s1 * gx)
    Y[..., 1, col["J_D"]] = a[..., 1]
    Y[..., 1, col["h_DC"]] = -(c2 * gy - s2 * gx)
    # distal rods: (elbow torque of the leg, the other motor gets only the P part)
    for leg, (T, L, ex_, ey_, bx, by, alpha) in enumerate((
            (TB, L1, "ux", "uy", "ddBx", "ddBy", "alpha3"),
            (TC, L2, "ex", "ey", "ddCx", "ddCy", "alpha4"))):
        Ex, Ey = o[bx], o[by]
        gBx, gBy = Ex - gx, Ey - gy
        relx, rely = o["ddPx"] - Ex, o["ddPy"] - Ey
        ux, uy = o[ex_], o[ey_]
        kx, ky = -o[alpha] * uy, o[alpha] * ux
        own = leg  # the row of this leg's motor
        m_name, h_name, J_name = (("m_BP", "h_BP", "J_BP") if leg == 0
                                  else ("m_CP", "h_CP", "J_CP"))
        Y[..., own, col[m_name]] = T(gBx, gBy)
        Ph = _perp_torques(o, gBx, gBy)
        PJ = _perp_torques(o, kx, ky)
        Y[..., 0, col[h_name]] = Ph[0] / L
        Y[..., 1, col[h_name]] = Ph[1] / L
        Y[..., own, col[h_name]] += (T(relx, rely) - T(gBx, gBy)) / L
        Y[..., 0, col[J_name]] = PJ[0] / (L * L)
        Y[..., 1, col[J_name]] = PJ[1] / (L * L)
        Y[..., own, col[J_name]] -= T(kx, ky) / (L * L)
    # point mass at P
    Pm = _perp_torques(o, o["ddPx"] - gx, o["ddPy"] - gy)
    Y[..., 0, col["m_P"]] = Pm[0]
    Y[..., 1, col["m_P"]] = Pm[1]
    # friction
    vs = ine.coulomb_speed
    for k, (v, c) in enumerate((("fv_A", "fc_A"), ("fv_D", "fc_D"))):
        Y[..., k, col[v]] = w[..., k] + zero
        Y[..., k, col[c]] = friction_torque(w[..., k], 0.0, 1.0, vs) + zero
    return Y

