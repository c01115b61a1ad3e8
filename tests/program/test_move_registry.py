"""A move type registered from outside the package plans from a config like the built-in
ones: its keys read and checked by name, its law any registered law, blended with a line."""

import json

import numpy as np
import pytest

from dextar.cli import main
from dextar.params import REQUIRED, Param
from dextar.paths import Line
from dextar.program import MOVE_TYPES, MovePlan, MoveType, register_move
from dextar.program.plan import along_path

TASK = """
[motors]
peak_torque = 2.0
max_speed_rpm = 60
[program]
start = [-30.0, 100.0]
[[move]]
type = "nudge"
by = [20.0, 10.0]
blend = 3.0
[[move]]
type = "line"
to = [30.0, 100.0]
[[move]]
type = "nudge"
by = [0.0, 15.0]
law = "min-jerk"
duration = 0.4
"""


def nudge_path(mv, start):
    """A line by ``by`` (m) from the start."""
    return Line(tuple(start), tuple(np.asarray(start) + np.asarray(mv.get("by"))))


def plan_nudge(ctx, mv, state):
    path = nudge_path(mv, state.P)
    law, sample, q1, poses = along_path(ctx, mv, path, state, ctx.grid, samples=201)
    end = type(state)(path.position(path.p1), q1, state.mode)
    return MovePlan(law, law.duration, sample, end, float(poses.distances.type1.min()),
                    float(poses.distances.type2.min()))


@pytest.fixture
def nudge():
    register_move(MoveType("nudge", {"by": Param("point", "mm", REQUIRED, "offset [dx, dy]")},
                           plan_nudge, path=nudge_path, help="a line by an offset"))
    yield
    MOVE_TYPES.pop("nudge")


def test_a_registered_move_type_plans_a_program(nudge, tmp_path, capsys):
    cfg = tmp_path / "task.toml"
    cfg.write_text(TASK)
    assert main(["program", "--no-figures", str(cfg), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert [m["type"] for m in s["moves"]] == ["nudge", "line", "nudge"]
    assert s["moves"][0]["blended_with_next"] and s["moves"][0]["law"] == "time-optimal"
    assert s["moves"][2]["law"] == "min-jerk" and s["moves"][2]["duration_s"] == 0.4
    data = np.genfromtxt(tmp_path / "o" / "setpoints.csv", delimiter=",", names=True)
    # the last nudge ends 15 mm above the line's end, at rest
    assert data["x_mm"][-1] == pytest.approx(30.0, abs=1e-9)
    assert data["y_mm"][-1] == pytest.approx(115.0, abs=1e-9)
    assert abs(data["dphi_rad_s"][-1]) < 1e-9
    # its keys are checked by name like the built-in types'
    cfg.write_text(TASK.replace("by = [0.0, 15.0]", "by = 15.0"))
    assert main(["program", str(cfg), "--out", str(tmp_path / "o2")]) == 2
    assert "[[move]] 2 (nudge).by must be a point" in capsys.readouterr().err
    cfg.write_text(TASK.replace("by = [0.0, 15.0]", "to = [0.0, 15.0]"))
    assert main(["program", str(cfg), "--out", str(tmp_path / "o3")]) == 2
    err = capsys.readouterr().err
    assert "[[move]] 2 (nudge).to is not known" in err


def test_an_unregistered_move_type_is_named(tmp_path, capsys):
    cfg = tmp_path / "task.toml"
    cfg.write_text(TASK)
    assert main(["program", str(cfg), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "[[move]] 0 (nudge).type must be one of line, arc, dwell, joint" in err
