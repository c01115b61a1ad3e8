"""Which parameters a set of poses identifies, and how well: the numerical rank of the
scaled identification Jacobian and its observability indices.

The Jacobian's columns are made dimensionless by :func:`characteristic_scales` (an angle
times the legs' mean reach): a column then says how far the points move per unit of that
parameter's error. Of its singular values ``s_1 >= ... >= s_p`` over ``n`` poses:

* **O1** ``= (s_1 s_2 ... s_p)^(1/p) / sqrt(n)`` (Borm and Menq), the D-optimality index:
  the geometric mean, per pose, of how far the points move per unit of parameter error.
  Maximised by the pose selection; its maximiser does not depend on the parameters' units.
* **O3** ``= s_p / sqrt(n)``: the same for the least observable combination of parameters
  (its standard deviation is ``sigma / (O3 sqrt(n))`` for point noise ``sigma`` per axis).
* the **condition number** ``s_1 / s_p``.

Identifiability (Gautier's numerical method): a QR decomposition of the Jacobian with its
columns scaled to unit norm, in the order of :data:`dextar.calibration.model.NAMES`; a
column whose ``|R_jj|`` (its distance from the span of the columns before it) is below
:data:`RANK_TOL` is a combination of those: that parameter is not identifiable and stays
at its nominal value.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from .model import NAMES

#: A unit-norm column closer than this to the span of the columns before it is not
#: identifiable (its standard deviation would be over a million times that of a column
#: independent of the others).
RANK_TOL = 1e-4


@dataclass(frozen=True)
class Observability:
    """How well poses identify parameters.

    Attributes
    ----------
    names : tuple of str
        The parameters the indices are computed for (the identifiable ones).
    singular_values : ndarray, shape (p,)
        Of the scaled Jacobian (descending).
    o1, o3 : float
        Observability indices (see the module doc), dimensionless.
    condition_number : float
    n_poses : int
    """

    names: tuple[str, ...]
    singular_values: Array
    o1: float
    o3: float
    condition_number: float
    n_poses: int

    def as_dict(self) -> dict[str, object]:
        """JSON-ready fields."""
        return {"index": "O1", "o1": self.o1, "o3": self.o3,
                "condition_number": self.condition_number, "n_poses": self.n_poses,
                "parameters": list(self.names)}


@dataclass(frozen=True)
class Identifiability:
    """Which of the free parameters the poses identify.

    Attributes
    ----------
    identifiable, not_identifiable : tuple of str
    combinations : dict
        For each parameter not identifiable, the combination of identifiable ones its
        column equals (words, e.g. ``"theta0 = -1 phi_offset"``).
    """

    identifiable: tuple[str, ...]
    not_identifiable: tuple[str, ...]
    combinations: dict[str, str]


def observability(J: Array, columns: Sequence[str], scales: Array) -> Observability:
    """The indices of the Jacobian ``J`` (n, 2, 10) restricted to ``columns`` (names of
    :data:`NAMES`), scaled by ``scales`` (10,)."""
    idx = [NAMES.index(c) for c in columns]
    A = (J[:, :, idx] * scales[idx]).reshape(-1, len(idx))
    n = len(J)
    if len(idx) == 0 or n == 0:
        return Observability(tuple(columns), np.zeros(0), 0.0, 0.0, np.inf, n)
    s = np.linalg.svd(A, compute_uv=False)
    o1 = float(np.exp(np.mean(np.log(np.maximum(s, 1e-300)))) / np.sqrt(n))
    o3 = float(s[-1] / np.sqrt(n))
    cond = float(s[0] / s[-1]) if s[-1] > 0 else np.inf
    return Observability(tuple(columns), s, o1, o3, cond, n)


def identifiability(J: Array, free: Sequence[str]) -> Identifiability:
    """Split ``free`` parameters into identifiable and not, from the Jacobian (n, 2, 10).

    The order is that of :data:`NAMES` whatever the order of ``free``: a later parameter
    that is a combination of earlier ones is the one reported (see the module doc).
    """
    order = [n for n in NAMES if n in set(free)]
    idx = [NAMES.index(n) for n in order]
    A = J[:, :, idx].reshape(-1, len(idx))
    norms = np.linalg.norm(A, axis=0)
    keep: list[int] = []
    gone: list[int] = []
    combos: dict[str, str] = {}
    if A.shape[0] == 0:
        return Identifiability((), tuple(order), {n: "no poses" for n in order})
    An = A / np.where(norms > 0, norms, 1.0)
    for j in range(len(idx)):
        if norms[j] == 0:
            gone.append(j)
            combos[order[j]] = f"{order[j]} does not move any point"
            continue
        if keep:
            Q, _ = np.linalg.qr(An[:, keep])
            resid = An[:, j] - Q @ (Q.T @ An[:, j])
            dist = float(np.linalg.norm(resid))
        else:
            dist = 1.0
        if dist < RANK_TOL:
            coef = np.linalg.lstsq(A[:, keep], A[:, j], rcond=None)[0]
            big = np.argsort(-np.abs(coef))[:3]
            terms = " + ".join(f"{coef[b]:.3g} {order[keep[b]]}" for b in big
                               if abs(coef[b]) > 1e-3 * np.abs(coef).max())
            combos[order[j]] = f"{order[j]} = {terms.replace('+ -', '- ')}"
            gone.append(j)
        else:
            keep.append(j)
    return Identifiability(tuple(order[j] for j in keep), tuple(order[j] for j in gone),
                           combos)


def correlation(cov: Array) -> Array:
    """The correlation matrix of a covariance matrix (p, p) (0 where a variance is 0)."""
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        c = cov / np.outer(sd, sd)
    c = np.where(np.isfinite(c), c, 0.0)
    np.fill_diagonal(c, 1.0)
    return np.asarray(np.clip(c, -1.0, 1.0))


def multiple_correlation(corr: Array) -> Array:
    """Each parameter's multiple correlation with all the others (p,), from the estimates'
    correlation matrix (p, p): ``sqrt(1 - 1 / VIF)``, the variance inflation factor
    ``VIF_j = [corr^-1]_jj``. Near 1, a parameter is nearly a combination of the others
    (coupled to them), even when no pair of parameters is strongly correlated."""
    if corr.size == 0:
        return np.zeros(0)
    try:
        vif = np.diag(np.linalg.inv(corr))
    except np.linalg.LinAlgError:
        return np.ones(len(corr))
    return np.asarray(np.sqrt(np.clip(1.0 - 1.0 / np.maximum(vif, 1.0), 0.0, 1.0)))
