"""Simulation and control: the robot driven by a controller on its exact dynamics."""

from .control import (
    TRACKING_TOLERANCE,
    ControlResult,
    simulate_computed_torque,
    tracking_tolerance,
)

__all__ = ["TRACKING_TOLERANCE", "ControlResult", "simulate_computed_torque",
           "tracking_tolerance"]
