"""Dynamics: inertial parameters, exact inverse and forward dynamics, the paper's model."""

from .along_path import RobotAlongPath, time_optimal_law
from .exact import (
    Model,
    Reactions,
    bias_forces,
    gravity_torques,
    inverse_dynamics,
    joint_reactions,
    kinetic_energy,
    mass_matrix,
    state_dynamics,
)
from .inertia import Inertia, Rod, paper_inertia

__all__ = ["Inertia", "Model", "Reactions", "Rod", "bias_forces", "gravity_torques",
           "inverse_dynamics", "joint_reactions", "kinetic_energy", "mass_matrix",
           "paper_inertia", "state_dynamics", "RobotAlongPath", "time_optimal_law"]
