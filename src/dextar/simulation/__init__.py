"""Simulation and control: the robot driven by a controller on its exact dynamics."""

from .control import ControlResult, simulate_computed_torque

__all__ = ["ControlResult", "simulate_computed_torque"]
