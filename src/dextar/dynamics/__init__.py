"""Dynamics: inertial parameters, exact inverse and forward dynamics, the paper's model."""

from .along_path import RobotAlongJointLine, RobotAlongPath, time_optimal_law
from .exact import (
    Model,
    Reactions,
    TorqueResult,
    bias_forces,
    gravity_torques,
    inverse_dynamics,
    joint_reactions,
    kinetic_energy,
    mass_matrix,
    state_dynamics,
    trajectory_torques,
)
from .inertia import Inertia, Rod, paper_inertia

__all__ = ["Inertia", "Model", "Reactions", "Rod", "bias_forces", "gravity_torques",
           "inverse_dynamics", "joint_reactions", "kinetic_energy", "mass_matrix",
           "paper_inertia", "state_dynamics", "TorqueResult", "trajectory_torques", "RobotAlongJointLine", "RobotAlongPath", "time_optimal_law"]
