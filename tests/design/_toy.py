"""A stand-in for the Dask evaluator (a client, futures and ``as_completed`` that finish the
chunks in an order of the test's choosing) and a toy task with a known Pareto front, to
test the search's driver without workers."""

from __future__ import annotations

import numpy as np

from dextar.design.space import LENGTHS, METRICS, DesignSpace

#: The toy's design space: three dimensions (l for both proximal rods, L, d), two objectives.
SPACE = DesignSpace((("l", 50.0, 150.0, (0, 1)), ("L", 50.0, 150.0, (2, 3)),
                     ("d", 0.0, 100.0, (4,))), (72.0, 72.0, 87.0, 87.0, 60.0), None, 24,
                    "sobol", 0, ("cycle_time_s", "footprint_mm"))


def unit(x):
    """A design's point of the unit cube."""
    return np.array([(x[0] - 50.0) / 100.0, (x[2] - 50.0) / 100.0, x[4] / 100.0])


def toy_row(x, number):
    """ZDT1 (Zitzler, Deb & Thiele 2000) on the unit cube: f1 = u0, f2 = g (1 - sqrt(f1 /
    g)), g = 1 + 9 mean(u1, u2); not feasible where u2 > 0.9 (never planned) or u1 > 0.95
    (planned, beyond a limit). Its front: g = 1 (u1 = u2 = 0), f2 = 1 - sqrt(f1)."""
    u = unit(x)
    g = 1.0 + 9.0 * (u[1] + u[2]) / 2.0
    row = {"design": number, **{k: float(v) for k, v in zip(LENGTHS, x, strict=True)},
           "feasible": True, "reason": "", **dict.fromkeys(METRICS, 0.0)}
    row["cycle_time_s"] = float(u[0])
    row["footprint_mm"] = float(g * (1.0 - np.sqrt(u[0] / g)))
    if u[2] > 0.9:
        row.update({"feasible": False, "reason": "geometry: toy", **dict.fromkeys(METRICS)})
    elif u[1] > 0.95:
        row.update({"feasible": False, "reason": "motors exceeded: toy"})
    return row


def true_front(n=2001):
    """Points of the toy's Pareto front (n, 2)."""
    f1 = np.linspace(0.0, 1.0, n)
    return np.stack([f1, 1.0 - np.sqrt(f1)], -1)


class Future:
    def __init__(self, designs, first):
        self.designs, self.first = designs, first

    def result(self):
        return [toy_row(x, self.first + j) for j, x in enumerate(self.designs)]


class Client:
    """Chunks as :class:`Future`; records every submission."""

    def __init__(self):
        self.submitted = []

    def scatter(self, task, **kwargs):
        return task

    def submit(self, fn, task, designs, first, **kwargs):
        self.submitted.append((first, len(designs)))
        return Future(np.array(designs), first)


class Cluster:
    workers = 1

    def __init__(self):
        self.client = Client()


class Distributed:
    """``as_completed`` handing futures back in the order ``pick`` chooses among those in
    flight (``pick(n)`` -> an index below n)."""

    def __init__(self, pick):
        self.pick = pick

    def as_completed(self):
        pick = self.pick

        class AsCompleted:
            def __init__(self):
                self.futures = []

            def add(self, f):
                self.futures.append(f)

            def __iter__(self):
                return self

            def __next__(self):
                if not self.futures:
                    raise StopIteration
                return self.futures.pop(pick(len(self.futures)))

        return AsCompleted()


def run(monkeypatch, settings, pick=lambda n: 0, resumed=None, space=SPACE):
    """The search on the toy, chunks finishing in the order ``pick`` gives; its rows in
    design order and the cluster (with the submissions)."""
    from dextar.design import search

    monkeypatch.setattr(search, "require_dask", lambda: Distributed(pick))
    cluster = Cluster()
    got = {}
    ran = search.run_search(cluster, None, space, settings, resumed=resumed or {},
                            on_chunk=lambda rows: got.update((r["design"], r) for r in rows))
    rows = {**(resumed or {}), **got}
    return [rows[i] for i in range(ran.designs)], cluster, ran
