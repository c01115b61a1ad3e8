"""Config files: typed tables validated at the boundary, and the scenario that composes them.

``[table]`` -> a frozen dataclass registered in :data:`TABLES`; a new table is a dataclass
and one :func:`register_table` line.
"""

from .scenario import (
    Scenario,
    default_scenario,
    kinematic_model,
    load_kinematics,
    load_robot_table,
    load_scenario,
    scenario_from_dict,
)
from .tables import (
    FIGURES,
    TABLES,
    ControlTable,
    FrictionTable,
    GravityTable,
    InertiaTable,
    InstrumentTable,
    LawTable,
    MotorsTable,
    OutputTable,
    PaperTable,
    PathTable,
    RobotTable,
    Table,
    TolerancesTable,
    register_table,
)
from .toml import check_tables, load_toml

__all__ = ["FIGURES", "TABLES", "ControlTable", "FrictionTable", "GravityTable",
           "InertiaTable", "InstrumentTable", "LawTable", "MotorsTable", "OutputTable",
           "PaperTable", "PathTable", "RobotTable", "Scenario", "Table", "TolerancesTable",
           "check_tables", "default_scenario", "kinematic_model", "load_kinematics",
           "load_robot_table", "load_scenario", "load_toml", "register_table",
           "scenario_from_dict"]
