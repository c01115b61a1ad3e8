"""Workspace of a working mode: reachability, singularity curves and dexterity on a grid."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from ..errors import ParameterError
from ..geometry import FiveBar, parse_working_mode, working_mode_name
from .positions import _leg_solve

#: Largest grid side of a workspace map (16 million points).
MAX_RESOLUTION = 4001


@dataclass(frozen=True)
class WorkspaceMap:
    """A workspace sampled on a regular grid.

    Attributes
    ----------
    x : ndarray, shape (nx,)
    y : ndarray, shape (ny,)
    reachable : ndarray of bool, shape (ny, nx)
        Both legs reach the point (the same for every working mode).
    type2 : ndarray, shape (ny, nx)
        Signed normalised parallel-singularity indicator ``det A / (L1 L2)`` for this working
        mode (zero on the type-2 curves, zero where unreachable).
    dexterity : ndarray, shape (ny, nx)
        Inverse condition number of ``J`` in ``[0, 1]`` (0 where unreachable or singular).
    mode : str
        The working mode.
    """

    robot: FiveBar
    x: Array
    y: Array
    reachable: Array
    type2: Array
    dexterity: Array
    mode: str

    @property
    def reachable_area(self) -> float:
        """Area of the reachable grid cells (length unit squared)."""
        dx = self.x[1] - self.x[0]
        dy = self.y[1] - self.y[0]
        return float(self.reachable.sum() * dx * dy)


def inverse_condition(m11: Array, m12: Array, m21: Array, m22: Array) -> Array:
    """Inverse condition number ``s_min / s_max`` in ``[0, 1]`` of 2x2 matrices given by their
    entries (arrays of one shape), in closed form (0 for a zero matrix)."""
    fro2 = m11**2 + m12**2 + m21**2 + m22**2
    detm = np.abs(m11 * m22 - m12 * m21)
    disc = np.sqrt(np.maximum(fro2 * fro2 - 4.0 * detm * detm, 0.0))
    smax2 = 0.5 * (fro2 + disc)
    smin2 = np.maximum(0.5 * (fro2 - disc), 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(np.sqrt(np.where(smax2 > 0, smin2 / smax2, 0.0)))


def workspace_map(
    robot: FiveBar,
    mode: str | tuple[int, int] = "+-",
    *,
    resolution: int = 301,
    bounds: tuple[float, float, float, float] | None = None,
) -> WorkspaceMap:
    """Sample the workspace of ``robot`` in working mode ``mode``.

    Parameters
    ----------
    resolution : int
        Number of grid points along the longer side (>= 10).
    bounds : (xmin, xmax, ymin, ymax), optional
        Defaults to the box that holds both legs' reach.
    """
    signs = parse_working_mode(mode)
    if not 10 <= int(resolution) <= MAX_RESOLUTION:
        raise ParameterError(f"workspace resolution {resolution} must be between 10 and "
                             f"{MAX_RESOLUTION} grid points")
    if bounds is None:
        r = max(robot.l1 + robot.L1, robot.l2 + robot.L2)
        h = 0.5 * robot.d
        bounds = (-h - r, h + r, -r, r)
    xmin, xmax, ymin, ymax = (float(b) for b in bounds)
    if not (xmin < xmax and ymin < ymax):
        raise ParameterError(f"workspace bounds {bounds} must satisfy xmin < xmax, ymin < ymax")
    span = max(xmax - xmin, ymax - ymin)
    nx = max(10, int(round(resolution * (xmax - xmin) / span)))
    ny = max(10, int(round(resolution * (ymax - ymin) / span)))
    x = np.linspace(xmin, xmax, nx)
    y = np.linspace(ymin, ymax, ny)
    X, Y = np.meshgrid(x, y)
    half = 0.5 * robot.d
    phi, _, bad1 = _leg_solve(X - half, Y, robot.l1, robot.L1, signs[0])
    psi, _, bad2 = _leg_solve(X + half, Y, robot.l2, robot.L2, signs[1])
    reachable = ~(bad1 | bad2)
    # A rows (P - B), (P - C); B = diag(b1, b2)
    ux = X - (half + robot.l1 * np.cos(phi))
    uy = Y - robot.l1 * np.sin(phi)
    vx = X - (-half + robot.l2 * np.cos(psi))
    vy = Y - robot.l2 * np.sin(psi)
    b1 = robot.l1 * (np.cos(phi) * uy - np.sin(phi) * ux)
    b2 = robot.l2 * (np.cos(psi) * vy - np.sin(psi) * vx)
    det = ux * vy - uy * vx
    type2 = np.where(reachable, det / (robot.L1 * robot.L2), 0.0)
    # J is proportional to adj(A) B; the condition number ignores the factor 1/det A.
    dex = inverse_condition(vy * b1, -uy * b2, -vx * b1, ux * b2)
    dex = np.where(reachable, dex, 0.0)
    return WorkspaceMap(robot, x, y, reachable, type2, dex, working_mode_name(signs))
