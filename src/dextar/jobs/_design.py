"""Choosing the robot, ``dextar design``: a sweep or an adaptive search of five-bar
geometries for a task on Dask, the Pareto front of the feasible designs, the design closest
to the ideal point and the chosen robot as a config file (``best.toml``)."""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

from .._arrays import Array
from ..config import Scenario
from ..design.evaluate import Task, evaluate_path, inertia_of
from ..design.pareto import Choice, choose
from ..design.search import (
    HypervolumeCurve,
    Progress,
    ProgressMeter,
    SearchSettings,
    hypervolume_curve,
    objectives_and_violation,
    pymoo_version,
    require_pymoo,
    run_search,
)
from ..design.space import LENGTHS, DesignSpace
from ..design.sweep import Cluster, SweepStats, require_dask, run_sweep
from ..geometry import FiveBar
from ..motors import Gearmotor

Row = dict[str, Any]


@dataclass(frozen=True)
class DesignSweep:
    """A sweep or a search to run: the task, the design space and its designs.

    Attributes
    ----------
    scenario : Scenario
        The task file (a program or a run config, with ``[design]``).
    task : Task
        What each design is evaluated on (SI).
    space : DesignSpace
        The ranges, the sampling and the objectives.
    designs : ndarray, shape (n, len(space.columns))
        A sweep's designs (``l1, l2, L1, L2, d`` in mm, then the counterweights and the
        motor's indices the space varies), numbered by row; a search's first
        population (the others it proposes as it goes).
    signature : str
        What makes two runs the same (the task file, the space, the grid, the motor
        catalogue, the search and the pymoo it runs on): a run resumes only its own designs.
    search : SearchSettings, optional
        The adaptive search (None for a sweep).
    """

    scenario: Scenario
    task: Task
    space: DesignSpace
    designs: Array = field(repr=False)
    signature: str
    search: SearchSettings | None = None

    @property
    def n(self) -> int:
        """Designs to evaluate: a sweep's samples, a search's evaluations."""
        return len(self.designs) if self.search is None else self.search.evaluations

    @property
    def kind(self) -> str:
        """``sobol``, ``grid``, ``random``, ``nsga2`` or ``smsemoa``."""
        return self.space.sampling if self.search is None else self.search.kind


def design_sweep(sc: Scenario, *, samples: int | None = None,
                 seed: int | None = None) -> DesignSweep:
    """The sweep or search of the task file ``sc`` (``[design]``; ``samples`` (a search's
    evaluations) and ``seed`` override it)."""
    search = sc.design.search(evaluations=samples, seed=seed)
    if search is not None:
        require_pymoo()
    task, space = sc.design_task(samples=None if search else samples, seed=seed)
    signature = hashlib.sha256(repr((sc.text, space, sc.design.grid, task.catalogue)
                                    if search is None else
                                    (sc.text, space, sc.design.grid, task.catalogue, search,
                                     pymoo_version())).encode()).hexdigest()
    return DesignSweep(sc, task, space, space.designs(), signature, search)


class DesignStore(Protocol):
    """Where a sweep or search keeps its rows as chunks finish (``designs.csv`` for the
    command, a dictionary in memory by default): the rows it has (an earlier run's, to
    resume), each finished chunk appended, every row in design order at the end. A context
    manager, entered once the cluster is up (a run that cannot start writes nothing)."""

    def __enter__(self) -> DesignStore:
        """Open the store."""

    def __exit__(self, *exc: object) -> None:
        """Close it."""

    @property
    def rows(self) -> Mapping[int, Row]:
        """The rows kept, by design number."""

    def append(self, rows: list[Row]) -> None:
        """Keep a finished chunk's rows."""

    def finish(self, n: int) -> list[Row]:
        """The rows of designs ``0 .. n - 1``, in design order."""


class MemoryStore:
    """A :class:`DesignStore` in memory."""

    def __init__(self) -> None:
        """An empty store."""
        self.rows: dict[int, Row] = {}

    def __enter__(self) -> MemoryStore:
        return self

    def __exit__(self, *exc: object) -> None:
        pass

    def append(self, rows: list[Row]) -> None:
        """Keep a finished chunk's rows."""
        self.rows.update((r["design"], r) for r in rows)

    def finish(self, n: int) -> list[Row]:
        """The rows of designs ``0 .. n - 1``, in design order."""
        return [self.rows[i] for i in range(n)]


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
    hypervolume : HypervolumeCurve
        The hypervolume of the front after each number of designs (in design order: a
        search's proposals, a sweep's sample), scaled by the final front.
    """

    sweep: DesignSweep
    rows: list[Row]
    stats: SweepStats
    choice: Choice
    best_toml: str | None
    best_path_mm: Array | None = field(default=None, repr=False)
    hypervolume: HypervolumeCurve | None = field(default=None, repr=False)

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
           store: DesignStore | None = None, progress: Callable[[Progress], None] | None = None,
           dashboard: Callable[[str], None] | None = None, label: str | None = None,
           store_label: str = "designs.csv") -> Designed:
    """Evaluate the sweep's designs, or run the search, on a Dask cluster (a local one of
    ``workers`` processes, or the running ``scheduler``), skipping the designs ``store``
    has (default: none, in memory), then choose: the Pareto front and the design closest to
    the ideal point, as a config.

    ``progress`` is called after each unit of work (:class:`~dextar.design.search.Progress`:
    designs done, feasible share, the front's hypervolume, time left); ``dashboard`` once
    with the Dask dashboard's address (when bokeh serves one). ``label`` names the task file
    in ``best.toml`` (default the scenario's source), ``store_label`` the store in an
    error."""
    require_dask()
    store = MemoryStore() if store is None else store
    sc, task, space = sweep.scenario, sweep.task, sweep.space
    with Cluster(workers=workers, scheduler=scheduler) as cluster, store:
        if dashboard is not None and cluster.dashboard:
            dashboard(cluster.dashboard)
        done = [store.rows[i] for i in sorted(store.rows) if i < sweep.n]
        meter = ProgressMeter(space, sweep.n, done, box_after=(
            sweep.search.population if sweep.search else min(sweep.n, 64)))

        def on_chunk(rows: list[Row]) -> None:
            store.append(rows)
            p = meter.add(rows)
            if progress is not None:
                progress(p)

        if sweep.search is None:
            stats = run_sweep(cluster, task, sweep.designs,
                              [i for i in range(sweep.n) if i not in store.rows],
                              chunk=sc.design.chunk, on_chunk=on_chunk)
            n = sweep.n
        else:
            ran = run_search(cluster, task, space, sweep.search, resumed=dict(store.rows),
                             on_chunk=on_chunk, label=store_label)
            stats, n = ran.stats, ran.designs
    rows = store.finish(n)
    choice = choose(rows, space)
    curve = hypervolume_curve(objectives_and_violation(space, rows)[0])
    best = choice.best_row
    if best is None:
        return Designed(sweep, rows, stats, choice, None, hypervolume=curve)
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
    return Designed(sweep, rows, stats, choice, best_toml, evaluate_path(task, best), curve)


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

