"""A run's scenario: the typed config tables composed, and the run's objects built from them.

The tables (:mod:`dextar.config.tables`) hold config units (mm, deg, kg, s, N m); the run
computes in one :class:`~dextar.units.Units` system, paper or SI, and every conversion
happens here, once, as the objects are built.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path as FilePath
from typing import Any, TypeVar

from ..analysis import RunInputs
from ..dynamics import Inertia, Model, RobotAlongPath
from ..errors import ConfigError, DextarError
from ..geometry import FiveBar
from ..kinematics.checker import Tolerances
from ..laws import Law, LawRequest, MotorLimits, law_type
from ..params import read_params
from ..paths import Path
from ..program import Move
from ..trajectory import Trajectory, check_path, sample_trajectory
from ..units import Units
from .design import DesignTable
from .program import ProgramTable, read_moves
from .tables import (
    TABLES,
    ControlTable,
    FrictionTable,
    GravityTable,
    InertiaTable,
    LawTable,
    MotorsTable,
    OutputTable,
    PaperTable,
    PathTable,
    RobotTable,
    Table,
    TolerancesTable,
)
from .toml import check_tables, load_toml

T = TypeVar("T", bound=Table)


@dataclass(frozen=True)
class Scenario:
    """Every config table of a run (defaults where a table is absent) and its source."""

    tables: Mapping[str, Table]
    source: str = "defaults (the paper's example)"
    moves: tuple[Move, ...] = ()

    def table(self, name: str) -> Any:
        """The parsed table ``[name]``."""
        return self.tables[name]

    def _get(self, cls: type[T]) -> T:
        t = self.tables[cls.NAME]
        if not isinstance(t, cls):
            raise TypeError(f"table [{cls.NAME}] holds {type(t).__name__}, not {cls.__name__}")
        return t

    # ------------------------------------------------------------------ the tables, typed
    @property
    def robot_table(self) -> RobotTable:
        """``[robot]``."""
        return self._get(RobotTable)

    @property
    def path_table(self) -> PathTable:
        """``[path]``."""
        return self._get(PathTable)

    @property
    def law_table(self) -> LawTable:
        """``[law]``."""
        return self._get(LawTable)

    @property
    def output(self) -> OutputTable:
        """``[output]``."""
        return self._get(OutputTable)

    @property
    def paper(self) -> PaperTable:
        """``[paper]``."""
        return self._get(PaperTable)

    @property
    def design(self) -> DesignTable:
        """``[design]`` (a sweep's ranges and objectives)."""
        return self._get(DesignTable)

    @property
    def tolerances(self) -> Tolerances:
        """The geometry checker's tolerances (``[tolerances]``)."""
        t = self._get(TolerancesTable)
        return t.tolerances()

    # ------------------------------------------------------------------ the run's objects
    @cached_property
    def units(self) -> Units:
        """The run's unit system (``[output].units``)."""
        if self.output.units == "si":
            return Units("si", 1000.0, 1.0, 1.0)
        inertia = self._get(InertiaTable)
        return Units("paper", self.robot_mm.L1, inertia.effector_mass, self.law_table.duration_s)

    @property
    def robot_mm(self) -> FiveBar:
        """The geometry in mm."""
        return self.robot_table.geometry_mm

    @cached_property
    def robot(self) -> FiveBar:
        """The geometry in run units."""
        return self.robot_mm.scaled(1.0 / self.units.length_mm)

    @property
    def mode(self) -> str:
        """The working mode."""
        return self.robot_table.working_mode

    @property
    def assembly(self) -> str:
        """The assembly mode."""
        return self.robot_table.assembly_mode

    @cached_property
    def path(self) -> Path:
        """The path in run units."""
        return self.path_table.build(self.units)

    @property
    def path_spec(self) -> dict[str, Any]:
        """The path as configured (mm, degrees)."""
        return self.path_table.summary()

    @cached_property
    def inertia(self) -> Inertia:
        """Masses, inertias, friction and gravity in run units."""
        t = self._get(InertiaTable)
        f = self._get(FrictionTable)
        g = self._get(GravityTable)
        return t.build(self.units, self.robot_mm, f, g)

    @property
    def effector_mass(self) -> float:
        """Point mass at P in run units."""
        return self.inertia.point_mass

    @property
    def control(self) -> dict[str, Any]:
        """The control simulation's settings in run units."""
        t = self._get(ControlTable)
        inertia = self._get(InertiaTable)
        return t.run_values(self.units, inertia.effector_mass)

    @property
    def motors(self) -> MotorLimits | None:
        """The motors' limits in run units (``[motors]``), or None."""
        return self._get(MotorsTable).limits(self.units)

    def model(self, assembly: str | None = None) -> Model:
        """Robot and inertia assembled in ``assembly`` (default: the configured one)."""
        return Model(self.robot, self.inertia, assembly or self.assembly,
                     tol=self.tolerances.type2)

    def law(self, kind: str | None = None) -> Law:
        """The configured law, or the registered law ``kind`` with its defaults and the
        configured duration. The path is checked first (reach and singularities)."""
        check_path(self.robot, self.path, mode=self.mode, tolerances=self.tolerances,
                   units=self.units)
        table = self.law_table
        if kind is not None and kind != table.type:
            lt = law_type(kind)
            raw = {"duration": table.duration_s} if "duration" in lt.params else {}
            table = LawTable(kind, read_params("law", raw, lt.params))
        lt = table.kind
        dynamics = (RobotAlongPath(self.model(), self.path, self.mode, self.units)
                    if lt.needs_dynamics else None)
        request = LawRequest(self.path, table.run_values(self.units), self.effector_mass,
                             dynamics, self.units, self.motors)
        return lt.build(request)

    def inputs(self) -> RunInputs:
        """What the analysis of a run needs, in run units (no config beyond this point)."""
        p = self.paper
        return RunInputs(self.robot, self.robot_mm, self.path, self.path_spec, self.mode,
                         self.assembly, self.inertia, self.units, self.output.samples,
                         self.law_table.type, dict(self.law_table.values), self.tolerances,
                         p.beta0_time, p.fig7_distal_mass_ratio, p.fig7_lambda, self.source)

    def trajectory(self, law: Law | None = None, samples: int | None = None) -> Trajectory:
        """The law sampled along the path (``[output].samples`` by default)."""
        return sample_trajectory(self.robot, self.path, law or self.law(), mode=self.mode,
                                 samples=samples or self.output.samples,
                                 tolerances=self.tolerances, units=self.units)


def scenario_from_dict(doc: Mapping[str, Any]) -> Scenario:
    """A :class:`Scenario` from a parsed config (tables as in ``examples/paper.toml``); every
    table is validated at this boundary, errors naming ``[table].key``."""
    check_tables({k: v for k, v in doc.items() if k != "move"}, set(TABLES) | {"move"})
    tables = {name: cls.from_toml(doc.get(name, {})) for name, cls in TABLES.items()}
    program = tables["program"]
    assert isinstance(program, ProgramTable)
    sc = Scenario(tables, moves=tuple(read_moves(doc.get("move"), program)))
    try:  # build the run's objects now: a bad value fails here, named by its table
        _ = (sc.units, sc.robot, sc.path, sc.inertia)
    except ConfigError:
        raise
    except DextarError as exc:
        raise ConfigError(f"config: {exc}") from None
    return sc


def load_scenario(path: str | FilePath | None = None) -> Scenario:
    """Read a config file (or none: the paper's example) into a :class:`Scenario`."""
    doc = {} if path is None else load_toml(path)
    sc = scenario_from_dict(doc)
    return sc if path is None else replace(sc, source=str(path))


def default_scenario() -> Scenario:
    """The paper's example."""
    return load_scenario(None)
