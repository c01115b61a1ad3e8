"""Laws of motion along a path (arc length against time), registered by config name."""

from ..params import REQUIRED, Param
from .base import Law, LawResult, MinimumJerkLaw, TrapezoidalLaw, UniformLaw, law_cost
from .optimal import OptimalLaw, line_solution, solve_optimal_law
from .registry import LAW_TYPES, LawRequest, LawType, law_type, register_law
from .time_optimal import (
    MotorLimits,
    PathCoefficients,
    PathDynamics,
    TimeOptimalLaw,
    solve_time_optimal_law,
)

__all__ = ["LAW_TYPES", "REQUIRED", "Law", "LawRequest", "LawResult", "LawType", "MinimumJerkLaw", "MotorLimits",
           "OptimalLaw", "Param", "PathCoefficients", "PathDynamics", "TimeOptimalLaw",
           "TrapezoidalLaw", "UniformLaw", "law_cost", "law_type", "line_solution",
           "register_law", "solve_optimal_law", "solve_time_optimal_law"]
