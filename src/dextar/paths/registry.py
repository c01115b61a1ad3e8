"""Path types by their config name (``[path].type``): each declares its keys and builds a
:class:`~dextar.paths.base.Path` in the run's units.

A new path type is one :func:`register_path` call: the config files, the command line's help
and the docs list the types from here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from ..params import REQUIRED, Param
from ..registry import Registry
from ..units import Units
from .base import Arc, ExpressionPath, Line, Path, Spline


@dataclass(frozen=True)
class PathType:
    """A registered path type.

    Attributes
    ----------
    name : str
        Its config name (``[path].type``).
    params : mapping of str to Param
        Its config keys.
    build : callable
        ``build(values, units) -> Path``: the values in run units (see
        :func:`dextar.params.to_run_units`) and the run's units.
    help : str
        One line for the docs.
    """

    name: str
    params: Mapping[str, Param]
    build: Callable[[Mapping[str, Any], Units], Path]
    help: str = ""


#: The path types by config name; installed packages add theirs through the entry-point
#: group ``dextar.paths``.
PATH_TYPES: Registry[PathType] = Registry("path type", "config key [path].type",
                                          group="dextar.paths")


def register_path(kind: PathType) -> PathType:
    """Add a path type to the registry (a later registration of the same name replaces it)."""
    return PATH_TYPES.register(kind)


def path_type(name: object, where: str | None = None) -> PathType:
    """The registered type ``name``; an :class:`~dextar.registry.UnknownNameError` (a
    :class:`~dextar.errors.ConfigError`) naming ``where`` lists the known ones."""
    return PATH_TYPES.lookup(name, where)


register_path(PathType(
    "arc", {"radius": Param("number", "mm", 120.0, "radius", positive=True),
            "center": Param("point", "mm", (0.0, 0.0), "centre [x, y]"),
            "start_deg": Param("number", "deg", 0.0, "polar angle at the start"),
            "end_deg": Param("number", "deg", 180.0, "polar angle at the end (> start)")},
    lambda v, u: Arc(v["radius"], v["start_deg"], v["end_deg"], center=v["center"]),
    "circular arc about a centre, from start_deg to end_deg (counter-clockwise)"))
register_path(PathType(
    "line", {"start": Param("point", "mm", REQUIRED, "first point [x, y]"),
             "end": Param("point", "mm", REQUIRED, "last point [x, y]")},
    lambda v, u: Line(v["start"], v["end"]), "straight segment"))
register_path(PathType(
    "spline", {"waypoints": Param("points", "mm", REQUIRED, "points [[x, y], ...]")},
    lambda v, u: Spline(v["waypoints"]),
    "quintic (C4) spline through waypoints; two waypoints give the segment"))
register_path(PathType(
    "expression", {"x": Param("text", "", REQUIRED, "x(p) in mm, text in p"),
                   "y": Param("text", "", REQUIRED, "y(p) in mm, text in p"),
                   "p0": Param("number", "", 0.0, "first value of p"),
                   "p1": Param("number", "", 1.0, "last value of p (> p0)")},
    lambda v, u: ExpressionPath(v["x"], v["y"], v["p0"], v["p1"], scale=u.length(1.0)),
    "x(p), y(p) as text (numbers, p, pi, e, + - * / **, sin cos tan exp log sqrt sinh cosh "
    "tanh asin acos atan), differentiated symbolically"))
