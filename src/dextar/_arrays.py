"""Small array helpers shared by the stages: input validation and naming a sample."""

from __future__ import annotations

from typing import Any, TypeAlias

import numpy as np

from .errors import ParameterError

#: A NumPy array (any shape and dtype; dextar computes in float64).
Array: TypeAlias = np.ndarray[Any, Any]


def as_points(values: object, name: str, *, finite: bool = True) -> Array:
    """Float array of shape (..., 2), finite (unless ``finite`` is False: the caller checks,
    with :func:`check_finite`); raises naming ``name`` and the first bad index."""
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 0 or arr.shape[-1] != 2:
        raise ParameterError(f"{name} must have shape (..., 2), got {arr.shape}")
    if finite:
        check_finite(arr, name)
    return arr


def check_whole(value: object, least: int, name: str, unit: str = "") -> None:
    """Raise naming ``name`` unless ``value`` (a number or a 0-d array) is real, whole and at
    least ``least`` (NaN, infinity, None, text and bools too, rather than Python's own
    errors; text quoted in the message)."""
    v = value.item() if isinstance(value, np.ndarray) and value.ndim == 0 else value
    if not (isinstance(v, (int, float, np.integer, np.floating))
            and not isinstance(v, (bool, np.bool_))
            and np.isfinite(v) and int(v) == v and v >= least):
        shown = repr(value) if isinstance(value, str) else value
        raise ParameterError(f"{name} = {shown} must be a whole number of at least "
                             f"{least}{unit}")


def check_finite(arr: Array, name: str) -> None:
    if not np.isfinite(arr).all():
        idx = first_index(~np.isfinite(arr))
        raise ParameterError(f"{name} has a non-finite value at index {idx}")


def first_index(mask: Array) -> tuple[int, ...] | int:
    """Index of the first True of ``mask`` (an int for 1-D or 0-D masks, else a tuple)."""
    flat = int(np.flatnonzero(mask)[0])
    if mask.ndim <= 1:
        return flat
    return tuple(int(i) for i in np.unravel_index(flat, mask.shape))


def where(index: tuple[int, ...] | int, shape: tuple[int, ...]) -> str:
    """Words that place a sample: '' for a single one, else 'at index i'."""
    return "" if shape == () else f" at index {index}"


def cross(ax: Array, ay: Array, bx: Array, by: Array) -> Array:
    """Z component of the 2-D cross product a x b."""
    return np.asarray(ax * by - ay * bx)


#: Samples per block in the vectorised kernels: blocks this size stay in cache.
CHUNK = 32768


def cos_sin(angle: Array) -> tuple[Array, Array]:
    """``(cos, sin)`` of ``angle`` through the half-angle tangent (one ``tan`` instead of a
    ``cos`` and a ``sin``: several times faster in NumPy, accurate to a few ulp)."""
    t = np.tan(0.5 * angle)
    t2 = t * t
    inv = 1.0 / (1.0 + t2)
    return (1.0 - t2) * inv, 2.0 * t * inv


def blocks(n: int, size: int = CHUNK) -> list[slice]:
    """Slices that cover ``range(n)`` in blocks of ``size``."""
    return [slice(i, min(i + size, n)) for i in range(0, n, size)] or [slice(0, 0)]


def flat_index(i: int, shape: tuple[int, ...]) -> tuple[int, ...] | int:
    """A flat sample index in the words of the original leading shape."""
    if len(shape) <= 1:
        return i
    return tuple(int(k) for k in np.unravel_index(i, shape))
