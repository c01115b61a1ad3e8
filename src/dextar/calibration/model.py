"""The calibration model: a five-bar's lengths, its encoders' zero offsets and where its frame
sits in the measuring instrument's frame, with the predicted measured point and its
analytic Jacobian.

Ten parameters, in this order (:data:`NAMES`; SI in Python, mm and degrees in files):

* ``l1, l2, L1, L2, d``: the lengths of :class:`dextar.FiveBar` (m);
* ``phi_offset, psi_offset``: encoder offsets, geometric angle = reading + offset (rad);
* ``x0, y0, theta0``: the pose of the robot frame (origin midway between the pivots, x from
  D to A) in the instrument's frame (m, m, rad), so a point ``P`` of the robot frame is
  measured at ``M = R(theta0) P + (x0, y0)``.

The prediction of a measured point is ``M(readings, assembly; p)``: the direct kinematics of
the robot of ``p`` at angles ``readings + offsets`` in the row's assembly mode, moved into
the instrument's frame. Its Jacobian follows from differentiating the two closures
``|P - B|^2 = L1^2`` and ``|P - C|^2 = L2^2``:

``A dP = [(P - B).dB + L1 dL1, (P - C).dC + L2 dL2]`` with the rows of ``A`` ``(P - B)^T``,
``(P - C)^T`` (the velocity relation's matrix), ``B = (d/2 + l1 cos phi, l1 sin phi)``,
``C = (-d/2 + l2 cos psi, l2 sin psi)``; so ``dP/dl1 = A^-1 ((P - B).e(phi), 0)``,
``dP/dd = A^-1 ((P - B)_x / 2, -(P - C)_x / 2)``, ``dP/dphi_offset = A^-1 (b1, 0)`` with
``b1 = (B - A) x (P - B)``, and so on; ``dM/dtheta0 = perp(R P)``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from .._arrays import Array, as_points
from ..errors import AssemblyError, ParameterError
from ..geometry import FiveBar
from ..kinematics import inverse_kinematics

#: The ten parameters of the model, in the order of every vector and matrix.
NAMES: tuple[str, ...] = ("l1", "l2", "L1", "L2", "d", "phi_offset", "psi_offset",
                          "x0", "y0", "theta0")
#: The lengths among them (SI m; mm in files); the others are angles (rad; deg in files).
LENGTHS: frozenset[str] = frozenset({"l1", "l2", "L1", "L2", "d", "x0", "y0"})
#: The parameters of the instrument frame (not part of the robot).
FRAME: tuple[str, ...] = ("x0", "y0", "theta0")
#: The parameters of the robot itself (what a calibrated config carries).
ROBOT: tuple[str, ...] = NAMES[:7]
#: Index of each parameter in :data:`NAMES`.
INDEX: dict[str, int] = {n: i for i, n in enumerate(NAMES)}


def to_file_units(name: str, value: float) -> float:
    """A value of parameter ``name`` from SI (m, rad) to file units (mm, deg), to 15
    significant digits (so that 72 mm comes back as 72, not 72.00000000000001)."""
    v = 1e3 * value if name in LENGTHS else math.degrees(value)
    return float(f"{v:.15g}")


@dataclass(frozen=True)
class KinematicModel:
    """The calibration parameters of a five-bar measured by an instrument (SI).

    Attributes
    ----------
    robot : FiveBar
        Lengths in metres.
    phi_offset, psi_offset : float
        Encoder offsets (rad): geometric angle = reading + offset.
    x0, y0 : float
        Origin of the robot frame in the instrument's frame (m).
    theta0 : float
        Angle of the robot frame's x axis in the instrument's frame (rad).
    """

    robot: FiveBar
    phi_offset: float = 0.0
    psi_offset: float = 0.0
    x0: float = 0.0
    y0: float = 0.0
    theta0: float = 0.0

    def __post_init__(self) -> None:
        for name in ("phi_offset", "psi_offset", "x0", "y0", "theta0"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise ParameterError(f"calibration parameter {name} = {v!r} is not a finite "
                                     "number")

    # ----------------------------------------------------------------- vectors and units
    def vector(self) -> Array:
        """The ten parameters in the order of :data:`NAMES`, shape (10,), SI."""
        r = self.robot
        return np.array([r.l1, r.l2, r.L1, r.L2, r.d, self.phi_offset, self.psi_offset,
                         self.x0, self.y0, self.theta0])

    @classmethod
    def from_vector(cls, p: object) -> KinematicModel:
        """The model of a vector of the ten parameters (SI), shape (10,).

        Raises
        ------
        GeometryError
            Lengths that are not positive or a robot that can never close.
        """
        v = np.asarray(p, dtype=float).reshape(-1)
        if v.shape != (len(NAMES),):
            raise ParameterError(f"a parameter vector has {len(NAMES)} entries, got {v.size}")
        return cls(FiveBar(*(float(x) for x in v[:5])), *(float(x) for x in v[5:]))

    @classmethod
    def from_config_units(cls, robot_mm: FiveBar, *,
                          encoder_offset_deg: Sequence[float] = (0.0, 0.0),
                          instrument: Sequence[float] = (0.0, 0.0, 0.0)) -> KinematicModel:
        """The model of config values: ``robot_mm`` in mm, ``[robot].encoder_offset_deg``
        ``(phi, psi)`` in degrees and ``[instrument]`` ``(x0_mm, y0_mm, theta0_deg)``."""
        ox, oy = (float(v) for v in encoder_offset_deg)
        x0, y0, th = (float(v) for v in instrument)
        return cls(robot_mm.scaled(1e-3), math.radians(ox), math.radians(oy), 1e-3 * x0,
                   1e-3 * y0, math.radians(th))

    def in_file_units(self) -> dict[str, float]:
        """The ten parameters by name in file units (mm, deg)."""
        return {n: to_file_units(n, float(v)) for n, v in zip(NAMES, self.vector(),
                                                              strict=True)}

    def with_frame(self, x0: float, y0: float, theta0: float) -> KinematicModel:
        """The same robot in another instrument frame (SI)."""
        return replace(self, x0=float(x0), y0=float(y0), theta0=float(theta0))

    @property
    def offsets(self) -> Array:
        """``(phi_offset, psi_offset)`` (rad), shape (2,)."""
        return np.array([self.phi_offset, self.psi_offset])

    # ----------------------------------------------------------------------- frames
    def rotation(self) -> Array:
        """``R(theta0)``, shape (2, 2)."""
        return rotation(self.theta0)

    def to_instrument(self, points: object) -> Array:
        """Points (..., 2) of the robot frame in the instrument's frame (m)."""
        P = as_points(points, "points")
        return np.asarray(P @ self.rotation().T + np.array([self.x0, self.y0]))

    def to_robot(self, points: object) -> Array:
        """Points (..., 2) of the instrument's frame in the robot frame (m)."""
        M = as_points(points, "points")
        return np.asarray((M - np.array([self.x0, self.y0])) @ self.rotation())

    # ------------------------------------------------------------------ prediction
    def angles(self, readings: object) -> Array:
        """Geometric angles ``readings + offsets`` (rad), shape (..., 2)."""
        return np.asarray(as_points(readings, "readings") + self.offsets)

    def predict(self, readings: object, assembly: object) -> Array:
        """The measured points predicted for encoder readings, in the instrument's frame.

        Parameters
        ----------
        readings : array_like, shape (n, 2)
            Encoder readings ``(phi, psi)`` (rad).
        assembly : array_like of int, shape (n,) or scalar
            Assembly mode of each row, +1 (up) or -1 (down).

        Returns
        -------
        M : ndarray, shape (n, 2)
            Predicted points (m), instrument frame.

        Raises
        ------
        AssemblyError
            A row whose distal rods cannot meet (named by its index).
        """
        k = closure(self, readings, assembly)
        k.raise_if_open()
        return self.to_instrument(k.P)

    def readings(self, points: object, mode: str | tuple[int, int]) -> Array:
        """Encoder readings that put the robot at ``points`` of the robot frame: the inverse
        kinematics of the model's geometry minus the offsets, wrapped to ``(-pi, pi]``.

        Parameters
        ----------
        points : array_like, shape (..., 2)
            Targets (m) in the robot frame.
        mode : str or (int, int)
            Working mode.

        Returns
        -------
        readings : ndarray, shape (..., 2)
            ``(phi, psi)`` readings (rad).

        Raises
        ------
        ReachError
            A target out of reach of a leg of the model's robot.
        """
        q = inverse_kinematics(self.robot, points, mode)
        return wrap(q - self.offsets)

    def readings_for_measured(self, points: object, mode: str | tuple[int, int]) -> Array:
        """Encoder readings that put the robot at ``points`` given in the instrument's frame
        (m), shape (..., 2) -> (..., 2) rad."""
        return self.readings(self.to_robot(points), mode)


def wrap(angle: Array) -> Array:
    """Angles wrapped to ``(-pi, pi]``."""
    a = np.asarray(angle, dtype=float)
    return np.asarray(np.pi - np.mod(np.pi - a, 2.0 * np.pi))


@dataclass(frozen=True)
class Closure:
    """The closed chain of each row for a model's readings (robot frame, SI).

    Attributes
    ----------
    q : ndarray, shape (n, 2)
        Geometric angles.
    P, B, C : ndarray, shape (n, 2)
        End-effector and elbows.
    b1, b2 : ndarray, shape (n,)
        ``(B - A) x (P - B)`` and ``(C - D) x (P - C)``: their signs are the working mode.
    det : ndarray, shape (n,)
        ``(P - B) x (P - C)`` (zero at a parallel singularity).
    gap : ndarray, shape (n,)
        How far ``|B - C|`` is outside ``[|L1 - L2|, L1 + L2]`` (m), 0 where the rods meet;
        where positive the rows' ``P`` is that of the rods stretched towards each other.
    sigma : ndarray of int, shape (n,)
        The assembly sign used.
    """

    q: Array
    P: Array
    B: Array
    C: Array
    b1: Array
    b2: Array
    det: Array
    gap: Array
    sigma: Array

    @property
    def open(self) -> Array:
        """Rows whose distal rods cannot meet, shape (n,) bool."""
        return np.asarray(self.gap > 0)

    def working_mode(self) -> Array:
        """Working-mode signs ``(s1, s2)`` of each row, shape (n, 2), entries +1/-1/0."""
        return np.stack([np.sign(self.b1), np.sign(self.b2)], axis=-1).astype(int)

    def raise_if_open(self, rows: Array | None = None) -> None:
        """Raise :class:`AssemblyError` for the first row whose rods cannot meet; ``rows``
        (n,) names the rows (default: their indices)."""
        if not self.open.any():
            return
        i = int(np.flatnonzero(self.open)[0])
        name = f"row {int(rows[i])}" if rows is not None else f"index {i}"
        raise AssemblyError(
            f"{name}: the distal rods cannot meet at angles ({math.degrees(self.q[i, 0]):.6g}, "
            f"{math.degrees(self.q[i, 1]):.6g}) deg: |B - C| is {1e3 * self.gap[i]:.4g} mm "
            "outside the rods' range")


def closure(model: KinematicModel, readings: object, assembly: object) -> Closure:
    """The closed chain of each row (see :class:`Closure`), vectorised over rows.

    Parameters
    ----------
    model : KinematicModel
    readings : array_like, shape (n, 2)
        Encoder readings (rad).
    assembly : array_like of int, shape (n,) or scalar
        +1 (up) or -1 (down) per row.
    """
    r = np.asarray(as_points(readings, "readings"), dtype=float).reshape(-1, 2)
    return closure_of(model.vector(), r, assembly)


def closure_of(p: Array, readings: Array, assembly: object) -> Closure:
    """:func:`closure` for a parameter vector ``p`` (10,) and readings (n, 2) already
    checked (the fit's inner loop: no validation, no objects)."""
    l1, l2, L1, L2, d = (float(v) for v in p[:5])
    q = readings + p[5:7]
    sigma = np.broadcast_to(np.asarray(assembly, dtype=int), (len(q),)).copy()
    half = 0.5 * d
    c1, s1 = np.cos(q[:, 0]), np.sin(q[:, 0])
    c2, s2 = np.cos(q[:, 1]), np.sin(q[:, 1])
    B = np.stack([half + l1 * c1, l1 * s1], axis=-1)
    C = np.stack([-half + l2 * c2, l2 * s2], axis=-1)
    v = B - C
    del2 = np.maximum((v * v).sum(axis=-1), 1e-300)
    k = 0.5 * (del2 + (L2 * L2 - L1 * L1))
    w2 = (L2 * L2) * del2 - k * k
    dist = np.sqrt(del2)
    gap = np.maximum(np.maximum(dist - (L1 + L2), abs(L1 - L2) - dist), 0.0)
    gap = np.where(w2 >= -1e-12 * (L2 * L2) * del2, 0.0, np.maximum(gap, 1e-300))
    w = sigma * np.sqrt(np.maximum(w2, 0.0))
    inv = 1.0 / del2
    P = np.stack([C[:, 0] + (k * v[:, 0] - w * v[:, 1]) * inv,
                  C[:, 1] + (k * v[:, 1] + w * v[:, 0]) * inv], axis=-1)
    u, vv = P - B, P - C
    b1 = l1 * (c1 * u[:, 1] - s1 * u[:, 0])
    b2 = l2 * (c2 * vv[:, 1] - s2 * vv[:, 0])
    det = u[:, 0] * vv[:, 1] - u[:, 1] * vv[:, 0]
    return Closure(q, P, B, C, b1, b2, det, gap, sigma)


def rotation(theta: float) -> Array:
    """``R(theta)``, shape (2, 2)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def predict_of(p: Array, k: Closure) -> Array:
    """The predicted measured points (n, 2) of a closure for the parameter vector ``p``."""
    return np.asarray(k.P @ rotation(float(p[9])).T + p[7:9])


def jacobian(model: KinematicModel, k: Closure) -> Array:
    """The identification Jacobian ``dM/dp`` of each row, shape (n, 2, 10), SI (m per m,
    m per rad), columns in the order of :data:`NAMES` (see the module doc)."""
    return jacobian_of(model.vector(), k)


def jacobian_of(p: Array, k: Closure) -> Array:
    """:func:`jacobian` for a parameter vector ``p`` (10,)."""
    L1, L2 = float(p[2]), float(p[3])
    n = len(k.q)
    u, v = k.P - k.B, k.P - k.C
    c1, s1 = np.cos(k.q[:, 0]), np.sin(k.q[:, 0])
    c2, s2 = np.cos(k.q[:, 1]), np.sin(k.q[:, 1])
    g = np.zeros((n, 2, 7))
    g[:, 0, 0] = u[:, 0] * c1 + u[:, 1] * s1
    g[:, 1, 1] = v[:, 0] * c2 + v[:, 1] * s2
    g[:, 0, 2] = L1
    g[:, 1, 3] = L2
    g[:, 0, 4] = 0.5 * u[:, 0]
    g[:, 1, 4] = -0.5 * v[:, 0]
    g[:, 0, 5] = k.b1
    g[:, 1, 6] = k.b2
    inv = 1.0 / np.where(k.det == 0.0, 1e-300, k.det)
    # A^-1 = [[vy, -uy], [-vx, ux]] / det
    dP = np.empty((n, 2, 7))
    dP[:, 0] = (v[:, 1, None] * g[:, 0] - u[:, 1, None] * g[:, 1]) * inv[:, None]
    dP[:, 1] = (u[:, 0, None] * g[:, 1] - v[:, 0, None] * g[:, 0]) * inv[:, None]
    R = rotation(float(p[9]))
    J = np.empty((n, 2, len(NAMES)))
    J[:, 0, :7] = R[0, 0] * dP[:, 0] + R[0, 1] * dP[:, 1]
    J[:, 1, :7] = R[1, 0] * dP[:, 0] + R[1, 1] * dP[:, 1]
    J[:, :, 7] = (1.0, 0.0)
    J[:, :, 8] = (0.0, 1.0)
    RP = k.P @ R.T
    J[:, 0, 9] = -RP[:, 1]
    J[:, 1, 9] = RP[:, 0]
    return J


def characteristic_scales(robot: FiveBar) -> Array:
    """Scales that make the Jacobian's columns dimensionless, shape (10,): 1 for a length,
    the mean reach of the legs ``(l1 + L1 + l2 + L2) / 2`` for an angle (an angle error
    moves the end-effector about that far per radian)."""
    reach = 0.5 * (robot.l1 + robot.L1 + robot.l2 + robot.L2)
    return np.array([1.0 if n in LENGTHS else reach for n in NAMES])
