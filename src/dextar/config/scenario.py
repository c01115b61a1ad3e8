"""A run's scenario: the typed config tables composed, and the run's objects built from them.

The tables (:mod:`dextar.config.tables`) hold config units (mm, deg, kg, s, N m); the run
computes in one :class:`~dextar.units.Units` system, paper or SI, and every conversion
happens here, once, as the objects are built.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path as FilePath
from typing import Any, TypeVar

from ..analysis import RunInputs
from ..calibration import KinematicModel
from ..design.evaluate import Task
from ..design.space import DesignSpace
from ..dynamics import Inertia, Model
from ..dynamics.along_path import RobotAlongPath
from ..dynamics.crossing import RobotAcrossPath
from ..errors import ConfigError, DextarError
from ..geometry import FiveBar
from ..kinematics.checker import Tolerances
from ..laws import Law, LawRequest, law_type
from ..laws.constraints import PathDynamics
from ..motors import MotorLimits
from ..output.config_file import model_toml
from ..params import read_params
from ..paths import Path
from ..program import Move, ProgramRequest
from ..program.drive import DriveUnits
from ..trajectory import Crossing, Trajectory, check_path, find_crossings, sample_trajectory
from ..units import SI, Units
from .base import TABLES, Table
from .design import DesignTable
from .design_task import design_task
from .kinematic import InstrumentTable, RobotTable, config_notes, kinematic_model
from .program import ProgramTable, read_moves
from .tables import (
    ControlTable,
    DriveTable,
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
from .toml import check_tables, read_config

T = TypeVar("T", bound=Table)

#: Where a scenario of no file comes from.
DEFAULT_SOURCE = "defaults (the paper's example)"


@dataclass(frozen=True)
class Scenario:
    """Every config table of a run (defaults where a table is absent) and its source.

    Attributes
    ----------
    tables : mapping of str to Table
        Every registered table, parsed.
    source : str
        Where the config came from (its path, or the defaults).
    moves : tuple of Move
        The ``[[move]]`` tables (SI).
    doc : mapping
        The file as parsed (each table as written), read once.
    text : bytes
        The file's bytes (a sweep's signature), empty without a file.
    """

    tables: Mapping[str, Table]
    source: str = DEFAULT_SOURCE
    moves: tuple[Move, ...] = ()
    doc: Mapping[str, Any] = field(default_factory=dict)
    text: bytes = b""

    def table(self, name: str) -> Table:
        """The parsed table ``[name]`` (a registered table; the typed properties below name
        the built-in ones)."""
        return self.tables[name]

    @property
    def notes(self) -> tuple[str, ...]:
        """What the user may not have meant, in words (each command says them on stderr and
        beside its error; computed by :func:`~dextar.config.kinematic.config_notes`): a
        config file with no table runs the paper's example; a robot that looks written in
        metres."""
        return config_notes(None if self.source == DEFAULT_SOURCE else self.source, self.doc,
                            self.robot_table.geometry_mm,
                            "this runs the paper's example (the DexTAR, the 120 mm semicircle, "
                            "the optimal law)")

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
    def inertia_table(self) -> InertiaTable:
        """``[inertia]``."""
        return self._get(InertiaTable)

    @property
    def friction_table(self) -> FrictionTable:
        """``[friction]``."""
        return self._get(FrictionTable)

    @property
    def gravity_table(self) -> GravityTable:
        """``[gravity]``."""
        return self._get(GravityTable)

    @property
    def control_table(self) -> ControlTable:
        """``[control]``."""
        return self._get(ControlTable)

    @property
    def motors_table(self) -> MotorsTable:
        """``[motors]``."""
        return self._get(MotorsTable)

    @property
    def drive_table(self) -> DriveTable:
        """``[drive]``."""
        return self._get(DriveTable)

    def drive(self) -> DriveUnits | None:
        """The drives in SI (``[drive]``), or None without the table."""
        t, off = self.drive_table, self.robot_table.encoder_offset_deg
        if not t.given:
            return None
        try:
            return DriveUnits(t.gear_ratio, (int(t.encoder_counts[0]), int(t.encoder_counts[1])),
                              t.rated_torque_Nm, (math.radians(off[0]), math.radians(off[1])),
                              t.pvt_period_ms * 1e-3, t.max_torque_permille)
        except DextarError as exc:
            raise ConfigError(f"config table [drive]: {exc}") from None

    @property
    def program_table(self) -> ProgramTable:
        """``[program]``."""
        return self._get(ProgramTable)

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
        return self._get(TolerancesTable).tolerances()

    def in_units(self, system: str | None) -> Scenario:
        """The scenario computed in another unit system (``"si"`` or ``"paper"``; None: as
        configured), as ``--units`` asks."""
        if system is None or system == self.output.units:
            return self
        if system not in ("si", "paper"):
            raise ConfigError(f"--units {system!r} must be si or paper")
        tables = {**self.tables, "output": replace(self.output, units=system)}
        return Scenario(tables, self.source, self.moves, self.doc, self.text)

    @property
    def instrument_table(self) -> InstrumentTable:
        """``[instrument]`` (the measuring instrument's frame and noise)."""
        return self._get(InstrumentTable)

    @property
    def kinematic_model(self) -> KinematicModel:
        """The robot (SI), its encoder offsets (``[robot].encoder_offset_deg``) and the
        instrument frame (``[instrument]``) as a calibration model."""
        return kinematic_model(self.robot_table, self.instrument_table)

    def raw(self, *names: str) -> dict[str, Mapping[str, Any]]:
        """The tables ``names`` as the file writes them (those it has)."""
        return {k: self.doc[k] for k in names if k in self.doc}

    # ------------------------------------------------------------------ the run's objects
    @cached_property
    def units(self) -> Units:
        """The run's unit system (``[output].units``)."""
        if self.output.units == "si":
            return Units("si", 1000.0, 1.0, 1.0)
        return Units("paper", self.robot_mm.L1, self.inertia_table.effector_mass,
                     self.law_table.duration_s)

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

    def _inertia(self, units: Units) -> Inertia:
        return self.inertia_table.build(units, self.robot_mm, self.friction_table,
                                        self.gravity_table)

    @cached_property
    def inertia(self) -> Inertia:
        """Masses, inertias, friction and gravity in run units."""
        return self._inertia(self.units)

    @property
    def effector_mass(self) -> float:
        """Point mass at P in run units."""
        return self.inertia.point_mass

    @property
    def control(self) -> dict[str, Any]:
        """The control simulation's settings in run units."""
        return self.control_table.run_values(self.units, self.inertia_table.effector_mass)

    @property
    def motors(self) -> MotorLimits | None:
        """The motors' limits in run units (``[motors]``), or None."""
        return self.motors_table.limits(self.units)

    def model(self, assembly: str | None = None) -> Model:
        """Robot and inertia assembled in ``assembly`` (default: the configured one)."""
        return Model(self.robot, self.inertia, assembly or self.assembly,
                     tol=self.tolerances.type2)

    # ------------------------------------------------------------------ SI (programs, ...)
    @cached_property
    def si_model(self) -> Model:
        """The robot and inertia in SI (m, kg, s), whatever ``[output].units``: the unit
        system of programs, identification and design sweeps."""
        return Model(self.robot_mm.scaled(1e-3), self._inertia(SI), self.assembly,
                     tol=self.tolerances.type2)

    @property
    def si_motors(self) -> MotorLimits | None:
        """The motors' limits in SI, or None."""
        return self.motors_table.limits(SI)

    @property
    def program_mode(self) -> str:
        """A program's working mode at its start (``[program].working_mode`` or the
        robot's)."""
        return self.program_table.working_mode or self.mode

    @property
    def program_start(self) -> tuple[float, float]:
        """``[program].start`` in m."""
        start = self.program_table.start
        if start is None:
            raise ConfigError("config key [program].start is required (the start point, at "
                              "rest)")
        return (SI.length(start[0]), SI.length(start[1]))

    def program_request(self) -> ProgramRequest:
        """The program of a task file (``[program]``, ``[[move]]``, ``[motors]``) in SI."""
        if not self.moves:
            raise ConfigError("the task has no move: add [[move]] tables")
        m = self.si_model
        return ProgramRequest(m.robot, m.inertia, self.moves, self.program_start,
                              self.program_mode, self.assembly, self.si_motors,
                              self.motors_table.rms_torque, self.output.servo_rate_hz,
                              self.program_table.grid, self.tolerances,
                              self.program_table.cycle)

    def design_task(self, *, samples: int | None = None, seed: int | None = None
                    ) -> tuple[Task, DesignSpace]:
        """A sweep's :class:`~dextar.design.evaluate.Task` and design space: a program task
        (``[program]`` and ``[[move]]``) or a run task (``[path]`` and ``[law]``; a law that
        does not depend on the robot is computed once here), in SI."""
        return design_task(self, samples=samples, seed=seed)

    def model_file(self, robot_mm: FiveBar, mode: str, inertia: Inertia, comment: str,
                   tables: Mapping[str, Mapping[str, Any]] | None = None) -> str:
        """A config file of ``inertia`` (SI) on ``robot_mm`` with this scenario's friction
        speed and gravity and its ``[motors]`` and ``[tolerances]`` as the file gives them
        (``identified.toml``, ``best.toml``); ``tables`` (config units) replace or add
        tables (a chosen motor's ``[motors]`` and ``[drive]``)."""
        extra = {**self.raw("motors", "tolerances"), **(tables or {})}
        return model_toml(robot_mm, mode, self.assembly, inertia,
                          coulomb_speed_deg_s=self.friction_table.coulomb_speed_deg_s,
                          gravity_mm_s2=self.gravity_table.vector, extra=extra,
                          comment=comment)

    @cached_property
    def crossings(self) -> tuple[Crossing, ...]:
        """The path's crossings of the parallel singularity curve that ``[path].assembly_mode``
        asks for (none when it is not given); refused by name where the path does not reach
        that assembly mode."""
        asked = self.path_table.assembly_mode
        if asked is None:
            return ()
        found = find_crossings(self.robot, self.path, mode=self.mode, units=self.units)
        end = self.assembly if len(found) % 2 == 0 else found[-1].assembly_after
        if end != asked:
            how = ("does not cross the parallel (type 2) singularity curve" if not found else
                   f"crosses the parallel (type 2) singularity curve {len(found)} times")
            raise ConfigError(
                f"config key [path].assembly_mode = \"{asked}\": the path {how} of working "
                f"mode {self.mode} from [robot].assembly_mode = \"{self.assembly}\", so it "
                f"ends in assembly mode {end}")
        return found

    def law(self, kind: str | None = None) -> Law:
        """The configured law, or the registered law ``kind`` with its defaults and the
        configured duration. The path is checked first (reach and singularities: a crossing
        of the parallel singularity curve only where ``[path].assembly_mode`` asks for one,
        planned by the time-optimal law under the degeneracy condition)."""
        crossings = self.crossings
        check_path(self.robot, self.path, mode=self.mode, tolerances=self.tolerances,
                   units=self.units, crossings=crossings)
        table = self.law_table
        if kind is not None and kind != table.type:
            lt = law_type(kind)
            raw = {"duration": table.duration_s} if "duration" in lt.params else {}
            table = LawTable(kind, read_params("law", raw, lt.params))
        lt = table.kind
        dynamics: PathDynamics | None = (RobotAlongPath(self.model(), self.path, self.mode,
                                                        self.units)
                                         if lt.needs_dynamics else None)
        if crossings:
            where = ", ".join(self.units.point_text(c.P) for c in crossings)
            if lt.name != "time-optimal":
                raise ConfigError(
                    f"config key [law].type = \"{lt.name}\": the path crosses the parallel "
                    f"(type 2) singularity curve at {where} ([path].assembly_mode), which only "
                    "the time-optimal law plans under the degeneracy condition; another law "
                    "would need unbounded torques there")
            motors = self.motors
            if motors is not None and motors.third_order:
                raise ConfigError(
                    f"config table [motors]: the path crosses the parallel (type 2) "
                    f"singularity curve at {where}, planned by the second-order time-optimal "
                    "law; max_jerk or max_torque_rate asks the jerk-limited one, which does "
                    "not impose the degeneracy condition")
            dynamics = RobotAcrossPath(replace(self.model(), tol=0.0), self.path, self.mode,
                                       crossings, self.units)
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
                                 tolerances=self.tolerances, units=self.units,
                                 crossings=self.crossings)


def scenario_from_dict(doc: Mapping[str, Any], *, source: str | None = None,
                       text: bytes = b"") -> Scenario:
    """A :class:`Scenario` from a parsed config (tables as in ``examples/paper.toml``); every
    table is validated at this boundary, errors naming ``[table].key``."""
    check_tables({k: v for k, v in doc.items() if k != "move"}, set(TABLES) | {"move"})
    tables = {name: cls.from_toml(doc.get(name, {})) for name, cls in TABLES.items()}
    program = tables["program"]
    if not isinstance(program, ProgramTable):
        raise TypeError("table [program] is not a ProgramTable")
    robot = tables["robot"]
    if not isinstance(robot, RobotTable):
        raise TypeError("table [robot] is not a RobotTable")
    moves = read_moves(doc.get("move"), program, robot.encoder_offset_deg)
    sc = Scenario(tables, moves=tuple(moves), doc=dict(doc), text=text)
    if source is not None:
        sc = Scenario(sc.tables, source, sc.moves, sc.doc, text)
    try:  # build the run's objects now: a bad value fails here, named by its table
        _ = (sc.units, sc.robot, sc.path, sc.inertia)
    except DextarError as exc:
        said = str(exc) if isinstance(exc, ConfigError) else f"config: {exc}"
        raise ConfigError(said + (f" (note: {'; '.join(sc.notes)})" if sc.notes else "")
                          ) from None
    return sc


#: The tables a model file (``identified.toml``, ``best.toml``, ``calibrated.toml``) gives to
#: another config (``--model``).
MODEL_TABLES = ("robot", "inertia", "friction", "gravity")


#: The first line dextar writes at the top of a model it fitted to data (``identified.toml``,
#: and ``calibrated.toml`` alike): ``# identified by dextar from DATA (STATUS: ...)``; the
#: status is the verb when the fit succeeded.
_FITTED_BY = re.compile(r"# (?P<verb>\w+) by dextar from (?P<data>.*?) \((?P<status>[^():]+): ")


def check_model_status(model: str | FilePath, text: bytes) -> None:
    """Refuse (:class:`ConfigError`) a model file whose first line says dextar's fit of it did
    not succeed (``# identified by dextar from DATA (poor fit: ...)``): its status names
    what to fix, and the user may delete that line to use the model anyway."""
    first = text.split(b"\n", 1)[0].decode("utf-8", errors="replace").rstrip("\r")
    m = _FITTED_BY.match(first)
    if m is None or m["status"] == m["verb"]:
        return
    raise ConfigError(f"--model {str(model)!r} is a model dextar {m['verb']} from {m['data']} "
                      f"with the status {m['status']!r}, not {m['verb']!r} (its first line "
                      "gives the reasons): it is not used. Fit it again from better data, or "
                      "delete that first line to use it anyway")


def load_scenario(path: str | FilePath | None = None, *,
                  model: str | FilePath | None = None) -> Scenario:
    """Read a config file (or none: the paper's example) into a :class:`Scenario`; the file
    is read once. ``model``: a model file whose robot, inertia, friction and gravity replace
    the config's (its other tables kept): what ``--model identified.toml`` does; a model file
    whose first line says its fit did not succeed is refused (:func:`check_model_status`)."""
    doc, text = ({}, b"") if path is None else read_config(path)
    source = None if path is None else str(path)
    if model is not None:
        mdoc, mtext = read_config(model)
        check_model_status(model, mtext)
        missing = [t for t in ("robot", "inertia") if t not in mdoc]
        if missing:
            raise ConfigError(f"--model {str(model)!r} has no [{missing[0]}] table: a model "
                              "file (identified.toml, best.toml) gives [robot], [inertia], "
                              "[friction] and [gravity]")
        check_tables({k: v for k, v in mdoc.items() if k != "move"}, set(TABLES) | {"move"})
        doc = {**{k: v for k, v in doc.items() if k not in MODEL_TABLES},
               **{k: mdoc[k] for k in MODEL_TABLES if k in mdoc}}
        text = text + b"\n# --model\n" + mtext
        source = f"{source or 'the defaults'} with the model of {model}"
    if path is None and model is None:
        return scenario_from_dict({})
    return scenario_from_dict(doc, source=source, text=text)


def default_scenario() -> Scenario:
    """The paper's example."""
    return load_scenario(None)
