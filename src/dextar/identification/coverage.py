"""The region of joint space a motion excites, and whether other motions stay inside it.

A sample ``(q, qdot)`` is inside the region of a set of samples when its pose is within
:data:`REGION_RADIUS` (joint space, both angles in the same units) of one of theirs and each
motor's speed is at most ``1 +`` :data:`SPEED_MARGIN` times their peak speed. The identified
model is exact for the rigid bodies everywhere, but what it lacks (friction beyond Coulomb and
viscous, a cable, cogging) it has only averaged over the poses and speeds the identification
visited: outside them a prediction extrapolates.

:class:`JointRegion` is the region of a task (a program's or a run's samples) that
:func:`~dextar.identification.excite.design_excitation` is asked to cover;
:func:`coverage` tells which samples of a validation motion lie outside the identification
data's region.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..errors import ParameterError
from .filtering import Conditioned

spatial = lazy_module("scipy.spatial")

#: Largest joint-space distance (rad) from a visited pose that counts as inside.
REGION_RADIUS = math.radians(10.0)
#: A speed up to this fraction above the peak visited counts as inside.
SPEED_MARGIN = 0.1


@dataclass(frozen=True)
class JointRegion:
    """Poses and speeds of joint space: a task's region.

    Attributes
    ----------
    q : ndarray, shape (m, 2)
        Poses visited (rad), thinned to one per cell of a quarter radius.
    peak_speed : ndarray, shape (2,)
        Each motor's peak speed (rad/s).
    radius : float
        Distance (rad) around each pose that belongs to the region.
    """

    q: Array
    peak_speed: Array
    radius: float = REGION_RADIUS

    def __post_init__(self) -> None:
        q = np.asarray(self.q, float)
        v = np.asarray(self.peak_speed, float)
        if q.ndim != 2 or q.shape[1] != 2 or len(q) == 0 or not np.isfinite(q).all():
            raise ParameterError(f"a joint region needs finite poses of shape (m, 2), got "
                                 f"{q.shape}")
        if v.shape != (2,) or not (np.isfinite(v).all() and (v >= 0).all()):
            raise ParameterError(f"a joint region's peak speeds {v!r} must be two numbers >= 0")
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise ParameterError(f"a joint region's radius {self.radius!r} must be positive")

    @staticmethod
    def from_samples(q: Array, dq: Array, *, radius: float = REGION_RADIUS) -> JointRegion:
        """The region of samples ``q, dq`` (each (n, 2), rad and rad/s), e.g. a program's
        set-points or a run's trajectory."""
        q = np.asarray(q, float).reshape(-1, 2)
        dq = np.asarray(dq, float).reshape(-1, 2)
        if len(q) != len(dq):
            raise ParameterError(f"a joint region needs as many speeds as poses: {len(dq)} "
                                 f"and {len(q)}")
        cells = np.unique(np.round(q / (0.25 * radius)), axis=0)
        return JointRegion(cells * 0.25 * radius, np.abs(dq).max(axis=0), radius)

    @property
    def lower(self) -> Array:
        """Smallest angle of each joint (2,)."""
        return np.asarray(self.q.min(axis=0))

    @property
    def upper(self) -> Array:
        """Largest angle of each joint (2,)."""
        return np.asarray(self.q.max(axis=0))

    def distance(self, q: Array) -> Array:
        """Joint-space distance (n,) of poses ``q`` (n, 2) to the nearest pose of the region."""
        d, _ = spatial.cKDTree(self.q).query(np.asarray(q, float).reshape(-1, 2))
        return np.asarray(d)

    def contains(self, q: Array, dq: Array) -> tuple[Array, Array]:
        """For samples ``q, dq`` (each (n, 2)): ``(near, slow)``, both (n,) bool: the pose
        within ``radius`` of the region's, every speed within its peak (plus
        :data:`SPEED_MARGIN`)."""
        near = self.distance(q) <= self.radius
        slow = (np.abs(np.asarray(dq, float).reshape(-1, 2))
                <= (1.0 + SPEED_MARGIN) * self.peak_speed[None, :] + 1e-12).all(axis=1)
        return np.asarray(near), np.asarray(slow)


@dataclass(frozen=True)
class Coverage:
    """Which samples of a motion lie in another motion's region.

    Attributes
    ----------
    fraction : float
        Fraction of the samples inside.
    inside : ndarray of bool, shape (n,)
    far : ndarray of bool, shape (n,)
        Pose farther than the radius from every visited pose.
    fast : ndarray of bool, shape (n,)
        A motor faster than the region's peak speed (plus the margin).
    rows : ndarray of int, shape (k,)
        Data-file rows (header = row 1) of the samples outside.
    times : ndarray, shape (k,)
        Their times (s).
    radius : float
        The region's radius (rad).
    """

    fraction: float
    inside: Array
    far: Array
    fast: Array
    rows: Array
    times: Array
    radius: float

    def message(self, source: str) -> str:
        """A warning naming the samples outside, or "" when every sample is inside."""
        if not len(self.rows):
            return ""
        why = []
        if self.far.any():
            why.append(f"{int(self.far.sum())} at poses farther than "
                       f"{math.degrees(self.radius):.3g} deg from every pose identified")
        if self.fast.any():
            why.append(f"{int(self.fast.sum())} faster than the identification moved")
        first, last = self.times[0], self.times[-1]
        return (f"{source}: {100 * (1 - self.fraction):.3g} % of the samples lie outside the "
                f"region the identification excited ({' and '.join(why)}; rows "
                f"{int(self.rows[0])} to {int(self.rows[-1])}, t = {first:.6g} to "
                f"{last:.6g} s): the prediction extrapolates there (dextar excite --task "
                "covers a task's region)")


def coverage(excited: Conditioned | JointRegion, samples: Conditioned) -> Coverage:
    """The samples of ``samples`` inside the region of ``excited``.

    Parameters
    ----------
    excited : Conditioned or JointRegion
        The identification data (every conditioned row counts) or a region.
    samples : Conditioned
        The motion to check (e.g. the validation data conditioned with the identification's
        filters).

    Returns
    -------
    Coverage
    """
    region = (excited if isinstance(excited, JointRegion)
              else JointRegion.from_samples(excited.q, excited.dq))
    near, slow = region.contains(samples.q, samples.dq)
    inside = near & slow
    out = np.flatnonzero(~inside)
    rows = (np.arange(len(samples.t)) if samples.rows is None else samples.rows)[out] + 2
    fraction = float(inside.mean()) if len(inside) else 1.0
    return Coverage(fraction, inside, ~near, ~slow, np.asarray(rows), samples.t[out],
                    region.radius)
