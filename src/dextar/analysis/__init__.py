"""Every computed metric and claim: the run's analysis, its physics checks and its summary."""

from .core import (
    POWER_BALANCE_TOL,
    REPLAY_TOL,
    STEP_DEPENDENCE,
    Analysis,
    PaperComparison,
    RunInputs,
    analyze,
    forward_error,
    forward_replay,
    power_balance_residual,
    power_balance_residuals,
    power_balance_times,
    replay_windows,
    torque_limit_ratio,
)
from .summary import is_paper_example, law_summary, run_summary, validation

__all__ = ["POWER_BALANCE_TOL", "REPLAY_TOL", "STEP_DEPENDENCE", "Analysis", "PaperComparison", "RunInputs",
           "analyze", "forward_error", "forward_replay", "replay_windows",
           "is_paper_example", "law_summary", "power_balance_residual", "power_balance_residuals",
           "power_balance_times",
           "run_summary", "torque_limit_ratio", "validation"]
