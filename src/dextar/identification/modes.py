"""Measured motion that stays in one working mode and one assembly mode, checked at every row.

The data hold the motor angles only; the end-effector is computed from them in the model's
assembly mode. Three ways the data can leave the model:

* **The rods cannot meet** at some row's angles (``|B - C|`` outside ``[|L1 - L2|, L1 + L2]``):
  not this robot's geometry, or angles in another zero or unit.
* **A working-mode change** (a leg stretched or folded through a serial singularity): the sign
  of ``(B - A) x (P - B)`` or ``(C - D) x (P - C)`` changes at a row.
* **An assembly-mode change** (B, C and P aligned: a parallel singularity crossed). From the
  angles alone the pose computed in a fixed assembly mode never changes its side, but its
  type-2 distance ``|(P - B) x (P - C)| / (L1 L2)`` (the same in both assembly modes) then
  touches zero with a corner: the robot's true signed indicator passes smoothly through
  zero, so the unsigned one computed here has a V. At every local minimum of the distance
  below :data:`NEAR` the samples around it are compared with the same samples with the sign
  flipped after the minimum; when the flipped sequence is the smoother (smaller largest
  second difference) the motion crossed, and the row and time are named. A near approach
  that does not cross stays smooth unflipped (its minimum is a parabola's). Where the
  encoder's noise hides the corner (within :data:`TOUCH` of the singularity) the data are
  refused as too near to tell.
"""

from __future__ import annotations

import math

import numpy as np

from .._arrays import Array
from ..dynamics.exact import Model
from ..errors import ParameterError
from ..geometry import parse_working_mode
from ..kinematics import direct_kinematics, elbows, working_mode
from .data import MotionData

#: Local minima of the type-2 distance below this are examined for a crossing.
NEAR = 0.2
#: Type-2 distance below which the data are too near a parallel singularity to tell the
#: assembly mode (encoder noise there: 0.013 for 17 bits; a crossing at 1 kHz leaves a sample
#: within 0.002 of it at 0.3 m/s, within 0.02 at 3 m/s).
TOUCH = 0.02
#: Relative amount (of ``L1 + L2``) by which the rods may miss each other at a row and still
#: count as meeting at a parallel singularity (encoder counts at a crossing: 2e-5 for 17 bits).
MEET_TOL = 1e-4


def _where(data: MotionData, i: int) -> str:
    return f"{data.source}: row {i + 2} (t = {data.t[i]:.6g} s)"


def _angles(data: MotionData, i: int) -> str:
    return (f"phi = {math.degrees(data.q[i, 0]):.6g} deg, psi = "
            f"{math.degrees(data.q[i, 1]):.6g} deg")


def _type2(q: Array, model: Model) -> Array:
    """Type-2 distance (n,) of the angles ``q`` (n, 2), the same in both assembly modes: the
    sine of the angle at P of the triangle B, C, P (0 where the rods are aligned, and where
    they miss each other by a hair)."""
    r = model.robot
    B, C = elbows(r, q)
    d2 = ((B - C) ** 2).sum(axis=1)
    c = (r.L1 ** 2 + r.L2 ** 2 - d2) / (2 * r.L1 * r.L2)
    return np.asarray(np.sqrt(np.clip(1.0 - c * c, 0.0, None)))


def parallel_crossings(q: Array, model: Model) -> Array:
    """Indices ``i`` (k,) such that the motion of the angles ``q`` (n, 2) crosses a parallel
    singularity between samples ``i`` and ``i + 1`` (see the module doc)."""
    if len(q) < 5:
        return np.zeros(0, int)
    s = _type2(q, model)
    mid = s[1:-1]
    minima = np.flatnonzero((mid <= s[:-2]) & (mid < s[2:]) & (mid < NEAR)) + 1
    minima = minima[(minima >= 2) & (minima <= len(s) - 3)]
    if not len(minima):
        return np.zeros(0, int)
    # the five samples around each minimum; the flip goes after the minimum or before it,
    # on the side of its lower neighbour
    win = s[minima[:, None] + np.arange(-2, 3)[None, :]]
    after = win[:, 3] <= win[:, 1]
    flip = np.where(after[:, None], np.arange(5)[None, :] >= 3, np.arange(5)[None, :] >= 2)
    flipped = np.where(flip, -win, win)

    def roughness(x: Array) -> Array:
        return np.asarray(np.abs(x[:, :-2] - 2 * x[:, 1:-1] + x[:, 2:]).max(axis=1))

    crossed = roughness(flipped) < roughness(win)
    return np.asarray(np.where(after, minima, minima - 1)[crossed])


def check_modes(data: MotionData, model: Model, mode: str) -> None:
    """Raise :class:`ParameterError` at the first row whose angles leave the model: rods
    that cannot meet, a working mode other than ``mode``, or a parallel singularity crossed
    (an assembly-mode change), naming the row, the time and the angles.

    Parameters
    ----------
    data : MotionData
    model : Model
        Geometry and assembly mode.
    mode : str
        The working mode the data must stay in (e.g. ``"+-"``).
    """
    r = model.robot
    B, C = elbows(r, data.q)
    d = np.hypot(*(B - C).T)
    lo, hi = abs(r.L1 - r.L2), r.L1 + r.L2
    tol = MEET_TOL * hi
    problems: list[tuple[int, str]] = []
    apart = ~((d >= lo - tol) & (d <= hi + tol))
    if apart.any():
        i = int(np.flatnonzero(apart)[0])
        problems.append((i, f"{_where(data, i)}: the distal rods cannot meet at {_angles(data, i)} "
                            f"(|B - C| = {1e3 * d[i]:.6g} mm outside [{1e3 * lo:.6g}, "
                            f"{1e3 * hi:.6g}] mm): not this robot's geometry, or angles in "
                            "another zero or unit"))
        n = i  # the rows before it can be checked
    else:
        n = len(data.t)
    if n:
        q = data.q[:n]
        meet = (d[:n] >= lo) & (d[:n] <= hi)  # rows a hair apart are at a singularity
        want = np.array(parse_working_mode(mode))
        P = np.full(q.shape, np.nan)
        P[meet] = direct_kinematics(r, q[meet], model.assembly)
        got = np.zeros(q.shape, int)
        got[meet] = working_mode(r, q[meet], P[meet])
        bad = meet & ~(got == want).all(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            sgn = "".join("+" if v > 0 else "-" if v < 0 else "0" for v in got[i])
            problems.append((i, f"{_where(data, i)} is in working mode {sgn}, not {mode}: "
                                f"{_angles(data, i)}, P = ({1e3 * P[i, 0]:.6g}, "
                                f"{1e3 * P[i, 1]:.6g}) mm"))
        cross = parallel_crossings(q, model)
        if len(cross):
            i = int(cross[0])
            j = min(i + 1, n - 1)
            problems.append((i, f"{_where(data, i)}: the motion crosses a parallel (type 2) "
                                f"singularity between rows {i + 2} and {j + 2} (t = "
                                f"{data.t[i]:.6g} to {data.t[j]:.6g} s, {_angles(data, i)}): "
                                f"the robot changed assembly mode there, the model's "
                                f"{model.assembly!r} no longer describes it; identify from "
                                "data that stay in one mode"))
        else:  # a corner hidden by noise: too near to tell
            near = _type2(q, model)
            touch = near < TOUCH
            if touch.any():
                i = int(np.flatnonzero(touch)[0])
                problems.append((i, f"{_where(data, i)}: the motion comes within {near[i]:.3g} "
                                    f"of a parallel (type 2) singularity (limit {TOUCH:g}) at "
                                    f"{_angles(data, i)}: it may cross there and change "
                                    "assembly mode, which the angles cannot tell; identify "
                                    "from data that stay farther from it"))
    if problems:
        raise ParameterError(min(problems)[1])
