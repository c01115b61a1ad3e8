"""Kinematics of the five-bar: positions, velocities, accelerations, singularities, workspace."""

from .positions import assembly_mode, direct_kinematics, elbows, inverse_kinematics, working_mode
from .velocity import (
    DEFAULT_SINGULARITY_TOL,
    check_singularities,
    jacobian,
    joint_acceleration,
    joint_rates,
    joint_velocity,
    parallel_indicator,
    singularity_distances,
    task_acceleration,
    task_velocity,
    velocity_matrices,
)
from .workspace import WorkspaceMap, workspace_map

__all__ = [
    "DEFAULT_SINGULARITY_TOL",
    "WorkspaceMap",
    "assembly_mode",
    "check_singularities",
    "direct_kinematics",
    "elbows",
    "inverse_kinematics",
    "jacobian",
    "joint_acceleration",
    "joint_rates",
    "joint_velocity",
    "parallel_indicator",
    "singularity_distances",
    "task_acceleration",
    "task_velocity",
    "velocity_matrices",
    "workspace_map",
    "working_mode",
]
