"""Plane paths with exact derivatives, arc length and curvature, registered by config name."""

from .base import Arc, ExpressionPath, Line, Path, Spline
from .expression import Expression
from .registry import PATH_TYPES, PathType, path_type, register_path

__all__ = ["PATH_TYPES", "Arc", "Expression", "ExpressionPath", "Line", "Path", "PathType",
           "Spline", "path_type", "register_path"]
