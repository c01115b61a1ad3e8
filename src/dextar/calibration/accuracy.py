"""How accurately the calibrated robot positions its end-effector over the workspace.

Commanding a point ``T`` sets the readings ``r = IK(T; p_hat) - offsets_hat``; the real
robot then sits at ``P(r; p) ~ T + J_p (p - p_hat)``, ``J_p`` the points' sensitivity to
the robot's parameters at fixed readings. With the estimates' covariance ``C`` and readings
realised to within the encoders' resolution (standard deviation ``s_r``), the position's
covariance is ``J_p C J_p^T + s_r^2 J_q J_q^T`` (``J_q`` the kinematic Jacobian). The map
gives its largest standard deviation, along the worst direction (the semi-major axis of
the 1-sigma ellipse). Parameters not identifiable count as exact (their error is unknown);
the instrument frame does not enter (the robot works in its own frame).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from ..errors import ParameterError
from ..geometry import canonical_working_mode, parse_assembly_mode
from ..kinematics import assembly_mode, inverse_kinematics
from ..kinematics.checker import pose_distances, reach_violation
from .model import NAMES, ROBOT, KinematicModel, closure, jacobian


@dataclass(frozen=True)
class AccuracyMap:
    """The predicted position uncertainty on a grid of the robot frame (SI).

    Attributes
    ----------
    x : ndarray, shape (nx,)
    y : ndarray, shape (ny,)
        Grid coordinates (m).
    std : ndarray, shape (ny, nx)
        Largest standard deviation of the position (m); 0 where not ``valid``.
    from_parameters : ndarray, shape (ny, nx)
        The same with the parameters' covariance alone (m).
    valid : ndarray of bool, shape (ny, nx)
        Reachable in the mode and assembly, ``margin`` from both singularity types.
    mode : str
    assembly : int
    reading_std : float or None
        The encoders' standard deviation used (rad).
    parameters : tuple of str
        The parameters whose covariance counts.
    """

    x: Array
    y: Array
    std: Array
    from_parameters: Array
    valid: Array
    mode: str
    assembly: int
    reading_std: float | None
    parameters: tuple[str, ...]

    @property
    def worst(self) -> float:
        """The largest ``std`` over the valid points (m)."""
        return float(self.std[self.valid].max(initial=0.0))

    @property
    def median(self) -> float:
        """The median ``std`` over the valid points (m)."""
        v = self.std[self.valid]
        return float(np.median(v)) if v.size else 0.0


def _major(S: Array) -> Array:
    """Square root of the largest eigenvalue of symmetric 2x2 matrices (..., 2, 2)."""
    a, b, c = S[..., 0, 0], S[..., 0, 1], S[..., 1, 1]
    lam = 0.5 * (a + c) + np.sqrt(0.25 * (a - c) ** 2 + b * b)
    return np.asarray(np.sqrt(np.maximum(lam, 0.0)))


def position_covariance(model: KinematicModel, points: Array, mode: str, assembly: int,
                        names: Sequence[str], covariance: Array,
                        reading_std: float | None = None, *, frame: str = "robot"
                        ) -> tuple[Array, Array]:
    """Covariance (n, 2, 2) of the position reached when commanding ``points`` (n, 2, m),
    and its parameters' part; see the module doc.

    ``frame = "robot"``: points and covariance in the robot frame (the instrument frame's
    parameters, if among ``names``, are ignored); ``"instrument"``: points in the
    instrument's frame, commanded through the estimated frame, whose uncertainty counts.

    Raises
    ------
    ReachError
        A point the model's robot does not reach.
    """
    if frame == "instrument":
        base = model
        points = model.to_robot(points)
    else:
        base = model.with_frame(0.0, 0.0, 0.0)
        keep = [i for i, n in enumerate(names) if n in ROBOT]
        names = [names[i] for i in keep]
        covariance = np.asarray(covariance)[np.ix_(keep, keep)]
    q = inverse_kinematics(base.robot, points, mode)
    k = closure(base, q - base.offsets, assembly)
    J = jacobian(base, k)
    idx = [NAMES.index(n) for n in names]
    Jp = J[:, :, idx]
    Sp = np.einsum("nik,kl,njl->nij", Jp, covariance, Jp, optimize=True)
    S = Sp.copy()
    if reading_std:
        Jq = J[:, :, 5:7]
        S += reading_std ** 2 * np.einsum("nik,njk->nij", Jq, Jq)
    return S, Sp


def accuracy_map(model: KinematicModel, names: Sequence[str], covariance: Array,
                 mode: str, *, assembly: str | int = "up", reading_std: float | None = None,
                 resolution: int = 121, margin: float = 0.05) -> AccuracyMap:
    """The predicted position uncertainty over the workspace of ``mode``.

    Parameters
    ----------
    model : KinematicModel
        The calibrated model (SI).
    names : sequence of str
        The robot parameters of ``covariance`` (instrument-frame names are dropped).
    covariance : ndarray, shape (k, k)
        Their covariance (SI).
    mode : str
        Working mode.
    assembly : {"up", "down"}
    reading_std : float, optional
        The encoders' standard deviation (rad), e.g. ``encoder_std(counts)``.
    resolution : int
        Grid points along the longer side.
    margin : float
        Least normalised distance to both singularity types of a valid point (the
        uncertainty grows without bound at a parallel singularity).

    Returns
    -------
    AccuracyMap
    """
    names = list(names)
    cov = np.asarray(covariance, dtype=float)
    if cov.shape != (len(names), len(names)):
        raise ParameterError(f"covariance of shape {cov.shape} for {len(names)} parameters")
    keep = [i for i, n in enumerate(names) if n in ROBOT]
    names_r = [names[i] for i in keep]
    cov = cov[np.ix_(keep, keep)]
    mode = canonical_working_mode(mode)
    sign = parse_assembly_mode(assembly)
    if not 10 <= resolution <= 1001:
        raise ParameterError(f"accuracy map resolution {resolution} must be in 10 ... 1001")
    r = model.robot
    reach = max(r.l1 + r.L1, r.l2 + r.L2)
    h = 0.5 * r.d
    x = np.linspace(-h - reach, h + reach, resolution)
    y = np.linspace(-reach, reach, max(10, int(round(resolution * reach / (h + reach)))))
    X, Y = np.meshgrid(x, y)
    grid = np.stack([X.ravel(), Y.ravel()], axis=-1)
    out, _ = reach_violation(r, grid)
    ok = (out == 0).all(axis=1)
    pts = grid[ok]
    q = inverse_kinematics(r, pts, mode)
    d = pose_distances(r, q, pts)
    good = (d.type1 >= margin) & (d.type2 >= margin) & (assembly_mode(r, q, pts) == sign)
    valid = np.zeros(len(grid), bool)
    valid[np.flatnonzero(ok)[good]] = True
    std = np.zeros(len(grid))
    par = np.zeros(len(grid))
    if valid.any():
        S, Sp = position_covariance(model, grid[valid], mode, sign, names_r, cov, reading_std)
        std[valid] = _major(S)
        par[valid] = _major(Sp)
    shape = X.shape
    return AccuracyMap(x, y, std.reshape(shape), par.reshape(shape), valid.reshape(shape),
                       mode, sign, reading_std, tuple(names_r))
