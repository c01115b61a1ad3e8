"""Plane paths with exact derivatives, arc length and curvature, registered by config name."""

from .base import Arc, ExpressionPath, Line, Path, Spline
from .composite import Composite, blended
from .expression import Expression
from .registry import PATH_TYPES, PathType, path_type, register_path

__all__ = ["PATH_TYPES", "Arc", "Composite", "Expression", "ExpressionPath", "Line", "Path",
           "PathType", "Spline", "blended", "path_type", "register_path"]
