"""What every config table shares: :class:`Table`, the generic reading of its declared keys,
and the table registry :data:`TABLES`.

A new table is a new dataclass with ``NAME``, ``PARAMS`` and (if it needs more than the
generic reading) ``from_toml``, and one line: ``register_table(MyTable)``. The built-in
tables are registered by where they are defined, so that reading one table (``[robot]``)
imports only its own module.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import ClassVar, TypeVar

from ..params import Param, read_params
from ..registry import Registry

T = TypeVar("T", bound="Table")


class Table:
    """Base of the table dataclasses: the generic reading of ``PARAMS``."""

    NAME: ClassVar[str] = ""
    PARAMS: ClassVar[dict[str, Param]] = {}

    @classmethod
    def from_toml(cls: type[T], raw: Mapping[str, object]) -> T:
        """The table from its TOML contents (validated; absent keys take their defaults)."""
        return cls(**read_params(cls.NAME, raw, cls.PARAMS))


#: The table registry: TOML name -> dataclass, in the order the docs list them.
TABLES: Registry[type[Table]] = Registry("config table", "config table")


def register_table(cls: type[T]) -> type[T]:
    """Make ``[cls.NAME]`` a known table of the config files."""
    TABLES.register(cls, cls.NAME)
    return cls


for _name, _where in (("robot", "kinematic:RobotTable"), ("path", "tables:PathTable"),
                      ("law", "tables:LawTable"), ("inertia", "tables:InertiaTable"),
                      ("friction", "tables:FrictionTable"), ("gravity", "tables:GravityTable"),
                      ("control", "tables:ControlTable"), ("paper", "tables:PaperTable"),
                      ("output", "tables:OutputTable"), ("tolerances", "tables:TolerancesTable"),
                      ("motors", "tables:MotorsTable"), ("drive", "tables:DriveTable"),
                      ("instrument", "kinematic:InstrumentTable"),
                      ("program", "program:ProgramTable"), ("design", "design:DesignTable")):
    TABLES.register_deferred(_name, f"{__package__}.{_where}")
