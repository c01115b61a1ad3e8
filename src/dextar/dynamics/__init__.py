"""Dynamics: inertial parameters, exact inverse and forward dynamics, the paper's model."""

from typing import TYPE_CHECKING, Any

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

if TYPE_CHECKING:
    from .along_path import RobotAlongJointLine, RobotAlongPath, time_optimal_law

#: The robot along a path, imported on first use: it plans laws, and the laws bring scipy,
#: which the model, its inertia and its exact dynamics do not need.
_ALONG_PATH = ("RobotAlongJointLine", "RobotAlongPath", "time_optimal_law")


def __getattr__(name: str) -> Any:
    if name in _ALONG_PATH:
        from . import along_path

        return getattr(along_path, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["Inertia", "Model", "Reactions", "Rod", "bias_forces", "gravity_torques",
           "inverse_dynamics", "joint_reactions", "kinetic_energy", "mass_matrix",
           "paper_inertia", "state_dynamics", "TorqueResult", "trajectory_torques", "RobotAlongJointLine", "RobotAlongPath", "time_optimal_law"]
