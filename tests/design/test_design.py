"""dextar design: a sweep on local Dask workers whose rows are the single-design function's,
the Pareto set by brute force, the same file for 1 and 2 workers and after a kill and a
resume, and bad input refused by name."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from dextar.cli import main
from dextar.config import load_scenario
from dextar.design.evaluate import Task, evaluate_design
from dextar.design.pareto import closest_to_ideal, pareto_mask
from dextar.design.space import METRICS, MOTOR_METRICS
from dextar.output.design import parse_line

pytest.importorskip("distributed")

TASK = """
[robot]
preset = "dextar"
working_mode = "+-"
[inertia]
effector_mass = 0.08
payload = 0.05
[friction]
coulomb = 0.02
viscous = 0.01
[gravity]
vector = [0.0, -9810.0]
[motors]
peak_torque = 3.4
max_speed_rpm = 30
[program]
start = [-40.0, 110.0]
[[move]]
type = "line"
to = [40.0, 110.0]
[[move]]
type = "dwell"
time = 0.1
[design]
l = [50.0, 120.0]
L = [60.0, 140.0]
d = [0.0, 100.0]
mass_per_length = [0.4, 0.3]
samples = 32
chunk = 4
grid = 30
"""


def write_task(folder: Path, extra: str = "", design: str | None = None) -> Path:
    text = TASK if design is None else TASK.split("[design]")[0] + design
    path = folder / "task.toml"
    path.write_text(text + extra)
    return path


def rows_of(out: Path) -> list[dict]:
    lines = (out / "designs.csv").read_text().splitlines(keepends=True)[1:]
    return [parse_line(x) for x in lines]


@pytest.fixture(scope="session")
def sweep2(tmp_path_factory, scheduler):
    """The task swept on the session's two workers."""
    folder = tmp_path_factory.mktemp("sweep")
    task = write_task(folder)
    out = folder / "two"
    assert main(["design", str(task), "--out", str(out), "--scheduler", scheduler,
                 "--quiet"]) == 0
    return task, out


@pytest.mark.slow
def test_rows_are_the_single_design_function(sweep2):
    task_path, out = sweep2
    rows = rows_of(out)
    assert [r["design"] for r in rows] == list(range(32))
    sc = load_scenario(task_path)
    task = Task(tuple(sc.moves), sc.program_start, sc.mode, sc.assembly, sc.si_motors,
                sc.motors_table.rms_torque, sc.si_model.inertia, (0.4, 0.3), 30,
                sc.tolerances)
    for i in (0, 7, 21, 31):
        direct = evaluate_design(task, [rows[i][k] for k in ("l1", "l2", "L1", "L2", "d")])
        for k, v in direct.items():
            if isinstance(v, float):
                assert rows[i][k] == pytest.approx(v, rel=1e-12), (i, k)
            else:
                assert rows[i][k] == v, (i, k)
    # the sweep meets every kind of design: feasible ones and refused ones with a reason
    assert any(r["feasible"] for r in rows) and any(not r["feasible"] for r in rows)
    assert all(r["reason"] for r in rows if not r["feasible"])


@pytest.mark.slow
def test_pareto_set_by_brute_force(sweep2):
    _, out = sweep2
    rows = [r for r in rows_of(out) if r["feasible"]]
    F = np.array([[r["cycle_time_s"], r["footprint_mm"], -r["min_type2_distance"]]
                  for r in rows])
    brute = {rows[i]["design"] for i in range(len(rows))
             if not any(all(F[j] <= F[i]) and any(F[j] < F[i]) for j in range(len(rows)))}
    written = {r["design"] for r in
               (parse_line(x) for x in (out / "pareto.csv").read_text().splitlines(True)[1:])}
    assert written == brute and brute
    s = json.loads((out / "summary.json").read_text())
    assert s["pareto"] == len(brute) and s["designs"] == 32
    assert s["feasible"] == len(rows) and s["best"]["design"] in brute
    # best.toml is a config every command takes: the chosen robot's lengths
    sc = load_scenario(out / "best.toml")
    assert sc.robot_mm.l1 == pytest.approx(s["best"]["l1"], rel=1e-12)


def test_pareto_helpers_on_a_known_front():
    F = np.array([[1, 5], [2, 2], [5, 1], [3, 3], [2, 2], [6, 6]], float)
    assert pareto_mask(F).tolist() == [True, True, True, False, True, False]
    assert closest_to_ideal(F[[0, 1, 2]]) == 1


def test_one_design_is_a_row_without_a_cluster(tmp_path):
    """What each worker runs, on its own: the DexTAR plans the task within its motors (its
    metrics finite); rods too short for the start are a row with the reason and no metric."""
    task, _ = load_scenario(write_task(tmp_path)).design_task()
    row = evaluate_design(task, (72.0, 72.0, 87.0, 87.0, 60.0))
    assert row["feasible"] and row["reason"] == "" and row["footprint_mm"] == 72 + 87 + 30
    assert all(np.isfinite(row[k]) for k in METRICS if k not in MOTOR_METRICS)
    assert row["cycle_time_s"] > 0 and row["shaking_force_N"] > 0  # no counterweights
    assert all(row[k] is None for k in MOTOR_METRICS)  # no catalogue: no motor chosen
    assert max(row["peak_torque_A_Nm"], row["peak_torque_D_Nm"]) <= 3.4  # [motors]
    short = evaluate_design(task, (20.0, 20.0, 30.0, 30.0, 60.0))  # reach 50 mm: start at 130
    assert not short["feasible"] and "out of reach of leg 1" in short["reason"]
    assert short["cycle_time_s"] is None and short["footprint_mm"] == 80.0


@pytest.mark.slow
def test_one_worker_gives_the_same_file(sweep2, tmp_path):
    task, out2 = sweep2
    out1 = tmp_path / "one"
    # --no-figures: the same data files (the figures are drawn after the sweep, from them)
    assert main(["design", str(task), "--out", str(out1), "--workers", "1", "--quiet",
                 "--no-figures"]) == 0
    assert (out1 / "designs.csv").read_bytes() == (out2 / "designs.csv").read_bytes()
    assert (out1 / "pareto.csv").read_bytes() == (out2 / "pareto.csv").read_bytes()
    assert (out1 / "best.toml").read_bytes() == (out2 / "best.toml").read_bytes()
    assert not list(out1.glob("*.png")) and not (out1 / "report.html").exists()
    assert list(out2.glob("*.png")) and (out2 / "report.html").exists()


@pytest.mark.slow
def test_a_killed_sweep_resumes_to_the_same_file(sweep2, tmp_path, scheduler):
    """A sweep killed half-way (SIGKILL; then a row cut short, as a kill during a write
    leaves it) resumes to the bytes of a whole sweep. The killed run takes one design per
    unit of work (the whole sweep four): with four its eight units ran two at a time and
    their rows came in bursts, and in one run of four the file went from 9 rows to all 32
    between two looks (the kill then found the sweep done); the finished file holds the rows
    in design order whatever the units (the grouping of a resumed sweep's designs into
    units: test_the_designs_left_go_in_runs_of_consecutive_numbers)."""
    _, out2 = sweep2
    task = write_task(tmp_path, design="[design]" + TASK.split("[design]")[1].replace(
        "chunk = 4", "chunk = 1"))
    assert "chunk = 1" in task.read_text()
    out = tmp_path / "killed"
    proc = subprocess.Popen([sys.executable, "-m", "dextar", "design", str(task), "--out",
                             str(out), "--scheduler", scheduler, "--quiet"],
                            start_new_session=True)
    csv_path = out / "designs.csv"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        if csv_path.exists() and len(csv_path.read_text().splitlines()) > 4:
            break
        if proc.poll() is not None:
            break
        time.sleep(0.01)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    partial = csv_path.read_text()
    done = len(partial.splitlines()) - 1
    assert 0 < done < 32, done  # killed half-way
    # a line cut short by the kill is dropped on resume
    csv_path.write_text(partial + "32,1.0,2.")
    assert main(["design", str(task), "--out", str(out), "--resume", "--scheduler", scheduler,
                 "--quiet", "--no-figures"]) == 0
    assert csv_path.read_bytes() == (out2 / "designs.csv").read_bytes()
    s = json.loads((out / "summary.json").read_text())
    assert s["resumed"] == done and s["evaluated"] == 32 - done


def test_the_designs_left_go_in_runs_of_consecutive_numbers():
    """sweep.chunks_of: a resumed sweep's designs left (sorted) in units of at most
    ``size`` consecutive design numbers; a gap starts a new unit."""
    from dextar.design.sweep import chunks_of

    assert chunks_of([0, 1, 2, 5, 6, 7, 8, 9, 11], 4) == [[0, 1, 2], [5, 6, 7, 8], [9], [11]]
    assert chunks_of(list(range(8)), 4) == [[0, 1, 2, 3], [4, 5, 6, 7]]
    assert chunks_of([], 4) == []


@pytest.mark.parametrize("design, message", [
    ('l = [120.0, 50.0]\nsamples = 4\n', r"\[design\].l = \[120, 50\] is inverted"),
    ('l = [70.0, 70.0]\nsamples = 4\n', r"\[design\].l = \[70, 70\] is empty"),
    ('l = [50.0, 120.0]\nobjectives = ["speed"]\n', "unknown objective 'speed'"),
    ('samples = 4\n', r"\[design\] varies nothing"),
    ('l = [50.0, 120.0]\nl1 = [50.0, 60.0]\n', r"\[design\].l and \[design\].l1 both"),
])
def test_bad_design_tables_exit_2(tmp_path, capsys, design, message):
    task = write_task(tmp_path, design=f"[design]\n{design}")
    assert main(["design", str(task), "--out", str(tmp_path / "o"), "--workers", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and __import__("re").search(message, err), err
    assert not (tmp_path / "o").exists()


@pytest.mark.slow
def test_geometries_that_cannot_assemble_are_rows(tmp_path, scheduler):
    """Rods too short for the base: every design is a row with its reason, no crash."""
    task = write_task(tmp_path, design='[design]\nl = [5.0, 10.0]\nL = [5.0, 10.0]\n'
                                       'd = [60.0, 100.0]\nsamples = 8\ngrid = 30\n')
    assert main(["design", str(task), "--out", str(tmp_path / "o"), "--scheduler", scheduler,
                 "--quiet", "--no-figures"]) == 0  # (the rows and summary are checked)
    rows = rows_of(tmp_path / "o")
    assert len(rows) == 8 and not any(r["feasible"] for r in rows)
    assert all(r["reason"] for r in rows)
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["feasible"] == 0 and s["best"] is None


@pytest.mark.slow
def test_unreachable_scheduler_is_named_within_10_s(tmp_path, capsys, monkeypatch):
    from dextar.design import sweep

    monkeypatch.setattr(sweep, "CONNECT_TIMEOUT_S", 2)  # the default 8 s, shortened
    task = write_task(tmp_path)
    t0 = time.monotonic()
    assert main(["design", str(task), "--out", str(tmp_path / "o"), "--scheduler",
                 "tcp://127.0.0.1:9"]) == 2
    assert time.monotonic() - t0 < 10
    err = capsys.readouterr().err
    assert "--scheduler 'tcp://127.0.0.1:9': no Dask scheduler answers" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_without_dask_the_extra_is_named(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    task = write_task(tmp_path)
    assert main(["design", str(task), "--out", str(tmp_path / "o")]) == 2
    assert "pip install -e '.[design]'" in capsys.readouterr().err


@pytest.mark.slow
def test_resume_refuses_another_sweep(sweep2, tmp_path, capsys):
    task, out2 = sweep2
    import shutil

    out = tmp_path / "copy"
    shutil.copytree(out2, out)
    assert main(["design", str(task), "--out", str(out), "--resume", "--seed", "5"]) == 2
    assert "was made with another task" in capsys.readouterr().err
    assert main(["design", str(task), "--out", str(out)]) == 2
    assert "--resume" in capsys.readouterr().err


@pytest.mark.slow
def test_a_run_task_sweeps_its_path_and_law(tmp_path, scheduler):
    """A dextar run config (one path, one law) is a task too: geometry and torque metrics
    along its path; its rows are the single-design function's."""
    from dextar.config import load_toml

    from ..program.test_program import EXAMPLES
    from ..robustness.harness import toml_text

    doc = load_toml(EXAMPLES / "line_si.toml")
    doc["motors"] = {"peak_torque": 1.0}
    doc["design"] = {"l": [50.0, 120.0], "L": [60.0, 140.0], "d": [10.0, 100.0],
                     "samples": 32, "chunk": 16, "objectives": ["peak_torque_A_Nm", "-gci"]}
    path = tmp_path / "run.toml"
    path.write_text(toml_text(doc))
    out = tmp_path / "o"
    # --no-figures: what is checked is in designs.csv and summary.json (the figures, drawn
    # from those files after the sweep, are checked on sweep2's)
    assert main(["design", str(path), "--out", str(out), "--scheduler", scheduler,
                 "--quiet", "--no-figures"]) == 0
    rows = rows_of(out)
    task, space = load_scenario(path).design_task()
    assert task.kind == "run"
    for i in (0, 9, 31):
        direct = evaluate_design(task, space.designs()[i])
        assert rows[i]["feasible"] == direct["feasible"] and rows[i]["reason"] == direct["reason"]
        if direct["feasible"]:
            assert rows[i]["cycle_time_s"] == 0.25  # the law's duration
            assert rows[i]["peak_torque_A_Nm"] == pytest.approx(direct["peak_torque_A_Nm"],
                                                                rel=1e-12)
    assert json.loads((out / "summary.json").read_text())["task_kind"] == "run"


def test_bad_samples_and_seed_exit_2(tmp_path, capsys):
    task = write_task(tmp_path)
    for args, message in ((["--samples", "0"], "samples = 0"), (["--seed", "-1"], "seed = -1"),
                          (["--workers", "0"], "--workers 0 must be at least 1")):
        assert main(["design", str(task), "--out", str(tmp_path / "o"), *args]) == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1, err
        assert not (tmp_path / "o").exists()


def _design_tables():
    from hypothesis import strategies as st

    value = st.one_of(
        st.lists(st.floats(allow_nan=True, allow_infinity=True, width=32), min_size=0,
                 max_size=3),
        st.tuples(st.floats(0, 200), st.floats(0, 200)).map(list),
        st.text(alphabet="abcLl-_ 1", max_size=4), st.integers(-3, 10**7), st.booleans())
    keys = st.sampled_from(["l", "L", "l1", "l2", "L1", "L2", "d", "mass_per_length",
                            "samples", "sampling", "seed", "objectives", "chunk", "grid",
                            "bogus"])
    return st.dictionaries(keys, value, max_size=6)


def test_random_design_tables_are_read_or_refused_by_name(tmp_path_factory):
    """Any [design] table either gives a design space whose first designs evaluate to rows
    (finite numbers or empty cells) or is refused with a ConfigError naming [design]."""
    from hypothesis import HealthCheck, given, settings

    from dextar.design.evaluate import evaluate_chunk
    from dextar.errors import ConfigError
    from dextar.output.design import row_line

    from ..robustness.harness import toml_text

    base = {k: v for k, v in __import__("tomllib").loads(TASK).items() if k != "design"}

    @settings(max_examples=60, deadline=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(table=_design_tables())
    def check(table):
        folder = tmp_path_factory.mktemp("d")
        path = folder / "t.toml"
        path.write_text(toml_text({**base, "design": table}))
        try:
            task, space = load_scenario(path).design_task()
        except ConfigError as exc:
            assert "design" in str(exc) or "samples" in str(exc) or "seed" in str(exc), exc
            return
        designs = space.designs()
        assert designs.shape == (space.samples, 5) and np.isfinite(designs).all()
        for row in evaluate_chunk(task, designs[:2], 0):
            line = row_line(row)
            assert "nan" not in line and "inf" not in line
            assert parse_line(line) == row  # the CSV line gives the row back exactly
            assert not row["reason"].startswith("internal error"), row["reason"]

    check()


@pytest.mark.slow
def test_a_running_cluster_by_address_gives_the_same_file(sweep2, tmp_path):
    """`dask scheduler` and `dask worker` started as the README shows; --scheduler uses them."""
    import shutil
    import socket

    dask_cli = Path(sys.executable).with_name("dask")
    if not dask_cli.exists():
        dask_cli = Path(shutil.which("dask") or "dask")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    procs = [subprocess.Popen([str(dask_cli), "scheduler", "--host", "127.0.0.1", "--port",
                               str(port), "--no-dashboard"], start_new_session=True,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:  # the worker retries until the scheduler listens; the client waits for it
        procs.append(subprocess.Popen([str(dask_cli), "worker", address, "--nthreads", "1",
                                       "--no-dashboard"], start_new_session=True,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from distributed import Client

        with Client(address, timeout="20s") as c:
            c.wait_for_workers(1, timeout=30)
        task, out2 = sweep2
        out = tmp_path / "remote"
        assert main(["design", str(task), "--out", str(out), "--scheduler", address,
                     "--quiet", "--no-figures"]) == 0
        assert (out / "designs.csv").read_bytes() == (out2 / "designs.csv").read_bytes()
    finally:
        for p in procs:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()


@pytest.mark.slow
def test_a_worker_that_dies_is_replaced_and_the_rows_are_complete(sweep2):
    """One of two workers is killed after the first chunk: Dask reruns its chunks elsewhere
    and the sweep ends with every row, equal to the uninterrupted sweep's."""
    from dextar.design.sweep import Cluster, run_sweep

    task_path, out2 = sweep2
    task, space = load_scenario(task_path).design_task()
    designs = space.designs()
    got: dict[int, dict] = {}
    killed = []

    with Cluster(workers=2) as cl:
        def on_chunk(rows):
            got.update({r["design"]: r for r in rows})
            if not killed:
                victim = sorted(cl.client.scheduler_info()["workers"])[0]
                pid = cl.client.run(os.getpid, workers=[victim])[victim]
                os.kill(pid, signal.SIGKILL)  # the worker process dies mid-sweep
                killed.append(pid)

        run_sweep(cl, task, designs, range(len(designs)), chunk=4, on_chunk=on_chunk)
    assert killed and sorted(got) == list(range(32))
    expected = rows_of(out2)
    for i in range(32):
        assert got[i] == expected[i]


@pytest.mark.slow
def test_sweeps_one_after_another_on_one_cluster(tmp_path, scheduler):
    """Two sweeps in a row on the same two workers (as a script or the benchmark does): the
    second one's task is not lost while the first one's copy is being released."""
    from dextar.design.sweep import Cluster, run_sweep

    task, space = load_scenario(write_task(tmp_path)).design_task()
    designs = space.designs()[:8]
    results = []
    with Cluster(scheduler=scheduler) as cluster:
        for _ in range(3):
            rows: list[dict] = []
            stats = run_sweep(cluster, task, designs, range(len(designs)), chunk=1,
                              on_chunk=rows.extend)
            assert stats.evaluated == len(designs)
            results.append(sorted(rows, key=lambda r: r["design"]))
    assert results[0] == results[1] == results[2]
