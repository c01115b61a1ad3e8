"""A design sweep's task from a scenario: the program or the run of the task file (SI), and
its design space (``[design]``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..design.evaluate import Task
from ..design.space import DesignSpace
from ..laws import LawRequest
from ..units import SI

if TYPE_CHECKING:
    from .scenario import Scenario


def design_task(sc: Scenario, *, samples: int | None = None,
                seed: int | None = None) -> tuple[Task, DesignSpace]:
    """The :class:`~dextar.design.evaluate.Task` and the design space of a sweep's task file:
    a program task (``[program]`` and ``[[move]]``) or a run task (``[path]`` and ``[law]``;
    a law that does not depend on the robot is computed once here); ``samples`` and ``seed``
    override ``[design]``'s."""
    space = sc.design.space(sc.robot_mm, samples=samples, seed=seed)
    inertia = sc.si_model.inertia
    motors, rms = sc.si_motors, sc.motors_table.rms_torque
    if sc.moves:  # a program task
        return Task(sc.moves, sc.program_start, sc.program_mode, sc.assembly, motors, rms,
                    inertia, space.mass_per_length, sc.design.grid, sc.tolerances,
                    robot=sc.si_model.robot), space
    path = sc.path_table.build(SI)  # a run task: one path and law
    kind = sc.law_table.kind
    values = sc.law_table.run_values(SI)
    law = None if kind.needs_dynamics else kind.build(LawRequest(
        path, values, inertia.point_mass, None, SI, motors))
    start = path.position(path.p0)
    task = Task((), (float(start[0]), float(start[1])), sc.mode, sc.assembly, motors, rms,
                inertia, space.mass_per_length, sc.design.grid, sc.tolerances, path=path,
                law=law, law_type=kind.name if law is None else None,
                law_values=values if law is None else None, robot=sc.si_model.robot)
    return task, space
