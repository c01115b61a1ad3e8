"""Robot programs: a sequence of moves under the motors, its setpoints and motor sizing."""

from .plan import MOVE_TYPES, Move, PlannedMove, ProgramResult, plan_program, sizing

__all__ = ["MOVE_TYPES", "Move", "PlannedMove", "ProgramResult", "plan_program", "sizing"]
