"""Adaptive multi-objective search of a design space: SMS-EMOA or NSGA-II (pymoo) on the
Dask evaluator, batch by batch, the same designs for any number of workers, resumable.

SMS-EMOA (Beume, Naujoks & Emmerich, EJOR 181(3), 2007) keeps, within the last
non-dominated rank it keeps, the designs that add most to the rank's hypervolume; NSGA-II
those of the largest crowding distance. On three objectives the first spreads the designs
it keeps over the front where crowding distance does not (``benchmarks/
bench_design_search.py``: 0.985-1.03 of a dense sweep's hypervolume with a tenth of its
evaluations on two robot tasks, NSGA-II 0.88-0.99).

The search works in the unit cube of the space's dimensions (whatever
:class:`~dextar.design.space.DesignSpace` declares: each range scaled to [0, 1], mapped back
by :meth:`~dextar.design.space.DesignSpace.from_unit`), so a variable the space gains joins the
search unchanged. Its first ``population`` designs are the space's own sample (scrambled
Sobol); after them it proposes ``batch`` designs at a time, each batch one unit of work on a
Dask worker (:func:`~dextar.design.sweep.evaluate_chunk_metered`).

Scheme (steady-state NSGA-II with a fixed delay; Deb et al., IEEE TEC 6(2), 2002, for
NSGA-II; Durillo et al., "On the effect of the steady-state selection scheme in multi-
objective genetic algorithms", EMO 2009, for the steady state): once the first population is
evaluated, ``lag`` batches are proposed from it; from then on, each batch that comes back is
*told* to the algorithm (merged with the population, which keeps its best ``population``
designs by non-dominated rank and crowding distance) and one new batch is proposed. Batches
are told in the order they were proposed, whatever order their results arrive in: the
sequence of proposals and of results given to the algorithm is fixed by the seed, the
population, the batch and the lag, never by the workers' speed or number. So the designs
proposed (and numbered) are the same for 1 or 100 workers, and a search killed part-way
replays to the same point from the rows already written, evaluating only what is missing.
No worker waits on a generation's slowest design: ``lag`` batches stay in flight (a
generation's worth with the defaults), a finished one is replaced as soon as the ones
proposed before it are back. With ``batch = population`` and ``lag = 1`` it is the
generational NSGA-II (``benchmarks/bench_design_search.py`` measures both).

A design that is not feasible has no objectives; it is ranked by a constraint violation (1
for a design planned but beyond a limit such as its motors, 2 for one that could not be
planned: no geometry, out of reach, a singularity), so that the search is drawn first to
robots that can do the task, then to those that do it within their limits.

pymoo is in the ``design`` extra (imported when a search runs, :mod:`dextar._lazy`).
"""

from __future__ import annotations

import collections
import importlib.metadata
import importlib.util
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..errors import ConfigError
from .evaluate import Task
from .pareto import pareto_mask
from .space import DesignSpace
from .sweep import INSTALL_HINT, Chunks, Cluster, SweepStats, chunks_of, require_dask

nsga2 = lazy_module("pymoo.algorithms.moo.nsga2")
sms = lazy_module("pymoo.algorithms.moo.sms")
pymoo_problem = lazy_module("pymoo.core.problem")
pymoo_evaluator = lazy_module("pymoo.core.evaluator")
pymoo_static = lazy_module("pymoo.problems.static")
pymoo_termination = lazy_module("pymoo.core.termination")
pymoo_hv = lazy_module("pymoo.indicators.hv")

Row = dict[str, Any]

#: Designs a search proposes at a time by default (``[design].chunk``): five batches in
#: flight at the default population of 20, which keep two workers busy (at 8, two batches:
#: 2-worker efficiency 0.71 against 0.87-0.93, benchmarks/bench_design_search.py).
BATCH = 4

#: The adaptive searches (``[design] search``), beside the sweeps' samplings: NSGA-II
#: (survival by non-dominated rank and crowding distance) and SMS-EMOA (survival by rank and
#: each design's exclusive contribution to the hypervolume).
SEARCHES = ("nsga2", "smsemoa")
#: The reference point of a hypervolume, each objective scaled to [0, 1] between the ideal
#: and the nadir point of the front it is measured against (a usual choice, e.g. Ishibuchi
#: et al., Evol. Comput. 26(3), 2018: a little beyond the nadir, so that the front's extreme
#: points count).
REFERENCE_POINT = 1.1
#: Constraint violation of a design planned but beyond a limit, and of one never planned.
VIOLATION_LIMIT, VIOLATION_UNPLANNED = 1.0, 2.0


def require_pymoo() -> None:
    """Raise a :class:`ConfigError` naming the extra when pymoo is not installed."""
    if importlib.util.find_spec("pymoo") is None:
        raise ConfigError(f"[design] search = {' or '.join(map(repr, SEARCHES))} needs pymoo: "
                          f"{INSTALL_HINT}")


def pymoo_version() -> str:
    """The installed pymoo's version (the proposals depend on it: a search's signature)."""
    return importlib.metadata.version("pymoo")


@dataclass(frozen=True)
class SearchSettings:
    """An adaptive search: which, how many designs, how they go out.

    Attributes
    ----------
    kind : str
        ``"nsga2"``.
    population : int
        Designs the algorithm keeps (and the first sample's size).
    evaluations : int
        Designs evaluated in all (the first population included).
    seed : int
        Seed of the algorithm (the first sample has the space's).
    batch : int
        Designs proposed at a time, one unit of work (``[design].chunk``).
    lag : int, optional
        Batches in flight after the first population; default ``population // batch`` (at
        least 1): a generation's worth.
    chunk : int, optional
        Designs per unit of work (default ``batch``: one per batch; the first population
        in as many as it takes). It does not change the designs proposed.
    """

    kind: str = "nsga2"
    population: int = 20
    evaluations: int = 2000
    seed: int = 0
    batch: int = BATCH
    lag: int | None = None
    chunk: int | None = None

    def __post_init__(self) -> None:
        if self.kind not in SEARCHES:
            raise ConfigError(f"config key [design].search = {self.kind!r}: one of "
                              f"{', '.join(SEARCHES)} (or a sweep: sobol, grid, random)")
        if not (isinstance(self.population, int) and self.population >= 4):
            raise ConfigError(f"config key [design].population = {self.population!r} must be "
                              "an integer of at least 4")
        if not (isinstance(self.evaluations, int) and self.evaluations >= self.population):
            raise ConfigError(f"evaluations = {self.evaluations!r} ([design].evaluations or "
                              f"--samples) must be an integer of at least the population "
                              f"({self.population})")
        if not (isinstance(self.batch, int) and self.batch >= 1):
            raise ConfigError(f"config key [design].chunk = {self.batch!r} must be at least 1")
        if self.lag is not None and self.lag < 1:
            raise ConfigError(f"a search's lag = {self.lag} must be at least 1")
        if self.chunk is not None and self.chunk < 1:
            raise ConfigError(f"a search's chunk = {self.chunk} must be at least 1")

    @property
    def in_flight(self) -> int:
        """Batches proposed ahead of the results (the lag)."""
        return self.lag if self.lag is not None else max(1, self.population // self.batch)


def objectives_and_violation(space: DesignSpace, rows: Sequence[Row]) -> tuple[Array, Array]:
    """The objectives (n, k) to minimise and the constraint violation (n,) of ``rows``: the
    space's objectives and 0 for a feasible design; ``inf`` and :data:`VIOLATION_LIMIT` (all
    its objectives exist: planned, beyond a limit) or :data:`VIOLATION_UNPLANNED` for the
    others."""
    k = len(space.objectives)
    F = np.full((len(rows), k), np.inf)
    G = np.zeros(len(rows))
    ok = [i for i, r in enumerate(rows) if r["feasible"]]
    if ok:
        F[ok] = space.objective_values([rows[i] for i in ok])
    for i, r in enumerate(rows):
        if not r["feasible"]:
            planned = all(r.get(o.lstrip("-")) is not None for o in space.objectives)
            G[i] = VIOLATION_LIMIT if planned else VIOLATION_UNPLANNED
    return F, G


class Proposer:
    """SMS-EMOA or NSGA-II (pymoo's operators and survival: simulated binary crossover,
    polynomial mutation, binary tournament; rank, then hypervolume contribution or crowding)
    behind two calls: :meth:`ask` a batch of
    points of the unit cube, :meth:`tell` the rows of the oldest batch not told yet.

    Deterministic: the same calls in the same order give the same points (the algorithm's
    random generator is seeded; pymoo >= 0.6.2 draws from it alone).
    """

    def __init__(self, space: DesignSpace, settings: SearchSettings) -> None:
        """The algorithm set up on the space's unit cube; its first population is the
        space's sample (its sampling, ``population`` designs)."""
        require_pymoo()
        self.space, self.settings = space, settings
        k = len(space.dims)
        self.problem = pymoo_problem.Problem(n_var=k, n_obj=len(space.objectives),
                                             n_ieq_constr=1, xl=0.0, xu=1.0)
        first = replace(space, samples=settings.population).unit_sample()
        kind = nsga2.NSGA2 if settings.kind == "nsga2" else sms.SMSEMOA
        self.algorithm = kind(pop_size=settings.population, n_offsprings=settings.batch,
                              sampling=first, eliminate_duplicates=True)
        self.algorithm.setup(self.problem, termination=pymoo_termination.NoTermination(),
                             seed=settings.seed)
        self.pending: collections.deque[Any] = collections.deque()

    def ask(self, limit: int) -> Array:
        """The next batch (at most ``limit`` points, shape (m, k)); empty when the algorithm
        can propose no new design (every offspring a duplicate)."""
        pop = self.algorithm.ask() if limit > 0 else None
        if pop is None or len(pop) == 0:
            return np.empty((0, len(self.space.dims)))
        pop = pop[:limit]
        self.pending.append(pop)
        return np.asarray(pop.get("X"), float)

    def tell(self, rows: Sequence[Row]) -> None:
        """The rows of the oldest batch not yet told, in its order."""
        pop = self.pending.popleft()
        assert len(pop) == len(rows)
        F, G = objectives_and_violation(self.space, rows)
        static = pymoo_static.StaticProblem(self.problem, F=F, G=G[:, None])
        pymoo_evaluator.Evaluator().eval(static, pop)
        self.algorithm.tell(infills=pop)


@dataclass(frozen=True)
class SearchRun:
    """What a search run did.

    Attributes
    ----------
    stats : SweepStats
        Designs evaluated here (the others resumed), wall time, workers.
    designs : int
        Designs proposed in all (``evaluations``, fewer when the algorithm ran out of new
        designs).
    algorithm_s : float
        Time spent in this process proposing and telling (pymoo), of ``stats.wall_s``.
    """

    stats: SweepStats
    designs: int
    algorithm_s: float = 0.0


@dataclass
class _Batch:
    first: int
    designs: Array
    left: set[int] = field(default_factory=set)


def run_search(cluster: Cluster, task: Task, space: DesignSpace, settings: SearchSettings, *,
               resumed: Mapping[int, Row], on_chunk: Callable[[list[Row]], None],
               label: str = "designs.csv") -> SearchRun:
    """Search the space on Dask: propose, evaluate, tell, until ``settings.evaluations``.

    Parameters
    ----------
    cluster : Cluster
    task : Task
    space : DesignSpace
        Its ``samples`` is the first population's size.
    settings : SearchSettings
    resumed : mapping of int to dict
        Rows already evaluated (a killed run's), by design number: a proposed design found
        there is not evaluated again.
    on_chunk : callable
        Called in this process with each finished unit of work's rows, as they finish.
    label : str
        Where ``resumed`` comes from, for an error.

    Returns
    -------
    SearchRun

    Raises
    ------
    ConfigError
        A resumed row whose variables are not the design this search proposes under that
        number (another task, space, seed or pymoo).
    """
    distributed = require_dask()
    t0 = time.perf_counter()
    proposer = Proposer(space, settings)
    chunks = Chunks(cluster, task)
    rows: dict[int, Row] = {}
    batches: list[_Batch] = []
    queue = distributed.as_completed()
    evaluated = 0
    pending = 0
    algorithm_s = 0.0

    def propose() -> bool:
        nonlocal pending
        first = batches[-1].first + len(batches[-1].designs) if batches else 0
        nonlocal algorithm_s
        ta = time.perf_counter()
        U = proposer.ask(settings.evaluations - first)
        algorithm_s += time.perf_counter() - ta
        if not len(U):
            return False
        designs = space.from_unit(U)
        batch = _Batch(first, designs)
        for j, x in enumerate(designs):
            r = resumed.get(first + j)
            if r is None:
                batch.left.add(first + j)
            elif not np.allclose([r[k] for k in space.columns], x, rtol=1e-12, atol=0.0):
                raise ConfigError(f"--resume: design {first + j} in {label} is not the design "
                                  "this search proposes under that number (made with another "
                                  "task, [design], seed or pymoo version)")
            else:
                rows[first + j] = r
        for part in chunks_of(sorted(batch.left), settings.chunk or settings.batch):
            queue.add(chunks.submit(designs[part[0] - first:part[-1] - first + 1], part[0]))
            pending += 1
        batches.append(batch)
        return True

    propose()
    told = 0
    while told < len(batches):
        while told < len(batches) and not batches[told].left:
            b = batches[told]
            ta = time.perf_counter()
            proposer.tell([rows[i] for i in range(b.first, b.first + len(b.designs))])
            algorithm_s += time.perf_counter() - ta
            told += 1
            for _ in range(settings.in_flight if told == 1 else 1):
                if not propose():
                    break
        if told == len(batches):
            break
        fut = next(queue)
        pending -= 1
        got = fut.result()
        evaluated += len(got)
        for r in got:
            rows[r["design"]] = r
            for b in batches[told:]:
                b.left.discard(r["design"])
        on_chunk(got)
    assert pending == 0
    n = batches[-1].first + len(batches[-1].designs)
    return SearchRun(SweepStats(evaluated, time.perf_counter() - t0, cluster.workers), n,
                     algorithm_s)


# ------------------------------------------------------------------ hypervolume and progress


def hypervolume(F: Array, ideal: Array, nadir: Array) -> float:
    """The hypervolume of the points ``F`` (n, k), minimised, each objective scaled to [0, 1]
    between ``ideal`` and ``nadir`` (an objective of no spread keeps its scale), with the
    reference point :data:`REFERENCE_POINT` in every scaled objective (pymoo's, by moocore).
    Points beyond the reference point add nothing."""
    F = np.asarray(F, float)
    if not len(F):
        return 0.0
    ideal, nadir = np.asarray(ideal, float), np.asarray(nadir, float)
    span = np.where(nadir > ideal, nadir - ideal, 1.0)
    Fn = (F - ideal) / span
    Fn = Fn[(Fn < REFERENCE_POINT).all(axis=1)]
    if not len(Fn):
        return 0.0
    if Fn.shape[1] == 1:
        return float(REFERENCE_POINT - Fn.min())
    return float(pymoo_hv.HV(ref_point=np.full(Fn.shape[1], REFERENCE_POINT))(Fn))


@dataclass(frozen=True)
class HypervolumeCurve:
    """The hypervolume of the front found after each number of evaluations.

    Attributes
    ----------
    evaluations : ndarray of int
        Designs evaluated (in design order: a search's proposals, a sweep's sample).
    hypervolume : ndarray
        The hypervolume of the feasible designs among them (:func:`hypervolume`).
    ideal, nadir : ndarray
        The scaling: the ideal and nadir points (minimised objectives) of the front it is
        measured against (by default the final front).
    """

    evaluations: Array
    hypervolume: Array
    ideal: Array
    nadir: Array

    def at(self, evaluations: int) -> float:
        """The hypervolume after ``evaluations`` designs (the last point at or before)."""
        i = int(np.searchsorted(self.evaluations, evaluations, side="right")) - 1
        return float(self.hypervolume[i]) if i >= 0 else 0.0


def hypervolume_curve(F: Array, *, ideal: Array | None = None, nadir: Array | None = None,
                      points: int = 100, at: Iterable[int] | None = None) -> HypervolumeCurve:
    """The hypervolume after each number of designs of ``F`` (n, k) (minimised objectives in
    design order, a row of ``inf`` for a design that is not feasible), at ``points`` counts
    spread over ``1..n`` (or the counts ``at``), scaled by ``ideal`` and ``nadir`` (default:
    those of the front of all of ``F``)."""
    F = np.asarray(F, float)
    n, k = F.shape
    ok = np.isfinite(F).all(axis=1)
    if ideal is None or nadir is None:
        if not ok.any():
            z = np.zeros(k)
            return HypervolumeCurve(np.array([n]), np.zeros(1), z, z)
        front = F[ok][pareto_mask(F[ok])]
        ideal = front.min(axis=0) if ideal is None else ideal
        nadir = front.max(axis=0) if nadir is None else nadir
    counts = (sorted({int(c) for c in at if 1 <= c <= n}) if at is not None else
              sorted({int(c) for c in np.unique(np.geomspace(1, n, min(points, n)).round())}))
    front = np.empty((0, k))
    values, last = [], 0
    for c in counts:
        new = F[last:c][ok[last:c]]
        last = c
        if len(new):
            cand = np.vstack([front, new])
            front = cand[pareto_mask(cand)]
        values.append(hypervolume(front, ideal, nadir))
    return HypervolumeCurve(np.array(counts, int), np.array(values), np.asarray(ideal, float),
                            np.asarray(nadir, float))


@dataclass(frozen=True)
class Progress:
    """A sweep's or search's progress, after each unit of work.

    Attributes
    ----------
    done, total : int
        Designs with a row (resumed ones included) and designs in all.
    resumed : int
        Rows from an earlier run.
    feasible : int
        Feasible designs among the ``done``.
    hypervolume : float or None
        Of the feasible designs' front so far, each objective scaled between the ideal and
        nadir points of the first feasible designs (:attr:`ProgressMeter.box_after`
        designs): it only grows, by how much the front improves; None before.
    elapsed_s : float
    left_s : float or None
        Time left at the rate so far (None before a design is evaluated here).
    """

    done: int
    total: int
    resumed: int
    feasible: int
    hypervolume: float | None
    elapsed_s: float
    left_s: float | None

    @property
    def feasible_share(self) -> float:
        """Feasible designs over designs done."""
        return self.feasible / self.done if self.done else 0.0


class ProgressMeter:
    """Counts the rows of a sweep or search as they come, keeps the front found so far and
    its hypervolume (:class:`~dextar.design.search.Progress`)."""

    def __init__(self, space: DesignSpace, total: int, resumed: Iterable[Row] = (), *,
                 box_after: int = 40) -> None:
        """A meter of ``total`` designs; ``resumed`` rows count as done; the hypervolume's
        box is fixed by the feasible designs among the first ``box_after`` rows."""
        self.space, self.total, self.box_after = space, total, box_after
        self.t0 = time.perf_counter()
        self.done = self.feasible = self.evaluated = 0
        self.front = np.empty((0, len(space.objectives)))
        self.box: tuple[Array, Array] | None = None
        self.first: list[Array] = []
        resumed = list(resumed)
        self.resumed = len(resumed)
        self._count(resumed)

    def _count(self, rows: Sequence[Row]) -> None:
        self.done += len(rows)
        ok = [r for r in rows if r["feasible"]]
        self.feasible += len(ok)
        if not ok:
            return
        F = self.space.objective_values(ok)
        cand = np.vstack([self.front, F])
        self.front = cand[pareto_mask(cand)]
        if self.box is None:
            self.first.append(F)
            if self.done >= min(self.box_after, self.total):
                allF = np.vstack(self.first)
                self.box = (allF.min(axis=0), allF.max(axis=0))

    def add(self, rows: Sequence[Row]) -> Progress:
        """Count a finished unit of work's rows; the progress now."""
        self._count(rows)
        self.evaluated += len(rows)
        elapsed = time.perf_counter() - self.t0
        left = (self.total - self.done) * elapsed / self.evaluated if self.evaluated else None
        hv = None if self.box is None else hypervolume(self.front, *self.box)
        return Progress(self.done, self.total, self.resumed, self.feasible, hv, elapsed, left)
