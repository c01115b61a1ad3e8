"""Plane paths with exact derivatives, arc length and curvature."""

from .base import Arc, ExpressionPath, Line, Path, Spline
from .expression import Expression

__all__ = ["Arc", "Expression", "ExpressionPath", "Line", "Path", "Spline"]
