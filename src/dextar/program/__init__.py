"""Robot programs: a sequence of moves under the motors, its setpoints and motor sizing."""

from . import move_types as _builtin  # noqa: F401 - registers line, arc, dwell, joint
from .moves import MOVE_TYPES, Move, MoveType, move_type, register_move
from .plan import (
    AUTO,
    ModeChoice,
    MovePlan,
    MoveTiming,
    PlanContext,
    PlannedMove,
    PlanState,
    ProgramRequest,
    ProgramResult,
    RmsFit,
    fit_rms,
    plan_program,
)
from .sizing import MotorSizing, Sizing, Violation, sizing

__all__ = ["AUTO", "MOVE_TYPES", "ModeChoice", "MotorSizing", "Move", "MovePlan", "MoveTiming", "MoveType",
           "PlanContext", "PlanState", "PlannedMove", "ProgramRequest", "ProgramResult", "RmsFit",
           "Sizing", "Violation", "fit_rms", "move_type", "plan_program", "register_move",
           "sizing"]
