"""The sweep engine: designs go out to Dask workers in chunks and come back as rows.

Dask (``dask.distributed``) runs the chunks: a ``LocalCluster`` of worker processes by
default, or a running cluster by its scheduler's address. A chunk is evaluated by
:func:`~dextar.design.evaluate.evaluate_chunk`; a worker that dies has its chunks retried by
Dask; a design that fails is a row with its reason, so the sweep never stops for one design.
Rows reach the caller chunk by chunk (``on_chunk``), in the order chunks finish.

In the Dask dashboard (``Cluster.dashboard``, with bokeh installed) the chunks are the tasks
named ``dextar-design`` (their key prefix): the Progress panel of the status page counts
them, the Task Stream shows each one; the Fine Performance Metrics page (unit ``designs``)
counts the designs evaluated, ``feasible`` and ``not feasible``, as the workers report them.
"""

from __future__ import annotations

import importlib.util
import time
import uuid
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import islice
from typing import Any

from .._arrays import Array
from .._lazy import lazy_module
from ..errors import ConfigError
from .evaluate import Task, evaluate_chunk

#: Dask's distributed scheduler (the ``design`` extra), imported when a sweep runs.
dask_distributed = lazy_module("distributed")
dask_metrics = lazy_module("distributed.metrics")

#: How to get the extra that holds Dask.
INSTALL_HINT = "pip install -e '.[design]' (or pip install 'dextar[design]')"
#: Chunks kept in flight per worker.
IN_FLIGHT_PER_WORKER = 4
#: Seconds to wait for a scheduler given by address.
CONNECT_TIMEOUT_S = 8
#: The key prefix of every chunk's Dask task (the name the dashboard shows).
TASK_PREFIX = "dextar-design"


@dataclass(frozen=True)
class SweepStats:
    """What a sweep run did: designs evaluated, wall time (s) and workers."""

    evaluated: int
    wall_s: float
    workers: int


def require_dask() -> Any:
    """The ``distributed`` module, or a :class:`ConfigError` naming the extra to install."""
    if importlib.util.find_spec("distributed") is None:
        raise ConfigError(f"dextar design needs Dask (dask.distributed): {INSTALL_HINT}")
    return dask_distributed


def chunks_of(indices: Sequence[int], size: int) -> list[list[int]]:
    """``indices`` (sorted) in runs of at most ``size`` consecutive design numbers."""
    out: list[list[int]] = []
    for i in indices:
        if out and len(out[-1]) < size and out[-1][-1] == i - 1:
            out[-1].append(i)
        else:
            out.append([i])
    return out


def evaluate_chunk_metered(task: Task, designs: Array, first: int) -> list[dict[str, Any]]:
    """:func:`~dextar.design.evaluate.evaluate_chunk`, and on a Dask worker the designs it
    evaluated reported to the dashboard's Fine Performance Metrics (unit ``designs``:
    ``feasible`` and ``not feasible``)."""
    rows = evaluate_chunk(task, designs, first)
    ok = sum(1 for r in rows if r["feasible"])
    meter = dask_metrics.context_meter
    meter.digest_metric("feasible", ok, "designs")
    meter.digest_metric("not feasible", len(rows) - ok, "designs")
    return rows


class Chunks:
    """The units of work of one run on a cluster: the task sent to every worker once, each
    chunk a Dask task named ``dextar-design-<run>-<first design>`` (retried twice when its
    worker dies)."""

    def __init__(self, cluster: Cluster, task: Task) -> None:
        """Send ``task`` to the workers."""
        self.client = cluster.client
        # a key of its own (hash=False): a sweep run right after another on the same client
        # would otherwise share the key the first one is releasing, and lose the task
        self.task = self.client.scatter(task, broadcast=True, hash=False)
        self.run = uuid.uuid4().hex[:8]

    def submit(self, designs: Array, first: int) -> Any:
        """The future of the rows of ``designs`` (m, columns) numbered from ``first``."""
        return self.client.submit(evaluate_chunk_metered, self.task, designs, first,
                                  key=f"{TASK_PREFIX}-{self.run}-{first}", retries=2)


class Cluster:
    """A Dask client: on a new ``LocalCluster`` of ``workers`` processes (default: the
    cores), or on the running scheduler at ``scheduler``. A context manager; closing it
    closes the local cluster."""

    def __init__(self, *, workers: int | None = None, scheduler: str | None = None) -> None:
        """Connect (within :data:`CONNECT_TIMEOUT_S` for a scheduler address).

        Raises
        ------
        ConfigError
            Dask is not installed, ``workers`` is not positive, or no scheduler answers.
        """
        distributed = require_dask()
        if workers is not None and workers < 1:
            raise ConfigError(f"--workers {workers} must be at least 1")
        self.cluster = None
        if scheduler is not None:
            try:
                self.client = distributed.Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S}s")
            except (OSError, TimeoutError, ValueError, TypeError) as exc:
                raise ConfigError(f"--scheduler {scheduler!r}: no Dask scheduler answers "
                                  f"there within {CONNECT_TIMEOUT_S} s ({type(exc).__name__}: "
                                  f"{exc})") from None
        else:
            self.cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1,
                                                    processes=True, dashboard_address=":0")
            self.client = distributed.Client(self.cluster)

    @property
    def dashboard(self) -> str | None:
        """The address of the Dask dashboard (None when bokeh, which serves it, is missing)."""
        if importlib.util.find_spec("bokeh") is None:
            return None
        link = getattr(self.client, "dashboard_link", None)
        return str(link) if link else None

    @property
    def workers(self) -> int:
        """Workers the scheduler knows now."""
        return len(self.client.scheduler_info().get("workers", {}))

    def close(self) -> None:
        """Close the client (and the local cluster)."""
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()

    def __enter__(self) -> Cluster:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def run_sweep(cluster: Cluster, task: Task, designs: Array, todo: Sequence[int], *,
              chunk: int, on_chunk: Callable[[list[dict[str, Any]]], None],
              progress: Callable[[int, int], None] | None = None) -> SweepStats:
    """Evaluate the designs numbered ``todo`` (rows of ``designs`` (n, 5), mm) on Dask.

    Parameters
    ----------
    cluster : Cluster
    task : Task
    designs : ndarray, shape (n, 5)
    todo : sequence of int
        The designs to evaluate (the others are done already).
    chunk : int
        Designs per unit of work.
    on_chunk : callable
        Called in this process with each finished chunk's rows, as chunks finish.
    progress : callable, optional
        ``progress(done, total)`` after each chunk.

    Returns
    -------
    SweepStats
    """
    distributed = require_dask()
    t0 = time.perf_counter()
    n_workers = cluster.workers
    done = 0
    if todo:
        chunks = Chunks(cluster, task)
        parts = iter(chunks_of(sorted(todo), chunk))

        def submit(p: list[int]) -> Any:
            return chunks.submit(designs[p[0]:p[-1] + 1], p[0])

        # a bounded number of chunks in flight: the scheduler and this process stay small
        # whatever the number of designs
        in_flight = max(IN_FLIGHT_PER_WORKER * max(n_workers, 1), 8)
        queue = distributed.as_completed([submit(p) for p in islice(parts, in_flight)])
        for fut in queue:
            rows = fut.result()
            on_chunk(rows)
            done += len(rows)
            if progress is not None:
                progress(done, len(todo))
            nxt = next(parts, None)
            if nxt is not None:
                queue.add(submit(nxt))
    return SweepStats(len(todo), time.perf_counter() - t0, n_workers)
