"""dextar design with [design] search = "nsga2": the driver's proposals whatever order the
results come back in, a resume that replays them, the optimiser's progress on a toy with a
known front (with margin), on Dask the same designs.csv for 1 and 2 workers and after a kill
and a resume; the hypervolume, the progress line, the axis words, bad tables refused."""

import json
import os
import re
import signal
import subprocess
import sys
import time
import warnings
from dataclasses import replace

import numpy as np
import pytest

from dextar.cli import main
from dextar.config import load_scenario
from dextar.design.search import (
    SearchSettings,
    hypervolume,
    hypervolume_curve,
    objectives_and_violation,
)
from dextar.output.design import metric_label

from . import _toy
from .test_design import TASK, rows_of, write_task

pytest.importorskip("distributed")
pytest.importorskip("pymoo")

SEARCH = TASK.replace("samples = 32\n", 'search = "nsga2"\npopulation = 8\nevaluations = 32\n')
assert "nsga2" in SEARCH  # (the replace must hit test_design.TASK)


def lengths(rows):
    return np.array([[r[k] for k in ("l1", "l2", "L1", "L2", "d")] for r in rows])


# ------------------------------------------------------------------ the driver, without Dask


@pytest.mark.slow
@pytest.mark.parametrize("settings", [SearchSettings("nsga2", 24, 160, 3, batch=4),
                                      SearchSettings("nsga2", 24, 150, 3, batch=24, lag=1)],
                         ids=["steady-state", "generational"])
def test_the_proposals_do_not_depend_on_the_order_results_arrive_in(monkeypatch, settings):
    """Chunks finishing first-in-first-out, last-in-first-out or at random give the same
    designs (the batches are told in the order they were proposed)."""
    rng = np.random.default_rng(7)
    runs = [_toy.run(monkeypatch, settings, pick)[0] for pick in
            (lambda n: 0, lambda n: n - 1, lambda n: int(rng.integers(n)))]
    assert len(runs[0]) == settings.evaluations
    for rows in runs[1:]:
        assert np.array_equal(lengths(rows), lengths(runs[0]))
    # the first population is the space's own Sobol sample; the others differ from it
    first = replace(_toy.SPACE, samples=24).designs()
    assert np.array_equal(lengths(runs[0][:24]), first)
    assert len(np.unique(lengths(runs[0]), axis=0)) > 0.9 * settings.evaluations


def test_steady_state_keeps_the_batches_in_flight(monkeypatch):
    """After the first population, a batch goes out as each one is told: never more than
    ``lag`` batches of ``batch`` designs out (here 6 of 4), one unit of work each."""
    settings = SearchSettings("nsga2", 24, 120, 1, batch=4)
    _, cluster, ran = _toy.run(monkeypatch, settings)
    sizes = [n for _, n in cluster.client.submitted]
    assert sizes[:6] == [4] * 6 and sum(sizes) == 120 and ran.stats.evaluated == 120
    assert settings.in_flight == 6


@pytest.mark.slow
def test_a_resumed_search_replays_and_evaluates_only_what_is_missing(monkeypatch):
    settings = SearchSettings("nsga2", 24, 120, 5, batch=4)
    full, _, _ = _toy.run(monkeypatch, settings)
    rng = np.random.default_rng(1)
    kept = {r["design"]: r for r in full[:90] if rng.random() < 0.7}  # out of order, as killed
    rows, cluster, ran = _toy.run(monkeypatch, settings, resumed=kept)
    assert rows == full
    assert ran.stats.evaluated == 120 - len(kept)
    assert sum(n for _, n in cluster.client.submitted) == 120 - len(kept)
    # a row that is not the design the search proposes under its number is refused
    bad = dict(kept)
    i = max(bad)
    bad[i] = {**bad[i], "l1": bad[i]["l1"] + 1.0}
    with pytest.raises(Exception, match=rf"--resume: design {i} in designs.csv is not"):
        _toy.run(monkeypatch, settings, resumed=bad)


@pytest.mark.slow
def test_the_search_finds_the_toy_front_where_a_sweep_of_as_many_does_not(monkeypatch):
    """ZDT1 on three variables, with designs that are not feasible: 600 designs of the
    search reach 0.85 of the true front's hypervolume (measured 0.93-0.98 over 10 seeds, batch
    4 and 8, and generational); a Sobol sample of as many stays far below (0.50-0.67)."""
    ref = hypervolume(_toy.true_front(), np.zeros(2), np.ones(2))
    for seed in (0, 1):
        rows, _, _ = _toy.run(monkeypatch, SearchSettings("nsga2", 24, 600, seed, batch=4),
                              space=replace(_toy.SPACE, seed=seed))
        F = objectives_and_violation(_toy.SPACE, rows)[0]
        assert hypervolume_curve(F, ideal=np.zeros(2), nadir=np.ones(2), at=[600]).at(600) \
            >= 0.85 * ref
        sweep = replace(_toy.SPACE, samples=600, seed=seed)
        sobol = [_toy.toy_row(x, i) for i, x in enumerate(sweep.designs())]
        F = objectives_and_violation(sweep, sobol)[0]
        assert hypervolume(F, np.zeros(2), np.ones(2)) < 0.75 * ref


def test_the_violation_ranks_designs_planned_before_the_others():
    rows = [_toy.toy_row(x, 0) for x in ([60, 60, 60, 60, 10], [60, 60, 149, 149, 10],
                                         [60, 60, 60, 60, 95])]
    F, G = objectives_and_violation(_toy.SPACE, rows)
    assert G.tolist() == [0.0, 1.0, 2.0]
    assert np.isfinite(F[0]).all() and np.isinf(F[1:]).all()


# ------------------------------------------------------------------ the hypervolume


def test_hypervolume_against_closed_forms():
    # two points of a 2-objective front in [0, 1]^2, reference point 1.1
    F = np.array([[0.0, 1.0], [1.0, 0.0]])
    assert hypervolume(F, [0, 0], [1, 1]) == pytest.approx(0.11 + 0.11 - 0.01)
    assert hypervolume(np.array([[0.5, 0.5, 0.5]]), [0, 0, 0], [1, 1, 1]) == \
        pytest.approx(0.6 ** 3)
    assert hypervolume(np.array([[2.0, 0.0]]), [0, 0], [1, 1]) == 0.0  # beyond the reference
    # scaling: the same front in other units has the same hypervolume
    assert hypervolume(F * [3.0, 1000.0] + 5, [5, 5], [8, 1005]) == \
        pytest.approx(hypervolume(F, [0, 0], [1, 1]))
    # a point the front dominates adds nothing
    assert hypervolume(np.vstack([F, [0.5, 1.05]]), [0, 0], [1, 1]) == \
        pytest.approx(hypervolume(F, [0, 0], [1, 1]))
    # the quarter circle's front: the area above it within the reference box
    t = np.linspace(0, np.pi / 2, 4001)
    arc = np.stack([1 - np.cos(t), 1 - np.sin(t)], -1)
    assert hypervolume(arc, [0, 0], [1, 1]) == pytest.approx(1.21 - 1 + np.pi / 4, abs=1e-3)


def test_the_curve_grows_and_ends_at_the_whole_front():
    rng = np.random.default_rng(3)
    F = rng.random((300, 3))
    F[rng.random(300) < 0.2] = np.inf  # designs that are not feasible
    c = hypervolume_curve(F, points=40)
    assert (np.diff(c.hypervolume) >= 0).all() and c.evaluations[-1] == 300
    ok = np.isfinite(F).all(axis=1)
    assert c.hypervolume[-1] == pytest.approx(hypervolume(F[ok], c.ideal, c.nadir))
    assert c.at(0) == 0.0 and c.at(10**6) == c.hypervolume[-1]


# ------------------------------------------------------------------ words and progress


def test_axes_are_named_in_words_and_units():
    assert metric_label("cycle_time_s") == "cycle time [s]"
    assert metric_label("footprint_mm").endswith("[mm]")
    assert metric_label("-min_type2_distance") == \
        "distance to parallel singularities (smallest sine) [-], maximised"
    assert metric_label("workspace_area_mm2") == "usable workspace area [mm²]"
    # a metric the design space gains later is named from its name
    assert metric_label("shaking_force_peak_N") == "shaking force peak [N]"
    assert metric_label("rms_torque_A_Nm") == "RMS torque of motor A [N m]"


def test_the_progress_line():
    from dextar.commands.design import duration_text, progress_line
    from dextar.design.search import Progress

    p = Progress(340, 2000, 40, 204, 0.8123, 10.0, 130.0)
    assert progress_line(p) == ("designs 340/2000 (40 resumed), feasible 60 %, hypervolume "
                                "0.8123, about 2 min 10 s left")
    assert progress_line(Progress(5, 10, 0, 0, None, 1.0, None)) == "designs 5/10, feasible 0 %"
    assert duration_text(3725) == "1 h 02 min" and duration_text(0.2) == "1 s"


def test_the_meter_counts_and_its_hypervolume_only_grows():
    from dextar.design.search import ProgressMeter

    rows = [_toy.toy_row(x, i) for i, x in
            enumerate(replace(_toy.SPACE, samples=200).designs())]
    meter = ProgressMeter(_toy.SPACE, 250, rows[:20], box_after=40)
    assert meter.done == 20 and meter.resumed == 20
    seen = [meter.add(rows[i:i + 10]) for i in range(20, 200, 10)]
    assert seen[-1].done == 200 and seen[-1].feasible == sum(r["feasible"] for r in rows)
    hv = [p.hypervolume for p in seen if p.hypervolume is not None]
    assert seen[0].hypervolume is None and hv and (np.diff(hv) >= 0).all()
    assert seen[-1].left_s is not None and seen[-1].left_s > 0


# ------------------------------------------------------------------ on Dask, by the command


@pytest.fixture(scope="module")
def search2(tmp_path_factory, scheduler):
    """The task searched on the session's two workers."""
    folder = tmp_path_factory.mktemp("search")
    task = write_task(folder, design=SEARCH[SEARCH.index("[design]"):])
    out = folder / "two"
    assert main(["design", str(task), "--out", str(out), "--scheduler", scheduler,
                 "--quiet"]) == 0
    return task, out


@pytest.mark.slow
def test_the_search_writes_its_rows_front_and_curve(search2):
    task, out = search2
    rows = rows_of(out)
    assert [r["design"] for r in rows] == list(range(32))
    s = json.loads((out / "summary.json").read_text())
    assert s["search"] == "nsga2" and s["population"] == 8 and s["designs"] == 32
    assert s["batch"] == 4 and s["batches_in_flight"] == 2
    hv = s["hypervolume"]
    assert hv["evaluations"][-1] == 32 and s["final_hypervolume"] == hv["value"][-1] > 0
    assert (np.diff(hv["value"]) >= 0).all()
    for name in ("hypervolume", "pareto"):
        assert (out / f"{name}.png").stat().st_size > 1000
    # the first population is the space's Sobol sample of 8
    _, space = load_scenario(task).design_task()
    assert np.array_equal(lengths(rows[:8]), replace(space, samples=8).designs())
    assert "design search of task.toml" in (out / "report.html").read_text().lower()


@pytest.mark.slow
def test_one_worker_gives_the_same_search_file(search2, tmp_path):
    task, out2 = search2
    out1 = tmp_path / "one"
    assert main(["design", str(task), "--out", str(out1), "--workers", "1", "--quiet",
                 "--no-figures"]) == 0  # (the figures are drawn from the files compared)
    assert (out1 / "designs.csv").read_bytes() == (out2 / "designs.csv").read_bytes()
    assert (out1 / "pareto.csv").read_bytes() == (out2 / "pareto.csv").read_bytes()


@pytest.mark.slow
def test_a_killed_search_resumes_to_the_same_front(search2, tmp_path, scheduler):
    task, out2 = search2
    out = tmp_path / "killed"
    proc = subprocess.Popen([sys.executable, "-m", "dextar", "design", str(task), "--out",
                             str(out), "--scheduler", scheduler, "--quiet"],
                            start_new_session=True)
    csv_path = out / "designs.csv"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:  # past the first population (8 designs)
        if csv_path.exists() and len(csv_path.read_text().splitlines()) > 15:
            break
        if proc.poll() is not None:
            break
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    partial = csv_path.read_text()
    done = len(partial.splitlines()) - 1
    assert 8 < done < 32, done  # killed part-way, past the first population
    csv_path.write_text(partial + "32,1.0,2.")  # a line cut short by the kill
    assert main(["design", str(task), "--out", str(out), "--resume", "--scheduler", scheduler,
                 "--quiet", "--no-figures"]) == 0
    assert (out / "pareto.csv").read_bytes() == (out2 / "pareto.csv").read_bytes()
    assert csv_path.read_bytes() == (out2 / "designs.csv").read_bytes()
    s = json.loads((out / "summary.json").read_text())
    assert s["resumed"] == done and s["evaluated"] == 32 - done


@pytest.mark.slow
def test_resume_refuses_another_search(search2, tmp_path, capsys):
    import shutil

    task, out2 = search2
    out = tmp_path / "copy"
    shutil.copytree(out2, out)
    assert main(["design", str(task), "--out", str(out), "--resume", "--seed", "5"]) == 2
    assert "was made with another task" in capsys.readouterr().err


@pytest.mark.slow
def test_the_dashboard_counts_the_designs(tmp_path):
    """The workers report each chunk's designs to the scheduler: its Fine Performance
    Metrics (unit designs) under the tasks' prefix dextar-design. (A cluster of its own: on
    the session's, the chunks of a search killed by another test may still be reporting.)"""
    from dextar.design.sweep import Cluster, run_sweep

    def counts(dask_scheduler):
        return {k[-2]: v for k, v in dask_scheduler.cumulative_worker_metrics.items()
                if isinstance(k, tuple) and k[-1] == "designs" and "dextar-design" in k}

    task, space = load_scenario(write_task(tmp_path)).design_task()
    with Cluster(workers=1) as cluster:
        c = cluster.client
        before = c.run_on_scheduler(counts)
        rows: list = []
        run_sweep(cluster, task, space.designs()[:8], range(8), chunk=4, on_chunk=rows.extend)
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline:  # the workers' heartbeats carry the metrics
            after = c.run_on_scheduler(counts)
            new = {k: after.get(k, 0) - before.get(k, 0) for k in ("feasible", "not feasible")}
            if sum(new.values()) >= 8:
                break
            time.sleep(0.3)
        assert new == {"feasible": sum(r["feasible"] for r in rows),
                       "not feasible": sum(not r["feasible"] for r in rows)}
        assert "dextar-design" in c.run_on_scheduler(
            lambda dask_scheduler: list(dask_scheduler.task_prefixes))


# ------------------------------------------------------------------ bad input


@pytest.mark.parametrize("design, message", [
    ('l = [50.0, 120.0]\nsearch = "nsga2"\nsampling = "grid"\n',
     r"\[design\].search = 'nsga2' and \[design\].sampling = 'grid' disagree"),
    ('l = [50.0, 120.0]\nsearch = "nsga2"\nsamples = 100\n',
     r"\[design\].samples is a sweep's"),
    ('l = [50.0, 120.0]\npopulation = 20\n', r"\[design\].population is a search's"),
    ('l = [50.0, 120.0]\nsearch = "nsga2"\npopulation = 2\n', r"\[design\].population"),
    ('l = [50.0, 120.0]\nsearch = "nsga2"\npopulation = 50\nevaluations = 20\n',
     r"evaluations = 20 .* at least the population \(50\)"),
    ('l = [50.0, 120.0]\nsearch = "nsga3"\n', r"\[design\].search"),
])
def test_bad_search_tables_exit_2(tmp_path, capsys, design, message):
    task = write_task(tmp_path, design=f"[design]\n{design}")
    assert main(["design", str(task), "--out", str(tmp_path / "o"), "--workers", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and re.search(message, err), err
    assert not (tmp_path / "o").exists()


def test_without_pymoo_the_extra_is_named(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "pymoo", None)
    task = write_task(tmp_path, design=SEARCH[SEARCH.index("[design]"):])
    assert main(["design", str(task), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "needs pymoo" in err and "pip install -e '.[design]'" in err
    assert not (tmp_path / "o").exists()


def test_no_warning_where_the_time_optimal_law_names_an_unreachable_stage(monkeypatch):
    """A pick-and-place design whose time-optimal plan fails at a stage after its torque
    limit was tightened to nothing: the reason is a row, no RuntimeWarning (numpy's divide
    by zero reached the terminal from every worker). The law now first refines its grid
    where the check finds an excess, and this design then fits its motors (near the
    envelope's top speed): the tightening path is taken here with the refinement off."""
    from pathlib import Path

    from dextar.config import load_toml
    from dextar.design.evaluate import evaluate_design
    from dextar.laws import time_optimal

    from ..robustness.harness import toml_text

    doc = load_toml(Path(__file__).parents[2] / "examples" / "pick_place.toml")
    doc["design"] = {"l1": [20.0, 200.0], "samples": 1, "grid": 50}
    path = Path(__import__("tempfile").mkdtemp()) / "pp.toml"
    path.write_text(toml_text(doc))
    task, _ = load_scenario(path).design_task()
    x = [53.501671366393566, 133.4673346579075, 93.27383426949382, 62.73520674556494,
         21.362981339916587]
    refined = evaluate_design(task, x)
    assert refined["feasible"], refined["reason"]
    monkeypatch.setattr(time_optimal, "MAX_SPLIT", 0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        row = evaluate_design(task, x)
    # (the law's last motion beyond its tightened limits is now returned and sized: the
    # envelope's limit named with its units; before, no motion was found)
    assert not row["feasible"], row
    assert ("no motion within the limits passes" in row["reason"]
            or ("motors exceeded: motor A torque" in row["reason"]
                and "N m above its limit" in row["reason"]
                and "torque-speed envelope's at" in row["reason"])), row["reason"]


def _search_tables():
    from hypothesis import strategies as st

    value = st.one_of(st.sampled_from(["nsga2", "sobol", "grid", "random", "nsga3", ""]),
                      st.integers(-3, 5000), st.floats(allow_nan=True, width=32),
                      st.booleans())
    keys = st.sampled_from(["search", "sampling", "population", "evaluations", "samples",
                            "seed", "chunk"])
    return st.dictionaries(keys, value, max_size=5)


@pytest.mark.slow
def test_random_search_tables_are_read_or_refused_by_name():
    """Any [design] table of search keys either gives a space (and, for nsga2, settings whose
    first population is the space's sample) or is refused with a ConfigError naming the key."""
    from hypothesis import HealthCheck, given, settings

    from dextar.config.design import DesignTable
    from dextar.errors import ConfigError
    from dextar.geometry import FiveBar

    robot = FiveBar(72.0, 72.0, 87.0, 87.0, 60.0)

    @settings(max_examples=40, deadline=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(table=_search_tables())
    def check(table):
        try:
            t = DesignTable.from_toml({"l": [50.0, 120.0], **table})
            space, found = t.space(robot), t.search()
        except ConfigError as exc:
            assert re.search(r"design|samples|seed|evaluations", str(exc)), exc
            return
        kind = table.get("search") or table.get("sampling") or "sobol"
        assert (found is not None) == (kind == "nsga2")
        if found is not None:
            assert space.samples == found.population <= found.evaluations
            assert found.batch == t.chunk and found.in_flight >= 1
            assert "samples" not in table
        else:
            assert space.sampling == kind and "population" not in table

    check()
