"""A design sweep's task from a scenario: the program or the run of the task file (SI), and
its design space (``[design]``), with its motor catalogue (``[design].motors``)."""

from __future__ import annotations

from pathlib import Path as FilePath
from typing import TYPE_CHECKING

from ..design.evaluate import Task
from ..design.space import DesignSpace
from ..errors import ConfigError
from ..laws import LawRequest
from ..motors import Catalogue
from ..program import AUTO
from ..units import SI
from .catalogue import read_catalogue

if TYPE_CHECKING:
    from .scenario import Scenario


def design_task(sc: Scenario, *, samples: int | None = None,
                seed: int | None = None) -> tuple[Task, DesignSpace]:
    """The :class:`~dextar.design.evaluate.Task` and the design space of a sweep's task file:
    a program task (``[program]`` and ``[[move]]``) or a run task (``[path]`` and ``[law]``;
    a law that does not depend on the robot is computed once here); ``samples`` and ``seed``
    override ``[design]``'s."""
    inertia = sc.si_model.inertia
    catalogue = design_catalogue(sc)
    c1, c2 = inertia.counterweights
    space = sc.design.space(sc.robot_mm, samples=samples, seed=seed, catalogue=catalogue,
                            counterweights=((c1.mass, c2.mass),
                                            (1e3 * c1.distance, 1e3 * c2.distance)))
    motors, rms = sc.si_motors, sc.motors_table.rms_torque
    if sc.moves and sc.program_mode == AUTO:
        raise ConfigError("config key [program].working_mode = \"auto\" is not for dextar "
                          "design (a design's workspace metrics are a working mode's): set "
                          "the working mode, or plan the program with dextar program")
    if sc.moves:  # a program task
        return Task(sc.moves, sc.program_start, sc.program_mode, sc.assembly, motors, rms,
                    inertia, space.mass_per_length, sc.design.grid, sc.tolerances,
                    robot=sc.si_model.robot, columns=space.columns, catalogue=catalogue,
                    motor_choice=sc.design.motor_choice, cycle=sc.program_table.cycle), space
    path = sc.path_table.build(SI)  # a run task: one path and law
    kind = sc.law_table.kind
    values = sc.law_table.run_values(SI)
    law = None if kind.needs_dynamics else kind.build(LawRequest(
        path, values, inertia.point_mass, None, SI, motors))
    start = path.position(path.p0)
    task = Task((), (float(start[0]), float(start[1])), sc.mode, sc.assembly, motors, rms,
                inertia, space.mass_per_length, sc.design.grid, sc.tolerances, path=path,
                law=law, law_type=kind.name if law is None else None,
                law_values=values if law is None else None, robot=sc.si_model.robot,
                columns=space.columns, catalogue=catalogue, motor_choice=sc.design.motor_choice)
    return task, space


def design_catalogue(sc: Scenario) -> Catalogue | None:
    """The motor catalogue of ``[design].motors`` (a path relative to the task file's folder)
    with ``[design].ratios``, or None."""
    name = sc.design.motors
    if name is None:
        return None
    path = FilePath(name)
    source = FilePath(sc.source)
    if not path.is_absolute() and source.is_file():
        path = source.parent / path
    return read_catalogue(path, sc.design.ratios)
