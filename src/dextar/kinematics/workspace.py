"""Workspace of a working mode: reachability, singularity curves and dexterity on a grid."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

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
    x: np.ndarray
    y: np.ndarray
    reachable: np.ndarray
    type2: np.ndarray
    dexterity: np.ndarray
    mode: str

    @property
    def reachable_area(self) -> float:
        dx = self.x[1] - self.x[0]
        dy = self.y[1] - self.y[0]
        return float(self.reachable.sum() * dx * dy)


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
    m11, m12, m21, m22 = vy * b1, -uy * b2, -vx * b1, ux * b2
    fro2 = m11**2 + m12**2 + m21**2 + m22**2
    detm = np.abs(m11 * m22 - m12 * m21)
    disc = np.sqrt(np.maximum(fro2 * fro2 - 4.0 * detm * detm, 0.0))
    smax2 = 0.5 * (fro2 + disc)
    smin2 = np.maximum(0.5 * (fro2 - disc), 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        dex = np.sqrt(np.where(smax2 > 0, smin2 / smax2, 0.0))
    dex = np.where(reachable, dex, 0.0)
    return WorkspaceMap(robot, x, y, reachable, type2, dex, working_mode_name(signs))


def plot_workspace(
    ws: WorkspaceMap,
    *,
    path: np.ndarray | None = None,
    pose: tuple[np.ndarray, np.ndarray] | None = None,
    unit: str = "mm",
    ax: Any = None,
) -> Any:
    """Draw a :class:`WorkspaceMap`: dexterity colour map, type-1 circles (dashed blue),
    type-2 curves (red), pivots, and optionally a path (n, 2) and a pose ``(q, P)``.

    Returns the matplotlib figure.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 5.6))
    else:
        fig = ax.figure
    r = ws.robot
    dex = np.ma.masked_where(~ws.reachable, ws.dexterity)
    im = ax.pcolormesh(ws.x, ws.y, dex, shading="auto", cmap="viridis", vmin=0, vmax=1)
    fig.colorbar(im, ax=ax, label="dexterity (inverse condition number of J)")
    t2 = np.ma.masked_where(~ws.reachable, ws.type2)
    if np.any(t2 > 0) and np.any(t2 < 0):
        ax.contour(ws.x, ws.y, t2, levels=[0.0], colors="red", linewidths=1.5)
    theta = np.linspace(0, 2 * np.pi, 361)
    for centre, l, L in ((r.A, r.l1, r.L1), (r.D, r.l2, r.L2)):
        for rad in {abs(l - L), l + L}:
            if rad > 0:
                ax.plot(
                    centre[0] + rad * np.cos(theta), centre[1] + rad * np.sin(theta), "b--", lw=0.8
                )
    ax.plot([r.A[0], r.D[0]], [0, 0], "ks", ms=6)
    ax.plot([], [], "r-", label="type-2 (parallel) singularity")
    ax.plot([], [], "b--", label="type-1 (serial) singularity")
    if path is not None:
        path = np.asarray(path)
        ax.plot(path[:, 0], path[:, 1], "w-", lw=2.5)
        ax.plot(path[:, 0], path[:, 1], "k-", lw=1.2, label="path")
    if pose is not None:
        from .positions import elbows

        q, P = pose
        B, C = elbows(r, q)
        ax.plot(
            [r.A[0], B[0], P[0], C[0], r.D[0]],
            [r.A[1], B[1], P[1], C[1], r.D[1]],
            "o-",
            color="orange",
            lw=2,
        )
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")
    ax.set_title(f'Workspace, working mode "{ws.mode}"')
    ax.legend(loc="lower right", fontsize=8)
    return fig
