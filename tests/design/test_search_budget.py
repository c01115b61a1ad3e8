"""[design] search = "smsemoa" (SMS-EMOA: survival by each design's exclusive contribution to
the front's hypervolume) beside "nsga2": named in the settings and the task file, its
proposals fixed by the seed whatever order the results arrive in, a resume that replays it,
and progress on the toy (ZDT1) with margin. The figures on the robot tasks (hypervolume
against evaluations, both searches and the Sobol sweep) are benchmarks/bench_design_search.py's."""

from dataclasses import replace

import numpy as np
import pytest

from dextar.config import load_scenario
from dextar.design.search import (
    SEARCHES,
    SearchSettings,
    hypervolume,
    hypervolume_curve,
    objectives_and_violation,
)
from dextar.errors import ConfigError

from . import _toy
from .test_design import write_task

pytest.importorskip("pymoo")


def lengths(rows):
    return np.array([[r[k] for k in ("l1", "l2", "L1", "L2", "d")] for r in rows])


def test_the_searches_are_named_in_the_settings_and_the_task_file(tmp_path):
    assert SEARCHES == ("nsga2", "smsemoa")
    with pytest.raises(ConfigError, match="one of nsga2, smsemoa"):
        SearchSettings("sms")
    task = write_task(tmp_path, design='[design]\nl = [50.0, 120.0]\nsearch = "smsemoa"\n'
                      "population = 8\nevaluations = 16\n")
    settings = load_scenario(task).design.search()
    assert settings is not None and settings.kind == "smsemoa"
    assert settings.population == 8 and settings.evaluations == 16


def test_smsemoa_proposals_are_fixed_by_the_seed_whatever_order_results_arrive_in(
        monkeypatch):
    settings = SearchSettings("smsemoa", 12, 60, 2, batch=4)
    fifo = lengths(_toy.run(monkeypatch, settings)[0])
    lifo = lengths(_toy.run(monkeypatch, settings, pick=lambda n: n - 1)[0])
    assert len(fifo) == 60 and np.array_equal(fifo, lifo)
    assert len(np.unique(fifo, axis=0)) == 60
    # the same first population (the space's Sobol sample), then its own proposals
    nsga2 = lengths(_toy.run(monkeypatch, replace(settings, kind="nsga2"))[0])
    assert np.array_equal(fifo[:12], nsga2[:12])
    assert not np.array_equal(fifo[12:], nsga2[12:])


def test_a_resumed_smsemoa_search_evaluates_only_what_is_missing(monkeypatch):
    settings = SearchSettings("smsemoa", 12, 60, 4, batch=4)
    full = _toy.run(monkeypatch, settings)[0]
    kept = {r["design"]: r for r in full[:45] if r["design"] % 3}  # as a kill leaves them
    rows, _, ran = _toy.run(monkeypatch, settings, resumed=kept)
    assert rows == full and ran.stats.evaluated == 60 - len(kept)


def test_smsemoa_makes_progress_on_the_toy_where_a_sweep_of_as_many_does_not(monkeypatch):
    """ZDT1 on three variables with designs that are not feasible, 600 designs: the search
    reaches 0.72 of the true front's hypervolume (measured 0.76-0.97 over ten seeds, 0.96-0.97
    at these two); a Sobol sample of as many stays below (0.50-0.67 over ten seeds)."""
    ref = hypervolume(_toy.true_front(), np.zeros(2), np.ones(2))
    for seed in (0, 1):
        rows, _, _ = _toy.run(monkeypatch, SearchSettings("smsemoa", 24, 600, seed, batch=8),
                              space=replace(_toy.SPACE, seed=seed))
        F = objectives_and_violation(_toy.SPACE, rows)[0]
        got = hypervolume_curve(F, ideal=np.zeros(2), nadir=np.ones(2), at=[600]).at(600)
        assert got >= 0.72 * ref
        sweep = replace(_toy.SPACE, samples=600, seed=seed)
        sobol = [_toy.toy_row(x, i) for i, x in enumerate(sweep.designs())]
        assert hypervolume(objectives_and_violation(sweep, sobol)[0], np.zeros(2),
                           np.ones(2)) < 0.72 * ref


def test_a_search_keeps_five_batches_in_flight_by_default(tmp_path):
    """At [design].chunk = 8 a search of population 20 had 2 batches in flight and 2 workers
    waited at each batch's return (efficiency 0.71; at chunk 4, five in flight: 0.87-0.93,
    benchmarks/bench_design_search.py): a search's default chunk is 4, a sweep's stays 8,
    and a chunk written in the file is kept."""
    def design(text):
        return load_scenario(write_task(tmp_path, design="[design]\nl = [50.0, 120.0]\n"
                                        + text)).design

    search = design('search = "smsemoa"\n').search()
    assert search is not None and search.batch == 4 and search.in_flight == 5
    assert design('search = "nsga2"\n').search().in_flight == 5
    assert design("samples = 16\n").chunk == 8
    assert design('search = "smsemoa"\nchunk = 8\n').search().in_flight == 2
