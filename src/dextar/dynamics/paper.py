"""The paper's simplified dynamic model, as published, and its energy comparisons.

The paper (section 3) freezes the angle ``beta`` at the base of the triangle CPB at its value
``beta0`` in the middle of the motion, treats the two distal rods as one rigid triangle of mass
``2 mL`` with centre ``S = lambda P + (1 - lambda) Q`` (``Q`` the midpoint of BC), drops the
triangle's rotational energy, and obtains (40)

    T = C1 (phidot^2 + psidot^2) / 2 + phidot psidot K(phi - psi),
    K(x) = C2 cos(x + 2 beta0) + C3 cos(x + beta0) + C4 cos(x),

    C1 = (1 + 2 lambda^2 mL / m) m l^2 / (4 cos^2 beta0) + (1 - lambda^2) mL l^2 / 2 + Jl + Je
    C2 = (1 + 2 lambda^2 mL / m) m l^2 / (4 cos^2 beta0)
    C3 = mL (1 - lambda) lambda l^2 / cos beta0
    C4 = mL (1 - lambda)^2 l^2 / 2

and the torques (42)

    M1 = C1 phiddot + psiddot K + psidot^2 S(phi - psi),
    M2 = C1 psiddot + phiddot K - phidot^2 S(phi - psi),
    S(x) = C2 sin(x + 2 beta0) + C3 sin(x + beta0) + C4 sin(x).

Interpretations the garbled text forced (each checked against a derivation):

* (21) and (23): the ``d`` inside the bracket reads ``d / l`` (SPEC section 2).
* (30): the ``beta-dot`` term in the x bracket enters with a plus sign, as it follows from
  differentiating (23) (see (28)); the printed (30) shows a minus.
* ``beta0`` is the base angle at ``t = T / 2`` ("the middle position"); ``beta`` is the angle at
  B (and C) of the isosceles triangle CPB, ``cos beta = |BC| / (2 L)``.
* ``m`` is the point mass at P (end-effector plus payload); ``mL`` the mass of each distal rod;
  ``Jl`` the inertia of a proximal rod about its pivot (``ml l^2 / 3`` for a uniform rod);
  ``Je`` the rotor inertia; ``lambda = 0.5`` for uniform distal rods.
* ``T_comp`` (Fig. 6) evaluates (30) with ``phidot, psidot, betadot`` from second-order
  central finite differences of the sampled angles (the paper's "finite differences");
  ``T_approx`` evaluates (32) with the exact rates, so it isolates the frozen-``beta`` error.
* Fig. 7's translational energy is ``T_S = mL |Sdot|^2`` from (34) with the exact velocities and
  the rotational one ``T_r = JL alphadot^2 / 2`` from (37)-(38).

The model only applies to the symmetric robot (``l1 = l2``, ``L1 = L2``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._arrays import Array, as_points
from ..errors import ParameterError
from ..geometry import FiveBar
from ..kinematics import elbows
from .inertia import Inertia


@dataclass(frozen=True)
class PaperModel:
    """Constants of the paper's model (40)."""

    l: float
    L: float
    d: float
    m: float
    mL: float
    Jl: float
    Je: float
    lam: float
    beta0: float

    @property
    def C1(self) -> float:
        """``C1`` of (40) (mass times length squared)."""
        return self.C2 + (1 - self.lam**2) * self.mL * self.l**2 / 2 + self.Jl + self.Je

    @property
    def C2(self) -> float:
        """``C2`` of (40)."""
        return ((1 + 2 * self.lam**2 * self.mL / self.m) * self.m * self.l**2
                / (4 * math.cos(self.beta0) ** 2))

    @property
    def C3(self) -> float:
        """``C3`` of (40)."""
        return self.mL * (1 - self.lam) * self.lam * self.l**2 / math.cos(self.beta0)

    @property
    def C4(self) -> float:
        """``C4`` of (40)."""
        return self.mL * (1 - self.lam) ** 2 * self.l**2 / 2

    def _K_S(self, x: Array) -> tuple[Array, Array]:
        b = self.beta0
        K = self.C2 * np.cos(x + 2 * b) + self.C3 * np.cos(x + b) + self.C4 * np.cos(x)
        S = self.C2 * np.sin(x + 2 * b) + self.C3 * np.sin(x + b) + self.C4 * np.sin(x)
        return K, S

    def torques(self, q: object, dq: object, ddq: object) -> Array:
        """The paper's torques (42), shape (..., 2)."""
        q, dq, ddq = as_points(q, "q"), as_points(dq, "dq"), as_points(ddq, "ddq")
        K, S = self._K_S(q[..., 0] - q[..., 1])
        M1 = self.C1 * ddq[..., 0] + ddq[..., 1] * K + dq[..., 1] ** 2 * S
        M2 = self.C1 * ddq[..., 1] + ddq[..., 0] * K - dq[..., 0] ** 2 * S
        return np.stack([M1, M2], axis=-1)

    def energy(self, q: object, dq: object) -> Array:
        """The paper's total kinetic energy (40)."""
        q, dq = as_points(q, "q"), as_points(dq, "dq")
        K, _ = self._K_S(q[..., 0] - q[..., 1])
        return np.asarray(self.C1 * (dq[..., 0] ** 2 + dq[..., 1] ** 2) / 2
                + dq[..., 0] * dq[..., 1] * K)


def base_angle(robot: FiveBar, q: object) -> Array:
    """Angle ``beta`` at the base of the triangle CPB, ``cos beta = |BC| / (2 L)`` (22)."""
    _require_symmetric(robot)
    B, C = elbows(robot, q)
    half = 0.5 * np.linalg.norm(B - C, axis=-1) / robot.L1
    return np.asarray(np.arccos(np.clip(half, -1.0, 1.0)))


def _require_symmetric(robot: FiveBar) -> None:
    if not robot.is_symmetric:
        raise ParameterError("the paper's simplified model assumes a symmetric robot "
                             f"(l1 = l2, L1 = L2); got {robot.as_dict()}")


def paper_model_limits(robot: FiveBar, inertia: Inertia) -> str | None:
    """Why the paper's model does not apply to ``robot`` and ``inertia`` (None if it does)."""
    if not robot.is_symmetric:
        return "the robot is not symmetric (l1 = l2, L1 = L2)"
    r3, r4 = inertia.distal
    p1, p2 = inertia.proximal
    if not (math.isclose(r3.mass, r4.mass) and math.isclose(r3.com, r4.com)
            and math.isclose(p1.about_joint, p2.about_joint)
            and math.isclose(inertia.rotor[0], inertia.rotor[1])):
        return "the two legs carry different rods or motors"
    if inertia.point_mass <= 0:
        return "there is no mass at P"
    return None


def paper_model(robot: FiveBar, inertia: Inertia, beta0: float, *,
                lam: float | None = None) -> PaperModel:
    """The paper's model for ``robot`` and ``inertia`` with base angle ``beta0``.

    ``lam`` (the centre of the triangle CPB) defaults to the distal rods' centre of mass
    fraction (0.5 for uniform rods). Rotor inertias enter as ``Je`` and the proximal rods'
    inertia about their pivots as ``Jl``; gravity and friction are not part of the model.
    """
    reason = paper_model_limits(robot, inertia)
    if reason is not None:
        raise ParameterError(f"the paper's simplified model does not apply: {reason}")
    r3, p1 = inertia.distal[0], inertia.proximal[0]
    lam = r3.com / robot.L1 if lam is None else float(lam)
    return PaperModel(l=robot.l1, L=robot.L1, d=robot.d, m=inertia.point_mass, mL=r3.mass,
                      Jl=p1.about_joint, Je=inertia.rotor[0], lam=lam, beta0=float(beta0))


# --------------------------------------------------------------------------- energies
def _effector_velocity_23(robot: FiveBar, q: Array, dq: Array, beta: Array,
                          dbeta: Array) -> tuple[Array, Array]:
    """End-effector velocity from (28), the derivative of (23)."""
    l, dl = robot.l1, robot.d / robot.l1
    phi, psi = q[..., 0], q[..., 1]
    w1, w2 = dq[..., 0], dq[..., 1]
    cb = np.cos(beta)
    k = 0.5 * l / cb
    vx = -k * (w1 * np.sin(phi + beta) + w2 * np.sin(psi - beta)
               + (np.sin(phi) - np.sin(psi)) * dbeta / cb)
    vy = k * (w1 * np.cos(phi + beta) + w2 * np.cos(psi - beta)
              + (np.cos(phi) - np.cos(psi) + dl) * dbeta / cb)
    return vx, vy


def effector_position_23(robot: FiveBar, q: object) -> Array:
    """End-effector position by the paper's direct kinematics (23), with ``d/l``."""
    _require_symmetric(robot)
    q = as_points(q, "q")
    beta = base_angle(robot, q)
    l, dl = robot.l1, robot.d / robot.l1
    phi, psi = q[..., 0], q[..., 1]
    x = 0.5 * l * (np.cos(phi) + np.cos(psi)) - 0.5 * l * np.tan(beta) * (np.sin(phi) - np.sin(psi))
    y = 0.5 * l * (np.sin(phi) + np.sin(psi)) + 0.5 * l * np.tan(beta) * (
        np.cos(phi) - np.cos(psi) + dl)
    return np.stack([x, y], axis=-1)


def effector_energy_fd(robot: FiveBar, mass: float, t: Array, q: Array) -> Array:
    """``T_comp`` of Fig. 6: (30) with rates by finite differences of the sampled angles."""
    _require_symmetric(robot)
    q = as_points(q, "q")
    t = np.asarray(t, dtype=float)
    beta = base_angle(robot, q)
    order: Literal[1, 2] = 2 if len(t) >= 3 else 1  # second-order differences need 3 samples
    dq = np.asarray(np.gradient(q, t, axis=0, edge_order=order))
    dbeta = np.asarray(np.gradient(beta, t, edge_order=order))
    vx, vy = _effector_velocity_23(robot, q, dq, beta, dbeta)
    return np.asarray(0.5 * mass * (vx * vx + vy * vy))


def effector_energy_const_beta(robot: FiveBar, mass: float, beta0: float, q: object,
                               dq: object) -> Array:
    """``T_approx`` of Fig. 6: (32), the end-effector energy with ``beta`` frozen at
    ``beta0``."""
    _require_symmetric(robot)
    q, dq = as_points(q, "q"), as_points(dq, "dq")
    w1, w2 = dq[..., 0], dq[..., 1]
    c = robot.l1**2 / (4 * math.cos(beta0) ** 2)
    return np.asarray(0.5 * mass * c * (w1 * w1 + w2 * w2
                             + 2 * w1 * w2 * np.cos(q[..., 0] - q[..., 1] + 2 * beta0)))


def triangle_energies(robot: FiveBar, mL: float, JL: float, lam: float, q: object, dq: object,
                      dP: object) -> tuple[Array, Array]:
    """Fig. 7: translational ``T_S = mL |Sdot|^2`` (34) and rotational
    ``T_r = JL alphadot^2 / 2`` (37)-(38) energies of the triangle CPB (mass ``2 mL``)."""
    _require_symmetric(robot)
    q, dq, dP = as_points(q, "q"), as_points(dq, "dq"), as_points(dP, "dP")
    l = robot.l1
    c1, s1, c2, s2 = np.cos(q[..., 0]), np.sin(q[..., 0]), np.cos(q[..., 1]), np.sin(q[..., 1])
    dB = np.stack([-l * s1 * dq[..., 0], l * c1 * dq[..., 0]], axis=-1)
    dC = np.stack([-l * s2 * dq[..., 1], l * c2 * dq[..., 1]], axis=-1)
    dS = lam * dP + (1 - lam) * 0.5 * (dB + dC)
    T_S = mL * np.sum(dS * dS, axis=-1)
    B, C = elbows(robot, q)
    v, dv = B - C, dB - dC
    alpha_dot = (v[..., 0] * dv[..., 1] - v[..., 1] * dv[..., 0]) / np.sum(v * v, axis=-1)
    return T_S, 0.5 * JL * alpha_dot**2


def torque_error(exact: Array, approx: Array) -> dict[str, float]:
    """Max and RMS of ``approx - exact`` over both motors, and both relative to the peak
    exact torque."""
    err = np.asarray(approx) - np.asarray(exact)
    peak = float(np.abs(exact).max())
    mx = float(np.abs(err).max())
    rms = float(np.sqrt(np.mean(err**2)))
    return {"max": mx, "rms": rms, "peak_exact": peak,
            "max_relative": mx / peak if peak > 0 else math.inf,
            "rms_relative": rms / peak if peak > 0 else math.inf}
