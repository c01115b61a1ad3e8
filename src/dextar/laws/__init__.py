"""Laws of motion along a path (arc length against time)."""

from .base import Law, MinimumJerkLaw, TrapezoidalLaw, UniformLaw, law_cost
from .optimal import OptimalLaw, line_solution, solve_optimal_law

__all__ = ["Law", "MinimumJerkLaw", "OptimalLaw", "TrapezoidalLaw", "UniformLaw", "law_cost",
           "line_solution", "solve_optimal_law"]
