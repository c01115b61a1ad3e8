"""An installed package extends the ``dextar`` command through entry points: a toy
distribution (a ``*.dist-info`` with ``entry_points.txt`` on a temporary path) registers a
move type, a path type, a law and a command, and the installed command uses all four."""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from dextar.registry import PluginError, Registry, UnknownNameError

TOY = '''
"""A toy dextar plugin: one item of every kind."""
import numpy as np

from dextar.commands import Command, register_command
from dextar.laws import LawType, Param, UniformLaw, register_law
from dextar.params import REQUIRED
from dextar.paths import Line, PathType, register_path
from dextar.program import MovePlan, MoveType, register_move
from dextar.program.plan import along_path


def nudge_path(mv, start):
    return Line(tuple(start), tuple(np.asarray(start) + np.asarray(mv.get("by"))))


def plan_nudge(ctx, mv, state):
    path = nudge_path(mv, state.P)
    law, sample, q1, poses = along_path(ctx, mv, path, state, ctx.grid, samples=201)
    end = type(state)(path.position(path.p1), q1, state.mode)
    return MovePlan(law, law.duration, sample, end, float(poses.distances.type1.min()),
                    float(poses.distances.type2.min()))


def moves():
    register_move(MoveType("nudge", {"by": Param("point", "mm", REQUIRED, "offset [dx, dy]")},
                           plan_nudge, path=nudge_path, help="a line by an offset"))


def paths():
    register_path(PathType("stroke", {"length": Param("number", "mm", 50.0, "length",
                                                      positive=True)},
                           lambda v, u: Line((0.0, u.length(100.0)),
                                             (v["length"], u.length(100.0))),
                           "a horizontal stroke at y = 100 mm"))


def laws():
    register_law(LawType("steady", {"duration": Param("number", "s", 1.0, "motion time",
                                                      positive=True)},
                         lambda req: UniformLaw(req.path.length, req.params["duration"]),
                         "constant speed"))


def commands():
    register_command(Command("hello", "dextar_toy_hello", "say hello (a toy plugin's command)"))
'''

HELLO = '''
"""dextar hello: the toy plugin's command."""
from dextar.commands.base import Result, json_flag


def add_arguments(sp):
    sp.add_argument("who")
    json_flag(sp)


def run(args):
    return Result({"hello": args.who}, f"hello, {args.who}")
'''

ENTRY_POINTS = """
[dextar.moves]
nudge = dextar_toy:moves

[dextar.paths]
stroke = dextar_toy:paths

[dextar.laws]
steady = dextar_toy:laws

[dextar.commands]
hello = dextar_toy:commands
"""

PROGRAM = """
[motors]
peak_torque = 2.0
[program]
start = [-30.0, 100.0]
[[move]]
type = "nudge"
by = [20.0, 10.0]
law = "steady"
duration = 0.5
[[move]]
type = "line"
to = [30.0, 100.0]
"""

RUN = """
[path]
type = "stroke"
length = 40.0
[law]
type = "steady"
duration = 0.5
[output]
units = "si"
samples = 11
"""


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """A folder holding the toy distribution, as an installer would leave it."""
    root = tmp_path_factory.mktemp("site")
    (root / "dextar_toy.py").write_text(TOY)
    (root / "dextar_toy_hello.py").write_text(HELLO)
    info = root / "dextar_toy-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: dextar-toy\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(textwrap.dedent(ENTRY_POINTS))
    return root


def dextar(site, *argv, cwd):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(site), *filter(None, [os.environ.get("PYTHONPATH")])])}
    return subprocess.run([sys.executable, "-m", "dextar", *argv], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_a_plugin_command_runs_and_is_listed(site, tmp_path):
    r = dextar(site, "hello", "world", "--json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout) == {"hello": "world"}
    r = dextar(site, "--help", cwd=tmp_path)
    assert "say hello (a toy plugin's command)" in r.stdout
    # without the plugin on the path the command is unknown
    r = subprocess.run([sys.executable, "-m", "dextar", "hello", "world"], cwd=tmp_path,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "invalid choice: 'hello'" in r.stderr


@pytest.mark.slow
def test_a_plugin_move_type_and_law_plan_a_program(site, tmp_path):
    (tmp_path / "task.toml").write_text(PROGRAM)
    r = dextar(site, "program", "task.toml", "--out", "o", "--no-figures", "--json",
               cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert [m["type"] for m in s["moves"]] == ["nudge", "line"]
    # the plugin's law is a constant speed (its law object is the uniform law)
    assert s["moves"][0]["law"] == "uniform" and s["moves"][0]["duration_s"] == 0.5
    data = np.genfromtxt(tmp_path / "o" / "setpoints.csv", delimiter=",", names=True)
    # the nudge ends 20 mm right and 10 mm up of the start, at constant speed on its way
    first = data["move"] == 0
    assert data["x_mm"][first][-1] == pytest.approx(-10.0, abs=0.05)
    assert data["y_mm"][first][-1] == pytest.approx(110.0, abs=0.05)
    assert np.ptp(np.diff(data["x_mm"][first])) < 1e-9  # constant speed
    assert data["x_mm"][-1] == pytest.approx(30.0, abs=1e-9)


@pytest.mark.slow
def test_a_plugin_path_type_and_law_plan_a_run(site, tmp_path):
    (tmp_path / "run.toml").write_text(RUN)
    r = dextar(site, "plan", "run.toml", "--out", "plan.csv", "--json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["law"] == "uniform"
    data = np.genfromtxt(tmp_path / "plan.csv", delimiter=",", names=True)
    assert np.allclose(data["x_m"], np.linspace(0.0, 0.04, 11), atol=1e-12)
    assert np.allclose(data["y_m"], 0.1, atol=1e-12)
    # the help lists the plugin's items beside the built-in ones
    r = dextar(site, "plan", "--help", cwd=tmp_path)
    assert "stroke" in r.stdout and "steady" in r.stdout and "nudge" in r.stdout


@pytest.mark.slow
def test_a_broken_plugin_is_named(tmp_path):
    (tmp_path / "dextar_broken.py").write_text("raise ImportError('no such thing')\n")
    info = tmp_path / "dextar_broken-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: dextar-broken\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[dextar.laws]\nbroken = dextar_broken:register\n")
    (tmp_path / "run.toml").write_text(RUN.replace("stroke", "line").replace(
        "length = 40.0", "start = [0.0, 100.0]\nend = [40.0, 100.0]"))
    r = dextar(tmp_path, "plan", "run.toml", "--out", "plan.csv", cwd=tmp_path)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr
    assert "plugin 'broken' of dextar.laws (dextar_broken:register) failed to load" in r.stderr


def test_one_unknown_name_error_lists_the_known_names():
    reg: Registry[str] = Registry("colour", "config key [paint].colour")
    reg.register("red", "red")
    reg.register("blue", "blue")
    with pytest.raises(UnknownNameError, match=r"\[paint\]\.colour must be one of red, blue, "
                                               r"got 'green'") as exc:
        reg.lookup("green")
    assert exc.value.known == ("red", "blue") and exc.value.name == "green"
    assert reg.lookup("blue") == "blue"
    with pytest.raises(UnknownNameError, match="somewhere else must be one of"):
        reg.lookup(3, "somewhere else")
    assert issubclass(PluginError, Exception)
