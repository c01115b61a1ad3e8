"""Exact inverse dynamics of the closed five-bar chain in the coordinates ``q = (phi, psi)``.

Method (Kane's equations / virtual power). Every velocity in the mechanism is linear in
``qdot``: ``Bdot = J_B qdot``, ``Cdot = J_C qdot``, ``Pdot = J_P qdot`` with ``J_P = A^-1 B``
(see :mod:`dextar.kinematics.velocity`), and the distal rods turn at
``omega_3 = (P - B) x (Pdot - Bdot) / L1^2``. The generalised force that realises
``qddot`` is the sum over the bodies of their inertia forces (minus gravity) projected on these
partial velocities:

    tau = sum_i J_Gi^T m_i (a_Gi - g) + (d omega_i / d qdot)^T I_i alpha_i
          + rotor and friction terms.

A distal rod with centre ``G = B + lambda (P - B)`` is equivalent to the forces
``(1 - lambda) f`` at B and ``lambda f`` at P, and its rotary inertia to the couple
``k (-(P-B)_y, (P-B)_x)`` at P and its opposite at B, ``k = I alpha / L^2``; so only the
three points B, C, P carry forces and ``tau = J_B^T F_B + J_C^T F_C + J_P^T F_P + ...``.
The same quantities give the reaction forces in the passive joints by Newton-Euler, which the
tests use as an independent check of the torques.

All functions are vectorised over samples (arrays of shape (n, 2)) and processed in
cache-sized blocks; a single state may be given as floats for the integrators.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from .._arrays import Array, as_points, blocks, check_finite, cos_sin
from .._compiled import usable
from ..errors import AssemblyError, ParameterError, SingularityError
from ..geometry import FiveBar, parse_assembly_mode, parse_working_mode
from ..kinematics import DEFAULT_SINGULARITY_TOL, inverse_kinematics, joint_rates
from .friction import friction_torque
from .inertia import Inertia

try:  # the fused kernel compiled (_kernel.c), built by pip where a C compiler is
    from . import _kernel as _compiled
except ImportError:  # pragma: no cover - installed without a C compiler: the numpy kernel
    _compiled = None  # type: ignore[assignment]  # the module or None, as USE_COMPILED says

#: The compiled kernel's interface this module calls (``KERNEL_VERSION`` in _kernel.c): a
#: build of another version (an old one left in place) is not used.
KERNEL_VERSION = 4
if not usable(_compiled, KERNEL_VERSION):
    _compiled = None  # type: ignore[assignment]  # an old build: the numpy kernel instead

#: Whether :func:`inverse_dynamics` and its kin use the compiled kernel (where it was built):
#: False gives the numpy kernel (the same torques to rounding; the tests compare the two).
USE_COMPILED = _compiled is not None


@dataclass(frozen=True)
class Model:
    """A robot with its inertia, assembled in one assembly mode.

    ``tol`` is the smallest normalised distance to a parallel singularity the dynamics accept.
    """

    robot: FiveBar
    inertia: Inertia
    assembly: str | int = "up"
    tol: float = DEFAULT_SINGULARITY_TOL

    def __post_init__(self) -> None:
        parse_assembly_mode(self.assembly)
        if not (self.tol >= 0):
            raise ParameterError(f"singularity tolerance {self.tol!r} must be >= 0")


class _Np:
    """Array operations for the kernel (numpy)."""

    cos_sin = staticmethod(cos_sin)
    sqrt = staticmethod(np.sqrt)

    @staticmethod
    def clip0(x: Any) -> Any:
        return np.maximum(x, 0.0)


class _Py:
    """Scalar operations for the kernel (plain floats, for the integrators)."""

    @staticmethod
    def cos_sin(a: float) -> tuple[float, float]:
        return math.cos(a), math.sin(a)

    sqrt = staticmethod(math.sqrt)

    @staticmethod
    def clip0(x: float) -> float:
        return x if x > 0.0 else 0.0


class Pose(NamedTuple):
    """Positions of one configuration (each field an array or a float): the motor angles'
    cosines and sines, the elbows B and C, P by direct kinematics, ``P - B`` (``u``),
    ``P - C`` (``e``), ``b1, b2`` (the diagonal of ``B``), ``det A`` and its inverse, and the
    circle-intersection discriminant ``wsq`` over ``del2 = |B - C|^2`` (for the checks)."""

    c1: Any
    s1: Any
    c2: Any
    s2: Any
    Bx: Any
    By: Any
    Cx: Any
    Cy: Any
    Px: Any
    Py: Any
    ux: Any
    uy: Any
    ex: Any
    ey: Any
    b1: Any
    b2: Any
    det: Any
    idet: Any
    wsq: Any
    del2: Any


class Rates(NamedTuple):
    """Velocities of B, C, P and the velocity-product terms of ``A Pddot - B qddot = b``."""

    dPx: Any
    dPy: Any
    dBx: Any
    dBy: Any
    dCx: Any
    dCy: Any
    bias1: Any
    bias2: Any


class Loads(NamedTuple):
    """Accelerations of B, C, P, the inertia forces of the distal rods and of the point mass
    (gravity included), the distal rods' angular accelerations and the motor torques."""

    ddPx: Any
    ddPy: Any
    ddBx: Any
    ddBy: Any
    ddCx: Any
    ddCy: Any
    f3x: Any
    f3y: Any
    f4x: Any
    f4y: Any
    fPx: Any
    fPy: Any
    alpha3: Any
    alpha4: Any
    tau1: Any
    tau2: Any


def _pose(model: Model, q1: Any, q2: Any, xp: Any) -> Pose:
    """Direct kinematics and the velocity-relation matrices, once per configuration."""
    r = model.robot
    l1, l2, L1, L2 = r.l1, r.l2, r.L1, r.L2
    half = 0.5 * r.d
    c1, s1 = xp.cos_sin(q1)
    c2, s2 = xp.cos_sin(q2)
    Bx, By = half + l1 * c1, l1 * s1
    Cx, Cy = l2 * c2 - half, l2 * s2
    # P from the circles (B, L1) and (C, L2)
    vx, vy = Bx - Cx, By - Cy
    del2 = vx * vx + vy * vy
    k = 0.5 * (del2 + (L2 * L2 - L1 * L1))
    wsq = (L2 * L2) * del2 - k * k
    h = xp.sqrt(xp.clip0(wsq))
    if parse_assembly_mode(model.assembly) < 0:
        h = -h
    inv = 1.0 / del2
    Px = Cx + (k * vx - h * vy) * inv
    Py = Cy + (k * vy + h * vx) * inv
    ux, uy = Px - Bx, Py - By
    ex, ey = Px - Cx, Py - Cy
    b1 = l1 * (c1 * uy - s1 * ux)
    b2 = l2 * (c2 * ey - s2 * ex)
    det = ux * ey - uy * ex
    return Pose(c1, s1, c2, s2, Bx, By, Cx, Cy, Px, Py, ux, uy, ex, ey, b1, b2, det, 1.0 / det,
                wsq, del2)


def _rates(model: Model, p: Pose, w1: Any, w2: Any) -> Rates:
    """Velocities for the joint rates ``w1, w2`` (``Pdot = A^-1 B qdot``)."""
    l1, l2 = model.robot.l1, model.robot.l2
    r1, r2 = p.b1 * w1, p.b2 * w2
    dPx = (p.ey * r1 - p.uy * r2) * p.idet
    dPy = (p.ux * r2 - p.ex * r1) * p.idet
    dBx, dBy = -l1 * p.s1 * w1, l1 * p.c1 * w1
    dCx, dCy = -l2 * p.s2 * w2, l2 * p.c2 * w2
    gx1, gy1 = dPx - dBx, dPy - dBy
    gx2, gy2 = dPx - dCx, dPy - dCy
    bias1 = -(gx1 * gx1 + gy1 * gy1) - l1 * w1 * w1 * (p.ux * p.c1 + p.uy * p.s1)
    bias2 = -(gx2 * gx2 + gy2 * gy2) - l2 * w2 * w2 * (p.ex * p.c2 + p.ey * p.s2)
    return Rates(dPx, dPy, dBx, dBy, dCx, dCy, bias1, bias2)


def _loads(model: Model, p: Pose, v: Rates, w1: Any, w2: Any, a1: Any, a2: Any, *,
           gravity: bool, friction: bool) -> Loads:
    """Accelerations, inertia forces and the motor torques (Kane's equations)."""
    r, ine = model.robot, model.inertia
    l1, l2, L1, L2 = r.l1, r.l2, r.L1, r.L2
    r1 = p.b1 * a1 + v.bias1
    r2 = p.b2 * a2 + v.bias2
    ddPx = (p.ey * r1 - p.uy * r2) * p.idet
    ddPy = (p.ux * r2 - p.ex * r1) * p.idet
    ww1, ww2 = w1 * w1, w2 * w2
    ddBx, ddBy = -l1 * (p.s1 * a1 + p.c1 * ww1), l1 * (p.c1 * a1 - p.s1 * ww1)
    ddCx, ddCy = -l2 * (p.s2 * a2 + p.c2 * ww2), l2 * (p.c2 * a2 - p.s2 * ww2)
    gx, gy = ine.gravity if gravity else (0.0, 0.0)
    rod1, rod2 = ine.proximal
    rod3, rod4 = ine.distal
    lam3, lam4 = rod3.com / L1, rod4.com / L2
    # distal rod 3 (B -> P)
    f3x = rod3.mass * (ddBx + lam3 * (ddPx - ddBx) - gx)
    f3y = rod3.mass * (ddBy + lam3 * (ddPy - ddBy) - gy)
    alpha3 = (p.ux * (ddPy - ddBy) - p.uy * (ddPx - ddBx)) / (L1 * L1)
    k3 = rod3.inertia * alpha3 / (L1 * L1)
    # distal rod 4 (C -> P)
    f4x = rod4.mass * (ddCx + lam4 * (ddPx - ddCx) - gx)
    f4y = rod4.mass * (ddCy + lam4 * (ddPy - ddCy) - gy)
    alpha4 = (p.ex * (ddPy - ddCy) - p.ey * (ddPx - ddCx)) / (L2 * L2)
    k4 = rod4.inertia * alpha4 / (L2 * L2)
    mP = ine.point_mass
    fPx, fPy = mP * (ddPx - gx), mP * (ddPy - gy)
    FPx = fPx + lam3 * f3x + lam4 * f4x - k3 * p.uy - k4 * p.ey
    FPy = fPy + lam3 * f3y + lam4 * f4y + k3 * p.ux + k4 * p.ex
    FBx, FBy = (1.0 - lam3) * f3x + k3 * p.uy, (1.0 - lam3) * f3y - k3 * p.ux
    FCx, FCy = (1.0 - lam4) * f4x + k4 * p.ey, (1.0 - lam4) * f4y - k4 * p.ex
    J1 = ine.rotor[0] + rod1.about_joint
    J2 = ine.rotor[1] + rod2.about_joint
    tau1 = (l1 * (p.c1 * FBy - p.s1 * FBx) + p.b1 * (p.ey * FPx - p.ex * FPy) * p.idet
            + J1 * a1 - rod1.mass * rod1.com * (p.c1 * gy - p.s1 * gx))
    tau2 = (l2 * (p.c2 * FCy - p.s2 * FCx) + p.b2 * (p.ux * FPy - p.uy * FPx) * p.idet
            + J2 * a2 - rod2.mass * rod2.com * (p.c2 * gy - p.s2 * gx))
    if friction:
        tau1 = tau1 + friction_torque(w1, ine.viscous[0], ine.coulomb[0], ine.coulomb_speed)
        tau2 = tau2 + friction_torque(w2, ine.viscous[1], ine.coulomb[1], ine.coulomb_speed)
    return Loads(ddPx, ddPy, ddBx, ddBy, ddCx, ddCy, f3x, f3y, f4x, f4y, fPx, fPy, alpha3,
                 alpha4, tau1, tau2)


def _check_state(model: Model, pose: Pose, q: Array, offset: int,
                 t: Array | None) -> None:
    r = model.robot
    same = ~(pose.del2 > 0.0)  # elbows B and C at one point: P anywhere on a circle
    bad_fk = pose.wsq < -1e-12 * (r.L2 * r.L2) * pose.del2
    dist = np.abs(pose.det) / (r.L1 * r.L2)
    bad_sing = dist < model.tol
    for bad, kind in ((same, "same"), (bad_fk, "fk"), (bad_sing, "sing")):
        if np.any(bad):
            j = int(np.flatnonzero(bad)[0])
            i = offset + j
            when = f"at t = {t[i]:.6g} (sample {i})" if t is not None else f"at sample {i}"
            qd = np.degrees(q[i])
            if kind == "same":
                raise AssemblyError(f"the elbows B and C coincide {when}: q = ({qd[0]:.6g}, "
                                    f"{qd[1]:.6g}) deg; the end-effector's position is not "
                                    "determined")
            if kind == "fk":
                raise AssemblyError(f"distal rods cannot meet {when}: q = ({qd[0]:.6g}, "
                                    f"{qd[1]:.6g}) deg")
            raise SingularityError(
                f"parallel (type 2) singularity {when}: q = ({qd[0]:.6g}, {qd[1]:.6g}) deg, "
                f"normalised distance {dist[j]:.3g} below tolerance {model.tol:g}; the torques "
                "would be unbounded")


def _run(model: Model, q: object, dq: object, ddq: object, *, gravity: bool, friction: bool,
         t: object = None, keys: tuple[str, ...] = ("tau1", "tau2")) -> dict[str, Array]:
    """Evaluate the kernel on samples (..., 2) in cache-sized blocks: the pose once per
    sample, then the rates and loads; returns the fields ``keys`` of :class:`Pose`,
    :class:`Rates` and :class:`Loads`, each of the leading shape."""
    q0 = as_points(q, "q")
    shape = q0.shape[:-1]
    qf = q0.reshape(-1, 2)
    dqf = as_points(dq, "dq").reshape(-1, 2)
    ddqf = as_points(ddq, "ddq").reshape(-1, 2)
    if not (len(dqf) == len(ddqf) == len(qf)):
        raise ParameterError(f"q, dq, ddq must have the same number of samples, got "
                             f"{len(qf)}, {len(dqf)}, {len(ddqf)}")
    tt = None if t is None else np.asarray(t, dtype=float).reshape(-1)
    out = {k: np.empty(len(qf)) for k in keys}
    for blk in blocks(len(qf)):
        w1, w2, a1, a2 = dqf[blk, 0], dqf[blk, 1], ddqf[blk, 0], ddqf[blk, 1]
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # checked below
            pose = _pose(model, qf[blk, 0], qf[blk, 1], _Np)
            rates = _rates(model, pose, w1, w2)
            loads = _loads(model, pose, rates, w1, w2, a1, a2, gravity=gravity,
                           friction=friction)
        _check_state(model, pose, qf, blk.start, tt)
        for k in keys:
            src = loads if k in Loads._fields else rates if k in Rates._fields else pose
            out[k][blk] = getattr(src, k)
    return {k: v.reshape(shape) for k, v in out.items()}


# --- the fused torque kernel ---------------------------------------------------------------
#
# The same Kane's equations, rearranged so that numpy makes as few passes over the samples as
# it can: about 80 ufunc calls per block, each writing into a preallocated, 64-byte aligned
# buffer, the two legs side by side in arrays of shape (2, block) so that one call serves
# both. Three identities shorten it:
#
# * a distal rod (mass m, centre at lam L from its elbow, inertia I about its centre) is
#   dynamically the point masses m (1 - lam) at its elbow and m lam at P plus the rotary inertia
#   ``I_r = I - m lam (1 - lam) L^2`` (equimomental); an elbow mass turns with its proximal rod,
#   so it only adds to that motor's inertia and gravity torque, and the masses at P are one;
# * with ``a`` the proximal rod (motor to elbow) and ``U`` the distal rod (elbow to P) of a leg,
#   ``b = a x U`` and ``c = a . U``; ``ue = u . e = (L1^2 + L2^2 - |B - C|^2) / 2`` and
#   ``det = u x e = -sign |B - C|^2 hh`` (``hh`` the half-chord over ``|B - C|^2``);
# * ``U x Pdot = T (b qdot)`` with ``T x = (L1^2 x2 - ue x1, ue x2 - L2^2 x1) / det``, so the
#   rods turn at ``omega L^2 = T (b qdot) - c qdot``; the same ``T`` gives ``U x Pddot`` from
#   ``A Pddot = b qddot + bias``, and ``A^-T F = (-(e x F), u x F) / det`` for a force at P.
#
# Then ``k = I_r alpha / L^2``, ``alpha L^2 = U x Pddot - c qddot - b qdot^2``, and
#   ``tau = J qddot - G (a x g) + b lam - k c + friction``,
#   ``lam = (-MP e x (Pddot - g) - ue k1 - L2^2 k2,  MP u x (Pddot - g) + L1^2 k1 + ue k2) / det``.
# tests/dynamics/test_exact.py checks it against a straightforward per-body evaluation.

#: Samples per block of the fused kernel: its ~25 buffers of 8192 samples stay in a 2 MiB L2
#: cache while the ~0.5 us a ufunc call costs is spread over enough samples
#: (benchmarks/bench_dynamics.py times 2048 to 32768).
FUSED_BLOCK = 8192

_mul, _add, _sub, _div = np.multiply, np.add, np.subtract, np.divide


@dataclass(frozen=True)
class _Lumped:
    """The model's constants as the fused kernel uses them: per leg an array of shape (2, 1)
    (or a float when both legs agree); ``None`` for a term that is zero."""

    l: Any  # proximal lengths
    two_l: Any
    d: float  # distance between the motors
    Lsq: Any  # L1^2, L2^2
    iLsq: Any
    L2sq: float
    ue0: float  # (L1^2 + L2^2) / 2
    cst: float  # (L2^2 - L1^2) / 2
    sign: int  # assembly mode
    J: Any  # motor-side inertia: rotor, proximal rod and elbow mass
    MP: float  # every mass at P
    cK: Any  # I_r / L^4
    Gax: Any  # gravity torque = Gax a_x + Gay a_y
    Gay: Any
    MPgx: float  # MP g
    MPgy: float
    viscous: Any
    coulomb: Any
    inv_vs: float


def _lumped(model: Model, gravity: bool, friction: bool) -> _Lumped:
    r, ine = model.robot, model.inertia
    l1, l2, L1, L2 = r.l1, r.l2, r.L1, r.L2
    rod1, rod2 = ine.proximal
    rod3, rod4 = ine.distal
    lam3, lam4 = rod3.com / L1, rod4.com / L2
    mE = (rod3.mass * (1.0 - lam3), rod4.mass * (1.0 - lam4))

    def leg(v1: float, v2: float) -> Any:
        # a float broadcasts faster than a (2, 1) array (no 2-D loop): the common case
        return v1 if v1 == v2 else np.array([[v1], [v2]])

    gx, gy = ine.gravity if gravity else (0.0, 0.0)
    G = leg((rod1.mass * rod1.com + mE[0] * l1) / l1, (rod2.mass * rod2.com + mE[1] * l2) / l2)
    MP = ine.point_mass + lam3 * rod3.mass + lam4 * rod4.mass
    Ir = (rod3.inertia - rod3.mass * lam3 * (1.0 - lam3) * L1 * L1,
          rod4.inertia - rod4.mass * lam4 * (1.0 - lam4) * L2 * L2)
    fric = friction and ine.has_friction
    lv = leg(l1, l2)
    return _Lumped(
        l=lv, two_l=2.0 * lv, d=r.d, Lsq=leg(L1 * L1, L2 * L2),
        iLsq=leg(1.0 / (L1 * L1), 1.0 / (L2 * L2)), L2sq=L2 * L2,
        ue0=0.5 * (L1 * L1 + L2 * L2), cst=0.5 * (L2 * L2 - L1 * L1),
        sign=parse_assembly_mode(model.assembly),
        J=leg(ine.rotor[0] + rod1.about_joint + mE[0] * l1 * l1,
              ine.rotor[1] + rod2.about_joint + mE[1] * l2 * l2),
        MP=MP, cK=leg(Ir[0] / L1**4, Ir[1] / L2**4),
        Gax=-G * gy if gy else None, Gay=G * gx if gx else None, MPgx=MP * gx, MPgy=MP * gy,
        viscous=leg(*ine.viscous) if fric else None,
        coulomb=leg(*ine.coulomb) if fric else None, inv_vs=1.0 / ine.coulomb_speed)


class _Buffers:
    """Scratch arrays for blocks of up to ``size`` samples, each starting on a 64-byte
    boundary (unaligned operands cost numpy's SIMD loops about 2x): ``views(b)`` gives
    ``PAIRS`` contiguous arrays of shape (2, b) and ``SINGLES`` of shape (b,)."""

    PAIRS, SINGLES = 15, 8

    def __init__(self, size: int) -> None:
        self.stride = -(-size // 8) * 8
        total = (2 * self.PAIRS + self.SINGLES) * self.stride
        raw = np.empty(total + 8)
        start = (-raw.ctypes.data) % 64 // 8
        self.raw = raw[start:start + total]
        self._views: dict[int, tuple[list[Array], list[Array]]] = {}

    def views(self, b: int) -> tuple[list[Array], list[Array]]:
        if b not in self._views:
            s, base = self.stride, 2 * self.PAIRS * self.stride
            self._views[b] = (
                [self.raw[2 * k * s:2 * k * s + 2 * b].reshape(2, b) for k in range(self.PAIRS)],
                [self.raw[base + k * s:base + k * s + b] for k in range(self.SINGLES)])
        return self._views[b]


def _fused_block(c: _Lumped, bufs: tuple[list[Array], list[Array]], q: Array, dq: Array,
                 ddq: Array, out: Array) -> tuple[float, float]:
    """Motor torques of one block ``q, dq, ddq`` (b, 2) into ``out`` (b, 2). Returns the
    smallest ``(h / |B - C|^2)^2`` (negative when the rods cannot meet) and the largest
    ``1 / |det A|`` of the block, for the checks."""
    (T, T2, AX, AY, UX, UY, Bb, CU, W, R, X, Acc, Y, K, SD), \
        (vx, vy, s1, s2, idel, hh, ue, s3) = bufs
    ux, ex, uy, ey = UX[0], UX[1], UY[0], UY[1]
    # proximal rods a = l (cos q, sin q) through t = tan(q / 2)
    _mul(q.T, 0.5, T)
    np.tan(T, T)
    _mul(T, T, T2)
    _add(T2, 1.0, T2)
    _div(c.two_l, T2, T2)
    _sub(T2, c.l, AX)
    _mul(T2, T, AY)
    # v = B - C, e = P - C = kk v + sign hh perp(v), u = P - B = e - v
    _sub(AX[0], AX[1], vx)
    _add(vx, c.d, vx)
    _sub(AY[0], AY[1], vy)
    _mul(vx, vx, s1)
    _mul(vy, vy, s2)
    _add(s1, s2, s1)
    _mul(s1, 0.5, ue)
    _sub(c.ue0, ue, ue)
    _div(1.0, s1, idel)
    kk: Any = 0.5
    _mul(idel, c.L2sq, hh)
    if c.cst == 0.0:
        _sub(hh, 0.25, hh)
    else:
        kk = s2
        _mul(idel, c.cst, kk)
        _add(kk, 0.5, kk)
        _mul(kk, kk, s3)
        _sub(hh, s3, hh)
    disc = float(hh.min()) if hh.size else 0.0
    if disc < 0.0:
        np.maximum(hh, 0.0, out=hh)
    np.sqrt(hh, hh)
    idet, nidet = SD[0], SD[1]
    _div(idel, hh, idet)  # 1 / |det|
    worst = float(idet.max()) if hh.size else 0.0
    if c.sign > 0:
        np.negative(idet, idet)
    np.negative(idet, nidet)
    _mul(hh, vy, s3)
    _mul(vx, kk, ex)
    (_sub if c.sign > 0 else _add)(ex, s3, ex)
    _mul(hh, vx, s3)
    _mul(vy, kk, ey)
    (_add if c.sign > 0 else _sub)(ey, s3, ey)
    _sub(ex, vx, ux)
    _sub(ey, vy, uy)
    _mul(AX, UY, Bb)  # b = a x U
    _mul(AY, UX, T)
    _sub(Bb, T, Bb)
    _mul(AX, UX, CU)  # c = a . U
    _mul(AY, UY, T)
    _add(CU, T, CU)
    # rates: omega L^2 = T (b qdot) - c qdot, bias = -omega^2 L^2 - qdot^2 c
    np.copyto(W, dq.T)
    _mul(Bb, W, R)
    _mul(c.Lsq, R[::-1], X)
    _mul(ue, R, T)
    _sub(X, T, X)
    _mul(X, SD, X)
    _mul(W, CU, T)
    _sub(X, T, X)
    _mul(W, T, T)
    _mul(X, X, X)
    _mul(X, c.iLsq, X)
    _add(X, T, X)  # -bias
    # accelerations: rr = b qddot + bias = A Pddot, Y = U x Pddot = T rr
    np.copyto(Acc, ddq.T)
    _mul(Bb, Acc, T2)
    _sub(T2, X, T2)
    _mul(c.Lsq, T2[::-1], Y)
    _mul(ue, T2, T)
    _sub(Y, T, Y)
    _mul(Y, SD, Y)
    # the rods' couples k = I_r alpha / L^2 with alpha L^2 = Y - c qddot - b qdot^2
    _mul(Acc, CU, K)
    _sub(Y, K, K)
    _mul(W, R, T)
    _sub(K, T, K)
    _mul(K, c.cK, K)
    # MP (U x Pddot - U x g) + (L1^2 k1, L2^2 k2) + ue (k2, k1), then over det: lam reversed
    _mul(Y, c.MP, Y)
    if c.MPgy:
        _mul(UX, c.MPgy, T)
        _sub(Y, T, Y)
    if c.MPgx:
        _mul(UY, c.MPgx, T)
        _add(Y, T, Y)
    _mul(c.Lsq, K, T)
    _add(Y, T, Y)
    _mul(ue, K[::-1], T)
    _add(Y, T, Y)
    _mul(Y, SD, Y)
    # tau = b lam - k c + J qddot + gravity + friction, the last sum into the output
    tau = T2
    _mul(Bb, Y[::-1], tau)
    _mul(K, CU, T)
    _sub(tau, T, tau)
    _mul(Acc, c.J, T)
    for coef, arm in ((c.Gax, AX), (c.Gay, AY)):
        if coef is not None:
            _add(tau, T, tau)
            _mul(arm, coef, T)
    if c.viscous is not None and c.coulomb is not None:
        _add(tau, T, tau)
        _mul(W, c.viscous, T)
        _add(tau, T, tau)
        _mul(W, c.inv_vs, T)
        np.tanh(T, T)
        _mul(T, c.coulomb, T)
    _add(tau[0], T[0], out[:, 0])
    _add(tau[1], T[1], out[:, 1])
    return disc, worst


def _torques(model: Model, q: object, dq: object, ddq: object, *, gravity: bool,
             friction: bool, t: object = None, block: int = FUSED_BLOCK) -> Array:
    """Motor torques (..., 2) by the fused kernel (compiled where it was built, else numpy
    in blocks of ``block`` samples), checked like :func:`_run`."""
    kernel = _compiled if USE_COMPILED else None  # (it checks the inputs as it reads)
    inputs = [as_points(x, name, finite=kernel is None)
              for x, name in ((q, "q"), (dq, "dq"), (ddq, "ddq"))]
    shape = inputs[0].shape[:-1]
    qf, dqf, ddqf = (x.reshape(-1, 2) for x in inputs)
    n = len(qf)
    if not (len(dqf) == len(ddqf) == n):
        raise ParameterError(f"q, dq, ddq must have the same number of samples, got "
                             f"{n}, {len(dqf)}, {len(ddqf)}")
    c = _lumped(model, gravity, friction)
    sing_cap = _singularity_cap(model)
    tt = None if t is None else np.asarray(t, dtype=float).reshape(-1)
    out = np.empty((n, 2))

    def check(disc: float, worst: float, blk: slice) -> None:
        if not _clear(disc, worst, sing_cap):
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                pose = _pose(model, qf[blk, 0], qf[blk, 1], _Np)
            _check_state(model, pose, qf, blk.start, tt)

    if kernel is not None:
        disc, worst, finite = kernel.torques(
            _kernel_constants(c), np.ascontiguousarray(qf), np.ascontiguousarray(dqf),
            np.ascontiguousarray(ddqf), out)
        if not finite:  # named here
            for x, name in zip(inputs, ("q", "dq", "ddq"), strict=True):
                check_finite(x, name)
        check(disc, worst, slice(0, n))
        return out.reshape(shape + (2,))
    bufs = _Buffers(min(block, max(n, 1)))
    for blk in blocks(n, block):
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # checked below
            disc, worst = _fused_block(c, bufs.views(blk.stop - blk.start), qf[blk], dqf[blk],
                                       ddqf[blk], out[blk])
        check(disc, worst, blk)
    return out.reshape(shape + (2,))


def _singularity_cap(model: Model) -> float:
    """The largest ``1 / |det A|`` the kernels' extremes may reach before the named checks
    run (:func:`_clear`): a hair inside ``1 / (tol L1 L2)``."""
    r = model.robot
    return (1.0 / (model.tol * r.L1 * r.L2) if model.tol > 0 else np.inf) * (1.0 - 1e-9)


def _clear(disc: float, worst: float, sing_cap: float) -> bool:
    """Whether a kernel's extremes leave no sample to name: rods that meet (a discriminant
    not negative) and ``1 / |det|`` below the cap; false for a NaN (elbows that coincide),
    as the comparisons are written."""
    return disc >= 0.0 and worst < sing_cap


def _kernel_constants(c: _Lumped) -> Array:
    """The constants of the compiled kernel, in the order of its ``C_*`` indices."""
    def pair(v: Any) -> tuple[float, float]:  # None, a float or a leg's (2, 1) pair
        if v is None:
            return 0.0, 0.0
        if isinstance(v, np.ndarray):
            return float(v[0, 0]), float(v[1, 0])
        return float(v), float(v)

    fric = c.viscous is not None and c.coulomb is not None
    return np.array([*pair(c.l), c.d, *pair(c.Lsq), *pair(c.iLsq), c.L2sq, c.ue0, c.cst,
                     float(c.sign), *pair(c.J), c.MP, *pair(c.cK), *pair(c.Gax), *pair(c.Gay),
                     c.MPgx, c.MPgy, *pair(c.viscous), *pair(c.coulomb), c.inv_vs,
                     1.0 if fric else 0.0])


def inverse_dynamics(model: Model, q: object, dq: object, ddq: object, *,
                     t: object = None) -> Array:
    """Motor torques ``tau = M(q) qddot + c(q, qdot) + g(q) + friction``.

    Parameters
    ----------
    q, dq, ddq : array_like, shape (..., 2)
        Actuator angles, rates and accelerations.
    t : array_like, optional
        Sample times, only to name the time in an error.

    Returns
    -------
    tau : ndarray, shape (..., 2)

    Raises
    ------
    SingularityError
        Within ``model.tol`` of a parallel singularity (names the sample, time and q).
    """
    return _torques(model, q, dq, ddq, gravity=True, friction=True, t=t)


def task_inverse_dynamics(model: Model, mode: str, points: object, dpoints: object,
                          ddpoints: object) -> tuple[Array, Array, Array]:
    """The joint rates, accelerations and motor torques of an end-effector motion.

    The same, to rounding, as :func:`dextar.kinematics.inverse_kinematics` in working mode
    ``mode``, :func:`dextar.kinematics.joint_rates` (serial singularities not refused) and
    :func:`inverse_dynamics` in turn, in one pass of the compiled kernel where it was built
    (the motor angles' cosines and sines from the elbows, no angle computed). Where it was
    not, or where a sample is out of reach, at a serial singularity to rounding, not finite
    or too near a parallel singularity, those three run in turn: the same results and the
    same errors, naming the sample.

    Parameters
    ----------
    points, dpoints, ddpoints : array_like, shape (..., 2), the same shape
        The end-effector's positions, velocities and accelerations.

    Returns
    -------
    dq, ddq, tau : ndarray, shape (..., 2)
    """
    P = as_points(points, "points")
    dP, ddP = (as_points(x, name, finite=False) for x, name in
               ((dpoints, "dpoints"), (ddpoints, "ddpoints")))
    if not (P.shape == dP.shape == ddP.shape):
        raise ParameterError(f"points, dpoints, ddpoints must have the same shape, got "
                             f"{P.shape}, {dP.shape}, {ddP.shape}")
    if USE_COMPILED:
        r = model.robot
        s1, s2 = parse_working_mode(mode)
        Pc, dPc, ddPc = (np.ascontiguousarray(x.reshape(-1, 2)) for x in (P, dP, ddP))
        dq, ddq, tau = np.empty(Pc.shape), np.empty(Pc.shape), np.empty(Pc.shape)
        bad, disc, worst, finite = _compiled.task_torques(
            _kernel_constants(_lumped(model, True, True)), (float(s1), float(s2), r.L1, r.L2),
            Pc, dPc, ddPc, dq, ddq, tau)
        if bad < 0 and finite and _clear(disc, worst, _singularity_cap(model)):
            return dq.reshape(P.shape), ddq.reshape(P.shape), tau.reshape(P.shape)
    q = inverse_kinematics(model.robot, P, mode)
    dq, ddq = joint_rates(model.robot, q, P, dP, ddP, tol=0.0)
    return dq, ddq, inverse_dynamics(model, q, dq, ddq)


def mass_matrix(model: Model, q: object) -> Array:
    """The inertia matrix ``M(q)``, shape (..., 2, 2), symmetric positive definite: its two
    columns are the torques of unit accelerations at rest without gravity or friction, both
    in one pass of the fused torque kernel (compiled where it was built), checked as
    :func:`inverse_dynamics` is."""
    q0 = as_points(q, "q")
    qf = q0.reshape(-1, 2)
    n = len(qf)
    unit = np.zeros((2 * n, 2))
    unit[:n, 0] = unit[n:, 1] = 1.0
    cols = _torques(model, np.concatenate([qf, qf]), np.zeros((2 * n, 2)), unit,
                    gravity=False, friction=False)
    M = np.stack([cols[:n], cols[n:]], axis=-1)  # M[i, :, k] = column k
    return M.reshape(q0.shape[:-1] + (2, 2))


def accelerations(model: Model, q: object, dq: object, tau: object, *,
                  t: object = None) -> Array:
    """The forward dynamics at states: ``qddot = M(q)^-1 (tau - h(q, qdot))``, shape
    (..., 2), with ``h = c + g + friction`` (:func:`inverse_dynamics` at zero acceleration)
    and ``M`` from :func:`mass_matrix`: three passes of the fused kernel in two calls, for
    any number of states (the forward dynamics' accelerations, the replay's windows).

    Raises
    ------
    SingularityError
        Within ``model.tol`` of a parallel singularity (names the sample, and the time when
        ``t`` is given).
    """
    qa = as_points(q, "q")
    h = inverse_dynamics(model, qa, dq, np.zeros_like(qa), t=t)
    r = np.asarray(tau, dtype=float) - h
    M = mass_matrix(model, qa)
    # the 2x2 systems by Cramer's rule (M is positive definite away from the singularities
    # refused above): a third of numpy's batched solve's time on 2000 states
    a, b, c, d = M[..., 0, 0], M[..., 0, 1], M[..., 1, 0], M[..., 1, 1]
    det = a * d - b * c
    return np.stack([(d * r[..., 0] - b * r[..., 1]) / det,
                     (a * r[..., 1] - c * r[..., 0]) / det], axis=-1)


def path_dynamics(model: Model, q: Array, dq_ds: Array, ddq_ds: Array
                  ) -> tuple[Array, Array, Array]:
    """The dynamics along a path ``q(s)``: ``a = M(q) q'``, ``b = M(q) q'' + c(q, q')`` and
    the gravity torques ``g(q)``, each (n, 2), so that ``tau = a sddot + b sdot^2 + g``
    (friction aside) for ``q' = dq_ds``, ``q'' = ddq_ds`` (each (n, 2)): three passes of the
    fused torque kernel (compiled where it was built), checked as :func:`inverse_dynamics`
    is."""
    qf, w, v = (as_points(x, name) for x, name in ((q, "q"), (dq_ds, "dq_ds"),
                                                  (ddq_ds, "ddq_ds")))
    zero = np.zeros_like(w)
    return (_torques(model, qf, zero, w, gravity=False, friction=False),
            _torques(model, qf, w, v, gravity=False, friction=False),
            _torques(model, qf, zero, zero, gravity=True, friction=False))


def bias_forces(model: Model, q: object, dq: object) -> Array:
    """Velocity-product torques ``c(q, qdot)`` (Coriolis and centrifugal), shape (..., 2)."""
    q = as_points(q, "q")
    return _torques(model, q, dq, np.zeros_like(q), gravity=False, friction=False)


def gravity_torques(model: Model, q: object) -> Array:
    """Gravity torques ``g(q)``, shape (..., 2) (what the motors must hold at rest)."""
    q = as_points(q, "q")
    z = np.zeros_like(q)
    return _torques(model, q, z, z, gravity=True, friction=False)


def kinetic_energy(model: Model, q: object, dq: object) -> Array:
    """Exact kinetic energy of the whole mechanism (rods, rotors, point mass at P)."""
    q = as_points(q, "q")
    keys = ("dPx", "dPy", "dBx", "dBy", "dCx", "dCy", "ux", "uy", "ex", "ey")
    o = _run(model, q, dq, np.zeros_like(q), gravity=False, friction=False, keys=keys)
    dq = as_points(dq, "dq")
    ine, r = model.inertia, model.robot
    rod1, rod2 = ine.proximal
    rod3, rod4 = ine.distal
    T = 0.5 * (ine.rotor[0] + rod1.about_joint) * dq[..., 0] ** 2
    T += 0.5 * (ine.rotor[1] + rod2.about_joint) * dq[..., 1] ** 2
    T += 0.5 * ine.point_mass * (o["dPx"] ** 2 + o["dPy"] ** 2)
    for rod, L, (bx, by), (px, py) in (
            (rod3, r.L1, ("dBx", "dBy"), ("ux", "uy")), (rod4, r.L2, ("dCx", "dCy"), ("ex", "ey"))):
        lam = rod.com / L
        vx = o[bx] + lam * (o["dPx"] - o[bx])
        vy = o[by] + lam * (o["dPy"] - o[by])
        omega = (o[px] * (o["dPy"] - o[by]) - o[py] * (o["dPx"] - o[bx])) / (L * L)
        T += 0.5 * rod.mass * (vx * vx + vy * vy) + 0.5 * rod.inertia * omega * omega
    return T


@dataclass(frozen=True)
class Reactions:
    """Forces in the passive joints, each of shape (..., 2).

    Attributes
    ----------
    B, C : ndarray
        Force of the proximal rod on the distal rod at the elbow (AB on BP at B, DC on CP at C).
    P1, P2 : ndarray
        Force of each distal rod (BP, CP) on the end-effector at P.
    """

    B: Array
    C: Array
    P1: Array
    P2: Array


def joint_reactions(model: Model, q: object, dq: object, ddq: object) -> Reactions:
    """Reaction forces in the passive joints B, C and P by Newton-Euler on the distal rods
    and the end-effector (for sizing bearings)."""
    keys = ("f3x", "f3y", "f4x", "f4y", "fPx", "fPy", "ux", "uy", "ex", "ey", "alpha3",
            "alpha4", "det")
    o = _run(model, q, dq, ddq, gravity=True, friction=False, keys=keys)
    r, ine = model.robot, model.inertia
    rod3, rod4 = ine.distal
    L1, L2 = r.L1, r.L2
    lam3, lam4 = rod3.com / L1, rod4.com / L2
    ux, uy, ex, ey = o["ux"], o["uy"], o["ex"], o["ey"]
    # normal components from the moment balance of each distal rod about its elbow
    t3 = -(lam3 * (ux * o["f3y"] - uy * o["f3x"]) + rod3.inertia * o["alpha3"]) / L1
    t4 = -(lam4 * (ex * o["f4y"] - ey * o["f4x"]) + rod4.inertia * o["alpha4"]) / L2
    wx = o["fPx"] - t3 * (-uy / L1) - t4 * (-ey / L2)
    wy = o["fPy"] - t3 * (ux / L1) - t4 * (ex / L2)
    a3 = L1 * (wx * ey - wy * ex) / o["det"]
    a4 = L2 * (ux * wy - uy * wx) / o["det"]
    P1 = np.stack([(a3 * ux - t3 * uy) / L1, (a3 * uy + t3 * ux) / L1], axis=-1)
    P2 = np.stack([(a4 * ex - t4 * ey) / L2, (a4 * ey + t4 * ex) / L2], axis=-1)
    B = np.stack([o["f3x"], o["f3y"]], axis=-1) + P1
    C = np.stack([o["f4x"], o["f4y"]], axis=-1) + P2
    return Reactions(B, C, P1, P2)


def state_dynamics(model: Model, q: Any, dq: Any) -> tuple[Array, Array]:
    """``M(q)`` (2x2) and ``h(q, qdot) = c + g + friction`` (2,) at one state, on plain floats
    (fast enough to call from an ODE integrator): the pose is computed once."""
    q1, q2 = float(q[0]), float(q[1])
    w1, w2 = float(dq[0]), float(dq[1])
    pose = _pose(model, q1, q2, _Py)
    dist = abs(pose.det) / (model.robot.L1 * model.robot.L2)
    if pose.wsq < 0 or dist < model.tol:
        raise SingularityError(
            f"parallel (type 2) singularity: q = ({math.degrees(q1):.6g}, "
            f"{math.degrees(q2):.6g}) deg, normalised distance {dist:.3g}")
    h = _loads(model, pose, _rates(model, pose, w1, w2), w1, w2, 0.0, 0.0, gravity=True,
               friction=True)
    still = _rates(model, pose, 0.0, 0.0)
    m1 = _loads(model, pose, still, 0.0, 0.0, 1.0, 0.0, gravity=False, friction=False)
    m2 = _loads(model, pose, still, 0.0, 0.0, 0.0, 1.0, gravity=False, friction=False)
    M = np.array([[m1.tau1, m2.tau1], [m1.tau2, m2.tau2]])
    return M, np.array([h.tau1, h.tau2])


@dataclass(frozen=True)
class TorqueResult:
    """The dynamics stage's result on a trajectory: exact motor torques, motor powers, the
    mechanism's kinetic energy and the passive-joint forces.

    Attributes
    ----------
    t : ndarray, shape (n,)
    tau : ndarray, shape (n, 2)
        Motor torques (gravity and friction included).
    power : ndarray, shape (n, 2)
        ``tau_i qdot_i``.
    kinetic_energy : ndarray, shape (n,)
    reactions : Reactions
    """

    t: Array
    tau: Array
    power: Array
    kinetic_energy: Array
    reactions: Reactions


def trajectory_torques(model: Model, t: Array, q: Array, dq: Array, ddq: Array
                       ) -> TorqueResult:
    """The :class:`TorqueResult` of the samples ``q, dq, ddq`` (n, 2) at times ``t`` (n,)."""
    tau = inverse_dynamics(model, q, dq, ddq, t=t)
    return TorqueResult(np.asarray(t), tau, tau * np.asarray(dq), kinetic_energy(model, q, dq),
                        joint_reactions(model, q, dq, ddq))
