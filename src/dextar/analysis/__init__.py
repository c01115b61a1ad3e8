"""Every computed metric and claim: the run's analysis, its physics checks and its summary."""

from .core import (
    Analysis,
    PaperComparison,
    RunInputs,
    analyze,
    forward_error,
    power_balance_residual,
    power_balance_times,
    torque_limit_ratio,
)
from .summary import is_paper_example, law_summary, run_summary, validation

__all__ = ["Analysis", "PaperComparison", "RunInputs", "analyze", "forward_error",
           "is_paper_example", "law_summary", "power_balance_residual", "power_balance_times",
           "run_summary", "torque_limit_ratio", "validation"]
