"""Arcs of a robot program's moves: through three points, or about a centre from one point to
another (any length unit; the points as arrays of shape (2,))."""

from __future__ import annotations

import math

import numpy as np

from .._arrays import Array
from ..errors import GeometryError
from .base import Arc


def arc_through(start: Array, via: Array, end: Array) -> Arc:
    """The arc from ``start`` through ``via`` to ``end`` (the circle through the three
    points, in the direction that passes ``via``).

    Raises
    ------
    GeometryError
        The three points are collinear (no circle passes through them).
    """
    P0, V, P1 = (np.asarray(x, float) for x in (start, via, end))
    a, b = V - P0, P1 - P0
    den = 2.0 * (a[0] * b[1] - a[1] * b[0])
    scale = max(float(np.linalg.norm(a)), float(np.linalg.norm(b)), 1e-300)
    if abs(den) <= 1e-9 * scale**2:
        raise GeometryError("the start, 'via' and 'to' points are collinear: no circle passes "
                            "through them")
    cx = (b[1] * (a @ a) - a[1] * (b @ b)) / den
    cy = (a[0] * (b @ b) - b[0] * (a @ a)) / den
    return _arc(P0, P1, P0 + np.array([cx, cy]), clockwise=bool(den < 0))


def arc_about(start: Array, center: Array, end: Array, *, clockwise: bool = False,
              unit: str = "", scale: float = 1.0) -> Arc:
    """The arc about ``center`` from ``start`` to ``end`` (a whole turn when they coincide),
    counter-clockwise unless ``clockwise``. ``unit`` and ``scale`` only word an error (the
    distances times ``scale``, in ``unit``).

    Raises
    ------
    GeometryError
        ``start`` and ``end`` are not on one circle about ``center`` (to 1e-6 relative).
    """
    P0, C, P1 = (np.asarray(x, float) for x in (start, center, end))
    r0, r1 = np.linalg.norm(P0 - C), np.linalg.norm(P1 - C)
    if abs(r0 - r1) > 1e-6 * max(r0, r1):
        raise GeometryError(f"'to' is {r1 * scale:.6g}{unit} from the centre but the start is "
                            f"{r0 * scale:.6g}{unit} from it: not on one circle")
    return _arc(P0, P1, C, clockwise=clockwise)


def _arc(P0: Array, P1: Array, C: Array, *, clockwise: bool) -> Arc:
    R = float(np.linalg.norm(P0 - C))
    a0 = math.atan2(P0[1] - C[1], P0[0] - C[0])
    a1 = math.atan2(P1[1] - C[1], P1[0] - C[0])
    if clockwise:
        a0, a1 = -a0, -a1
    sweep = (a1 - a0) % (2 * math.pi)
    if sweep <= 1e-12:
        sweep = 2 * math.pi
    return Arc(R, a0, a0 + sweep, center=(float(C[0]), float(C[1])), clockwise=clockwise)
