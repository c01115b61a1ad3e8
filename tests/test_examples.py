"""The shipped examples run: the Python scripts check themselves, every TOML config plans
what it says (a run config its path and law, a program its own moves)."""

import runpy
import tomllib
from pathlib import Path

import pytest

from dextar.config import load_scenario
from dextar.geometry import parse_working_mode
from dextar.kinematics import working_mode
from dextar.program import sizing

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CONFIGS = {p.name: tomllib.loads(p.read_text()) for p in sorted(EXAMPLES.glob("*.toml"))}


def test_quickstart_script_runs(capsys):
    runpy.run_path(str(EXAMPLES / "quickstart.py"), run_name="__main__")
    assert "checks passed" in capsys.readouterr().out


def test_jerk_limited_script_runs_and_checks_itself(capsys):
    """The script's own asserts are the checks (jerk within 1 %, torques within 0.1 %, at
    rest at both ends, power against the kinetic energy's rate); they run here."""
    runpy.run_path(str(EXAMPLES / "jerk_limited.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "checks passed" in out and "peak jerk / limit" in out


@pytest.mark.parametrize("name", [n for n, doc in CONFIGS.items() if "move" not in doc])
def test_example_configs_plan(name):
    sc = load_scenario(str(EXAMPLES / name))
    tr = sc.trajectory(samples=101)
    assert tr.t.size == 101


# (a design task's motors come from its catalogue: tests/design/test_motors.py sweeps it)
@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n, doc in CONFIGS.items()
                                  if "move" in doc and "design" not in doc])
def test_example_programs_plan_their_moves(name):
    """The program as `dextar program` plans it: every [[move]] of the file in order, from
    [program].start to the last move's target point, in the working mode the moves leave it
    in, within the file's motors."""
    doc = CONFIGS[name]
    req = load_scenario(EXAMPLES / name).program_request()
    res = req.plan()
    # (a working mode the planner chose may add a change of mode before a path move)
    assert ([m.type for m in res.timeline() if not m.mode_change]
            == [m["type"] for m in doc["move"]])
    assert res.P[0] * 1e3 == pytest.approx(doc["program"]["start"], abs=1e-9)
    targets = [m["to"] for m in doc["move"] if "to" in m]
    assert res.P[-1] * 1e3 == pytest.approx(targets[-1], abs=1e-6)
    modes = [req.working_mode] + [m["working_mode"] for m in doc["move"] if "working_mode" in m]
    if res.mode_choice is not None:  # working_mode = "auto": the modes the planner chose
        modes = [res.mode_choice.start_mode, *res.mode_choice.modes]
    assert tuple(working_mode(req.robot, res.q[-1], res.P[-1])) == parse_working_mode(modes[-1])
    assert sizing(res).fits


def test_paper_toml_is_the_default():
    a = load_scenario(str(EXAMPLES / "paper.toml"))
    b = load_scenario(None)
    assert a.robot == b.robot and a.path == b.path and a.inertia == b.inertia
    assert a.law_table == b.law_table and a.units == b.units and a.paper == b.paper


@pytest.mark.slow
def test_identification_script_runs(capsys):
    runpy.run_path(str(EXAMPLES / "identify_synthetic.py"), run_name="__main__")
    assert "identification checks passed" in capsys.readouterr().out


def test_balancing_script_runs(capsys):
    runpy.run_path(str(EXAMPLES / "balancing.py"), run_name="__main__")
    assert "balancing checks passed" in capsys.readouterr().out
