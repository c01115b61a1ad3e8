"""Choosing the robot, ``dextar design``: a sweep of five-bar geometries for a task on Dask,
the Pareto front of the feasible designs, the design closest to the ideal point and the
chosen robot as a config file (``best.toml``)."""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from .._arrays import Array
from ..config import Scenario
from ..design.evaluate import Task, evaluate_path, inertia_of
from ..design.pareto import Choice, choose
from ..design.space import LENGTHS, DesignSpace
from ..design.sweep import Cluster, SweepStats, require_dask, run_sweep
from ..geometry import FiveBar
from ..motors import Gearmotor

Row = dict[str, Any]


@dataclass(frozen=True)
class DesignSweep:
    """A sweep to run: the task, the design space and its designs.

    Attributes
    ----------
    scenario : Scenario
        The task file (a program or a run config, with ``[design]``).
    task : Task
        What each design is evaluated on (SI).
    space : DesignSpace
        The ranges, the sampling and the objectives.
    designs : ndarray, shape (n, 5)
        The designs' lengths ``l1, l2, L1, L2, d`` (mm), numbered by row.
    signature : str
        What makes two sweeps the same (the task file, the space, the grid): a sweep resumes
        only its own designs.
    """

    scenario: Scenario
    task: Task
    space: DesignSpace
    designs: Array = field(repr=False)
    signature: str


def design_sweep(sc: Scenario, *, samples: int | None = None,
                 seed: int | None = None) -> DesignSweep:
    """The sweep of the task file ``sc`` (``[design]``; ``samples`` and ``seed`` override
    it)."""
    task, space = sc.design_task(samples=samples, seed=seed)
    signature = hashlib.sha256(repr((sc.text, space, sc.design.grid, task.catalogue)
                                    ).encode()).hexdigest()
    return DesignSweep(sc, task, space, space.designs(), signature)


class DesignStore(Protocol):
    """Where a sweep keeps its rows as chunks finish (``designs.csv`` for the command, a
    dictionary in memory by default): the designs still to evaluate, each finished chunk
    appended, every row in design order at the end. A context manager, entered once the
    cluster is up (a sweep that cannot start writes nothing)."""

    def __enter__(self) -> DesignStore:
        """Open the store."""

    def __exit__(self, *exc: object) -> None:
        """Close it."""

    @property
    def missing(self) -> list[int]:
        """The designs without a row."""

    def append(self, rows: list[Row]) -> None:
        """Keep a finished chunk's rows."""

    def finish(self) -> list[Row]:
        """Every row, in design order."""


class MemoryStore:
    """A :class:`DesignStore` in memory: every design of ``n`` to evaluate."""

    def __init__(self, n: int) -> None:
        """An empty store of ``n`` designs."""
        self.n = n
        self.rows: dict[int, Row] = {}

    def __enter__(self) -> MemoryStore:
        return self

    def __exit__(self, *exc: object) -> None:
        pass

    @property
    def missing(self) -> list[int]:
        """The designs without a row."""
        return [i for i in range(self.n) if i not in self.rows]

    def append(self, rows: list[Row]) -> None:
        """Keep a finished chunk's rows."""
        self.rows.update((r["design"], r) for r in rows)

    def finish(self) -> list[Row]:
        """Every row, in design order."""
        return [self.rows[i] for i in range(self.n)]


@dataclass(frozen=True)
class Designed:
    """A design sweep's outcome.

    Attributes
    ----------
    sweep : DesignSweep
    rows : list of dict
        Every design's row (lengths, feasibility, the reason, the metrics), in order.
    stats : SweepStats
        Designs evaluated (the others resumed), wall time, workers.
    choice : Choice
        The Pareto set of the feasible designs and the one closest to the ideal point.
    best_toml : str or None
        The chosen robot as a config (``best.toml``), None without a feasible design.
    best_path_mm : ndarray or None
        The task's end-effector path (n, 2) (mm) on the chosen design.
    """

    sweep: DesignSweep
    rows: list[Row]
    stats: SweepStats
    choice: Choice
    best_toml: str | None
    best_path_mm: Array | None = field(default=None, repr=False)

    @property
    def best(self) -> Row | None:
        """The chosen design's row (None without a feasible design)."""
        return self.choice.best_row

    @property
    def best_robot_mm(self) -> FiveBar | None:
        """The chosen design's geometry (mm)."""
        best = self.best
        return None if best is None else FiveBar(*(best[k] for k in LENGTHS))


def design(sweep: DesignSweep, *, workers: int | None = None, scheduler: str | None = None,
           store: DesignStore | None = None, progress: Callable[[int, int], None] | None = None,
           label: str | None = None) -> Designed:
    """Evaluate the sweep's designs missing from ``store`` (default: all, in memory) on a
    Dask cluster (a local one of ``workers`` processes, or the running ``scheduler``), then
    choose: the Pareto front and the design closest to the ideal point, as a config.
    ``label`` names the task file in ``best.toml`` (default the scenario's source)."""
    require_dask()
    store = MemoryStore(len(sweep.designs)) if store is None else store
    sc, task, space = sweep.scenario, sweep.task, sweep.space
    with Cluster(workers=workers, scheduler=scheduler) as cluster, store:
        stats = run_sweep(cluster, task, sweep.designs, store.missing, chunk=sc.design.chunk,
                          on_chunk=store.append, progress=progress)
    rows = store.finish()
    choice = choose(rows, space)
    best = choice.best_row
    if best is None:
        return Designed(sweep, rows, stats, choice, None)
    robot_mm = FiveBar(*(best[k] for k in LENGTHS))
    rods = (f"uniform rods of {space.mass_per_length[0]:g} and "
            f"{space.mass_per_length[1]:g} kg/m" if space.mass_per_length else
            "each rod of the task's robot keeps its linear density and shape on its new length "
            "(mass and centre of mass scale with the length, the inertia about the centre "
            "with its cube); the effector, payload and rotors as given")
    motors, tables = chosen_motors(task, best)
    best_toml = sc.model_file(
        robot_mm, task.working_mode, inertia_of(task, robot_mm.scaled(1e-3), best),
        f"the Pareto design closest to the ideal point of dextar design {label or sc.source} "
        f"(design {best['design']} of {len(rows)}; objectives {', '.join(space.objectives)})\n"
        f"rods: {rods}{motors}", tables)
    return Designed(sweep, rows, stats, choice, best_toml, evaluate_path(task, best))


def chosen_motors(task: Task, best: Row) -> tuple[str, dict[str, dict[str, object]] | None]:
    """The words of ``best.toml``'s comment on its counterweights and motors, and the
    ``[motors]`` and ``[drive]`` tables of the catalogue motor a design was planned with (None
    without a catalogue)."""
    said = ""
    c1, c2 = inertia_of(task, FiveBar(*(best[k] for k in LENGTHS)).scaled(1e-3),
                        best).counterweights
    if not (c1.none and c2.none):
        said += (f"\ncounterweights: {c1.mass:.4g} and {c2.mass:.4g} kg at {1e3 * c1.distance:.4g}"
                 f" and {1e3 * c2.distance:.4g} mm behind the motor axes (in [inertia])")
    if task.catalogue is None or not best.get("motor"):
        return said, None
    gm = Gearmotor(task.catalogue.motor(str(best["motor"])), float(best["gear_ratio"]))
    said += (f"\nmotors: {gm.motor.name} on both joints, gear ratio {gm.ratio:g} (from "
             f"{task.catalogue.source}); [motors] at the joints, its reflected rotor inertia "
             f"{gm.reflected_inertia * 1e6:.4g} kg mm^2 in [inertia].rotor_inertia")
    return said, gm.config_tables(task.motors)

