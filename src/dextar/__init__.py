"""dextar: kinematics, optimal motion and dynamics of five-bar parallel robots (DexTAR)."""

from .errors import (
    AssemblyError,
    ConfigError,
    ConvergenceError,
    DextarError,
    GeometryError,
    InfeasibleError,
    NumericalError,
    ParameterError,
    ReachError,
    SingularityError,
)
from .geometry import DEXTAR_MM, FiveBar, preset
from .kinematics import (
    assembly_mode,
    direct_kinematics,
    elbows,
    inverse_kinematics,
    jacobian,
    joint_acceleration,
    joint_velocity,
    singularity_distances,
    task_acceleration,
    task_velocity,
    velocity_matrices,
    working_mode,
    workspace_map,
)

__version__ = "0.1.0"

__all__ = [
    "DEXTAR_MM",
    "AssemblyError",
    "ConfigError",
    "ConvergenceError",
    "DextarError",
    "FiveBar",
    "GeometryError",
    "InfeasibleError",
    "NumericalError",
    "ParameterError",
    "ReachError",
    "SingularityError",
    "assembly_mode",
    "direct_kinematics",
    "elbows",
    "inverse_kinematics",
    "jacobian",
    "joint_acceleration",
    "joint_velocity",
    "preset",
    "singularity_distances",
    "task_acceleration",
    "task_velocity",
    "velocity_matrices",
    "workspace_map",
    "working_mode",
]
