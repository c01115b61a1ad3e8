"""The shipped examples run: the Python script checks itself, every TOML config loads."""

import runpy
from pathlib import Path

import pytest

from dextar.config import load_scenario

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_quickstart_script_runs(capsys):
    runpy.run_path(str(EXAMPLES / "quickstart.py"), run_name="__main__")
    assert "checks passed" in capsys.readouterr().out


@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLES.glob("*.toml")))
def test_example_configs_plan(name):
    sc = load_scenario(str(EXAMPLES / name))
    tr = sc.trajectory(samples=101)
    assert tr.t.size == 101


def test_paper_toml_is_the_default():
    a = load_scenario(str(EXAMPLES / "paper.toml"))
    b = load_scenario(None)
    assert a.robot == b.robot and a.path == b.path and a.inertia == b.inertia
    assert a.law_table == b.law_table and a.units == b.units and a.paper == b.paper


def test_identification_script_runs(capsys):
    runpy.run_path(str(EXAMPLES / "identify_synthetic.py"), run_name="__main__")
    assert "identification checks passed" in capsys.readouterr().out


def test_balancing_script_runs(capsys):
    runpy.run_path(str(EXAMPLES / "balancing.py"), run_name="__main__")
    assert "balancing checks passed" in capsys.readouterr().out
