"""Synthetic measurements: a perturbed "real" robot measured by a noisy instrument, to plan a
calibration (what accuracy do these poses give?) and to test one."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .._arrays import Array
from ..errors import ParameterError
from ..geometry import FiveBar, working_mode_name
from .data import PoseData
from .model import KinematicModel, closure


def perturbed(nominal: KinematicModel, rng: np.random.Generator, *,
              length_error: float = 0.5e-3, offset_error: float = math.radians(0.5),
              frame: tuple[float, float, float] | None = None) -> KinematicModel:
    """A "real" robot near ``nominal``: each length off by up to ``length_error`` (m),
    each encoder offset by up to ``offset_error`` (rad), uniformly; the instrument frame
    ``frame`` ``(x0, y0, theta0)`` (m, m, rad) or a random one (within 0.5 m, any angle)."""
    r = nominal.robot
    dl = rng.uniform(-length_error, length_error, 5)
    robot = FiveBar(*(v + e for v, e in zip((r.l1, r.l2, r.L1, r.L2, r.d), dl, strict=True)))
    do = rng.uniform(-offset_error, offset_error, 2)
    if frame is None:
        frame = (float(rng.uniform(-0.5, 0.5)), float(rng.uniform(-0.5, 0.5)),
                 float(rng.uniform(-math.pi, math.pi)))
    return replace(nominal, robot=robot, phi_offset=nominal.phi_offset + float(do[0]),
                   psi_offset=nominal.psi_offset + float(do[1]), x0=float(frame[0]),
                   y0=float(frame[1]), theta0=float(frame[2]))


def measure(true: KinematicModel, readings: object, assembly: object,
            rng: np.random.Generator, *, point_std: float, count: float = 0.0,
            frame: str = "instrument", source: str = "synthetic") -> PoseData:
    """The poses the instrument measures on the robot ``true`` at encoder readings.

    Parameters
    ----------
    true : KinematicModel
        The real robot, encoder offsets and instrument frame.
    readings : array_like, shape (n, 2)
        The readings the robot really is at (rad), e.g. commanded ones.
    assembly : array_like of int, shape (n,) or scalar
        +1 (up) or -1 (down).
    rng : numpy.random.Generator
    point_std : float
        Gaussian noise of the measured points per axis (m).
    count : float
        One encoder count (rad): the recorded readings are off by up to one count
        (uniform in ``[-count, count]``).
    frame : {"instrument", "robot"}
        The frame of the measured points.

    Returns
    -------
    PoseData
        Recorded readings, measured points, the true working modes and assembly modes.
    """
    r = np.asarray(readings, dtype=float).reshape(-1, 2)
    k = closure(true, r, assembly)
    k.raise_if_open()
    P = true.to_instrument(k.P) if frame == "instrument" else k.P
    if frame not in ("instrument", "robot"):
        raise ParameterError(f"frame {frame!r} must be 'instrument' or 'robot'")
    M = P + rng.normal(scale=point_std, size=P.shape)
    rec: Array = r + rng.uniform(-count, count, size=r.shape)
    signs = k.working_mode()
    modes = tuple(working_mode_name((int(a), int(b))) for a, b in signs)
    return PoseData(rec, M, modes, k.sigma, source=source)
