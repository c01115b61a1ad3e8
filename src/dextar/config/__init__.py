"""Config files: each TOML table ``[table]`` is a frozen dataclass registered in
:data:`TABLES` (a new table is a dataclass and one :func:`register_table` line), read and
validated when the file is read; a :class:`Scenario` composes them and builds the run's,
a program's and a sweep's objects.

The names below are imported from their modules when first used, so that a command that
reads only the robot's tables (:mod:`dextar.config.kinematic`) does not import the laws,
paths and dynamics a whole scenario builds.
"""

from typing import TYPE_CHECKING

from .._lazy import lazy_attributes

if TYPE_CHECKING:
    from .base import TABLES, Table, register_table
    from .kinematic import (
        InstrumentTable,
        KinematicConfig,
        RobotTable,
        kinematic_model,
        load_kinematic_config,
        load_kinematics,
        load_robot_table,
    )
    from .scenario import Scenario, default_scenario, load_scenario, scenario_from_dict
    from .tables import (
        FIGURES,
        ControlTable,
        FrictionTable,
        GravityTable,
        InertiaTable,
        LawTable,
        MotorsTable,
        OutputTable,
        PaperTable,
        PathTable,
        TolerancesTable,
    )
    from .toml import check_tables, load_toml

__all__ = ["FIGURES", "TABLES", "ControlTable", "FrictionTable", "GravityTable",
           "InertiaTable", "InstrumentTable", "KinematicConfig", "LawTable", "MotorsTable",
           "OutputTable", "PaperTable", "PathTable", "RobotTable", "Scenario", "Table",
           "TolerancesTable", "check_tables", "default_scenario", "kinematic_model",
           "load_kinematic_config", "load_kinematics", "load_robot_table", "load_scenario",
           "load_toml", "register_table", "scenario_from_dict"]

__getattr__, __dir__ = lazy_attributes(__name__, {
    **dict.fromkeys(("TABLES", "Table", "register_table"), ".base"),
    **dict.fromkeys(("InstrumentTable", "KinematicConfig", "RobotTable", "kinematic_model",
                     "load_kinematic_config", "load_kinematics", "load_robot_table"),
                    ".kinematic"),
    **dict.fromkeys(("Scenario", "default_scenario", "load_scenario", "scenario_from_dict"),
                    ".scenario"),
    **dict.fromkeys(("FIGURES", "ControlTable", "FrictionTable", "GravityTable",
                     "InertiaTable", "LawTable", "MotorsTable", "OutputTable", "PaperTable",
                     "PathTable", "TolerancesTable"), ".tables"),
    **dict.fromkeys(("check_tables", "load_toml"), ".toml"),
})
