"""Laws of motion along a path (arc length against time), registered by config name."""

from ..motors import MotorLimits
from ..params import REQUIRED, Param
from .base import Law, LawResult, MinimumJerkLaw, TrapezoidalLaw, UniformLaw, law_cost
from .constraints import (
    AccelerationLimit,
    Constraint,
    JerkLimit,
    JointSamples,
    PathCoefficients,
    PathDynamics,
    SpeedLimit,
    TorqueLimit,
    TorqueRateLimit,
    TorqueSpeedEnvelope,
    motor_constraints,
)
from .optimal import OptimalLaw, line_solution, solve_optimal_law
from .registry import LAW_TYPES, LawRequest, LawType, law_type, register_law
from .smooth import JerkLimitedLaw, solve_jerk_limited_law
from .time_optimal import TimeOptimalLaw, solve_time_optimal_law

__all__ = ["LAW_TYPES", "REQUIRED", "AccelerationLimit", "Constraint", "JerkLimit",
           "JerkLimitedLaw", "JointSamples", "Law", "LawRequest",
           "LawResult", "LawType", "MinimumJerkLaw", "MotorLimits", "OptimalLaw", "Param",
           "PathCoefficients", "PathDynamics", "SpeedLimit", "TimeOptimalLaw", "TorqueLimit",
           "TorqueRateLimit", "TorqueSpeedEnvelope", "TrapezoidalLaw", "UniformLaw", "law_cost", "law_type",
           "line_solution", "motor_constraints", "register_law", "solve_jerk_limited_law",
           "solve_optimal_law", "solve_time_optimal_law"]
