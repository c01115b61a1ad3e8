"""Base parameters: the combinations of standard parameters that the torques determine.

The regressor ``Y`` (:mod:`dextar.dynamics.regressor`) has dependent columns: a distal rod's
mass moves its elbow, which the proximal rod moves too, so ``m_BP`` only appears as
``J_A + l1^2 m_BP`` and ``h_AB + l1 m_BP``; without gravity the first moments ``h_AB``,
``h_DC`` leave no trace at all. The reduction is numerical (Gautier's method): a QR
decomposition of ``Y`` stacked over random states, columns scaled to unit norm, in the order
of :data:`~dextar.dynamics.regressor.STANDARD`; a column whose ``|R_ii|`` is below
:data:`RANK_TOL` depends on the earlier ones and is lumped into them,
``beta = theta_b + K_d theta_d``, so that ``Y theta = Y_b beta`` for every ``theta``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from ..dynamics.exact import Model
from ..dynamics.regressor import NAMES, STANDARD, regressor
from ..kinematics import direct_kinematics, elbows
from ..kinematics.checker import pose_distances

#: Relative size of ``|R_ii|`` (unit-norm columns) below which a column is dependent.
RANK_TOL = 1e-7
#: Relative size of a column's norm below which the torques do not depend on its parameter.
ZERO_TOL = 1e-12


@dataclass(frozen=True)
class BaseParameters:
    """The base parameters of a model.

    Attributes
    ----------
    independent : tuple of int
        Standard parameters kept (columns of ``Y_b``), one per base parameter.
    K : ndarray, shape (n_base, 15)
        ``beta = K @ theta``; row ``i`` has a 1 at ``independent[i]`` and the lumped
        standard parameters' coefficients.
    unidentifiable : tuple of int
        Standard parameters the torques do not depend on at all (zero columns).
    """

    independent: tuple[int, ...]
    K: Array
    unidentifiable: tuple[int, ...]

    @property
    def size(self) -> int:
        """Number of base parameters."""
        return len(self.independent)

    @property
    def names(self) -> list[str]:
        """Each base parameter named by its leading standard parameter (``J_A'`` when other
        parameters are lumped into ``J_A``)."""
        out = []
        for i, j in enumerate(self.independent):
            lumped = np.count_nonzero(self.K[i]) > 1
            out.append(NAMES[j] + ("'" if lumped else ""))
        return out

    @property
    def meanings(self) -> list[str]:
        """Each base parameter as its combination of standard parameters, e.g.
        ``J_A + 0.0225 m_BP`` (coefficients in SI when the model is in SI)."""
        out = []
        for row in self.K:
            terms = []
            for j in np.flatnonzero(row):
                c = float(row[j])
                if abs(c - 1.0) < 1e-12:
                    terms.append(NAMES[j])
                else:
                    terms.append(f"{c:.6g} {NAMES[j]}")
            out.append(" + ".join(terms).replace("+ -", "- "))
        return out

    @property
    def units(self) -> list[str]:
        """SI unit of each base parameter (that of its leading standard parameter)."""
        return [STANDARD[j].unit for j in self.independent]

    @property
    def nonnegative(self) -> Array:
        """True for base parameters that are sums of non-negative standard parameters with
        non-negative coefficients (so physics bounds them below by 0), shape (n_base,)."""
        nn = np.array([p.nonnegative for p in STANDARD])
        return np.array([bool(np.all(nn[np.flatnonzero(row)]) and np.all(row[row != 0] > 0))
                         for row in self.K])

    def of(self, theta: Array) -> Array:
        """Base parameters ``beta`` (n_base,) of standard parameters ``theta`` (15,)."""
        return np.asarray(self.K @ np.asarray(theta, float))

    def columns(self, Y: Array) -> Array:
        """The base regressor ``Y_b`` (..., 2, n_base) of a full regressor (..., 2, 15)."""
        return Y[..., list(self.independent)]


def random_states(model: Model, n: int, rng: np.random.Generator,
                  margin: float = 0.1) -> tuple[Array, Array, Array]:
    """``n`` random states ``(q, dq, ddq)`` (each (n, 2)) that assemble in the model's
    assembly mode, at least ``margin`` away from both singularity types."""
    r = model.robot
    out: list[Array] = []
    count = 0
    lo, hi = abs(r.L1 - r.L2), r.L1 + r.L2
    while count < n:
        q = rng.uniform(-np.pi, np.pi, size=(4 * n, 2))
        B, C = elbows(r, q)
        dist = np.hypot(*(B - C).T)
        q = q[(dist > lo + 1e-3 * hi) & (dist < hi * (1 - 1e-3))]
        P = direct_kinematics(r, q, model.assembly)
        d = pose_distances(r, q, P)
        q = q[(d.type1 > margin) & (d.type2 > margin)]
        out.append(q)
        count += len(q)
    q = np.concatenate(out)[:n]
    return q, rng.normal(size=q.shape), rng.normal(size=q.shape)


def base_parameters(model: Model, *, samples: int = 200, seed: int = 0) -> BaseParameters:
    """The base parameters of ``model`` (its geometry, assembly mode, gravity and Coulomb
    regularisation; not its masses), from the regressor at ``samples`` random states.

    Returns
    -------
    BaseParameters
    """
    q, dq, ddq = random_states(model, samples, np.random.default_rng(seed))
    Y = regressor(model, q, dq, ddq).reshape(-1, len(STANDARD))
    return reduce_columns(Y)


def reduce_columns(Y: Array) -> BaseParameters:
    """Base parameters of a stacked regressor ``Y`` (m, 15) (see the module doc)."""
    norms = np.linalg.norm(Y, axis=0)
    zero = norms <= ZERO_TOL * norms.max()
    live = np.flatnonzero(~zero)
    Ys = Y[:, live] / norms[live]
    R = np.asarray(np.linalg.qr(Ys, mode="r"))
    keep = [int(live[i]) for i in range(len(live)) if abs(R[i, i]) > RANK_TOL]
    dep = [int(j) for j in live if j not in keep]
    K = np.zeros((len(keep), Y.shape[1]))
    K[np.arange(len(keep)), keep] = 1.0
    if dep:
        coef, *_ = np.linalg.lstsq(Y[:, keep], Y[:, dep], rcond=None)
        scale = norms[dep][None, :] / norms[keep][:, None]
        coef[np.abs(coef) * scale < 1e-9] = 0.0
        K[:, dep] = coef
    return BaseParameters(tuple(keep), K, tuple(int(j) for j in np.flatnonzero(zero)))
