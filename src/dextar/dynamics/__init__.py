"""Dynamics: inertial parameters, exact inverse and forward dynamics, the paper's model."""

from typing import TYPE_CHECKING

from .._lazy import lazy_attributes
from .exact import (
    Model,
    Reactions,
    TorqueResult,
    accelerations,
    bias_forces,
    gravity_torques,
    inverse_dynamics,
    joint_reactions,
    kinetic_energy,
    mass_matrix,
    state_dynamics,
    trajectory_torques,
)
from .inertia import Counterweight, Inertia, Rod, paper_inertia

if TYPE_CHECKING:
    from .along_path import RobotAlongJointLine, RobotAlongPath, time_optimal_law

# The robot along a path plans laws (dextar.laws, dextar.paths): imported when first used,
# so that the model, its inertia and its exact dynamics (a calibration's model file, an
# identification) load no law or path module.
__getattr__, __dir__ = lazy_attributes(__name__, dict.fromkeys(
    ("RobotAlongJointLine", "RobotAlongPath", "time_optimal_law"), ".along_path"))


__all__ = ["Counterweight", "Inertia", "Model", "Reactions", "Rod", "accelerations", "bias_forces", "gravity_torques",
           "inverse_dynamics", "joint_reactions", "kinetic_energy", "mass_matrix",
           "paper_inertia", "state_dynamics", "TorqueResult", "trajectory_torques", "RobotAlongJointLine", "RobotAlongPath", "time_optimal_law"]
