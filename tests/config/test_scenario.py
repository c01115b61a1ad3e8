"""The config layer on its own: typed tables, one reading of the file, the program request
and the design task in SI, errors named by their key."""

import math

import pytest

from dextar.config import load_robot_table, load_scenario, scenario_from_dict
from dextar.config.kinematic import RobotTable
from dextar.config.tables import MotorsTable
from dextar.errors import ConfigError
from dextar.program import ProgramRequest

from ..program.test_program import EXAMPLES


def test_typed_tables_of_the_example():
    sc = load_scenario(EXAMPLES / "pick_place.toml")
    assert isinstance(sc.motors_table, MotorsTable) and sc.motors_table.peak_torque == (3.4, 3.4)
    assert sc.inertia_table.effector_mass == 0.08 and sc.friction_table.coulomb == (0.02, 0.02)
    assert sc.gravity_table.vector == (0.0, -9810.0)
    assert sc.program_table.start == (-40.0, 110.0)
    assert sc.text == (EXAMPLES / "pick_place.toml").read_bytes()  # read once, kept
    assert sc.raw("motors") == {"motors": {"peak_torque": 3.4, "max_speed_rpm": 30,
                                           "knee_speed_rpm": 1}}


def test_program_request_is_in_si(tmp_path):
    sc = load_scenario(EXAMPLES / "pick_place.toml")
    req = sc.program_request()
    assert isinstance(req, ProgramRequest)
    assert req.start == pytest.approx((-0.04, 0.11), abs=1e-15)
    assert req.robot.l1 == pytest.approx(0.072) and req.servo_rate_hz == 1000.0
    assert req.moves[0].type == "line" and req.moves[0].get("to") == pytest.approx((-0.04, 0.09))
    assert req.moves[2].blend == pytest.approx(0.005)
    assert req.motors is not None
    assert req.motors.max_speed[0] == pytest.approx(30 * 2 * math.pi / 60)
    # a joint move's target: a point (`to`, mm) goes to m; readings (`to_deg`) go to rad
    # under a name without the unit (`to_q`). mode_change.toml's joint move says `to`; the
    # same file with that move given as the readings of its point says `to_deg`.
    text = (EXAMPLES / "mode_change.toml").read_text()
    point = 'to = [-20.0, 120.0]\nworking_mode = "++"'
    assert text.count(point) == 1
    readings = tmp_path / "mode_change_deg.toml"
    readings.write_text(text.replace(point, 'to_deg = [73.4588, 39.5574]\nworking_mode = "++"'))
    [joint] = [m for m in load_scenario(EXAMPLES / "mode_change.toml").program_request().moves
               if m.type == "joint"]
    assert joint.get("to") == pytest.approx((-0.02, 0.12), abs=1e-15)
    assert "to_q" not in joint.values and "to_deg" not in joint.values
    [joint] = [m for m in load_scenario(readings).program_request().moves if m.type == "joint"]
    assert joint.get("to_q") == pytest.approx((math.radians(73.4588), math.radians(39.5574)),
                                              abs=1e-15)
    assert "to_deg" not in joint.values and "to" not in joint.values


def test_program_start_is_required_by_key():
    sc = scenario_from_dict({"move": [{"type": "dwell", "time": 0.1}]})
    with pytest.raises(ConfigError, match=r"config key \[program\].start is required"):
        sc.program_request()
    with pytest.raises(ConfigError, match="the task has no move"):
        scenario_from_dict({"program": {"start": [0.0, 100.0]}}).program_request()


@pytest.mark.parametrize("move, words", [
    ({"type": "line"}, r"\[\[move\]\] 0 \(line\).to is required"),
    ({"type": "line", "to": [0, 100], "via": [1, 2]}, r"\(line\).via is not known"),
    ({"type": "dwell", "time": 0.1, "law": "min-jerk"}, r"\(dwell\).law is not known"),
    ({"type": "arc", "to": [0, 100]}, "an arc needs exactly one of 'via' and 'center'"),
    ({"type": "joint"}, "a joint move needs exactly one of 'to' and 'to_deg'"),
    ({"type": "joint", "to_deg": [1, 2], "working_mode": "x"}, r"\(joint\): working_mode"),
    ({"type": "line", "to": [0, 100], "duration": 1.0}, "the time-optimal law has no "
     "duration"),
    ({"type": "line", "to": [0, 100], "law": "warp"}, r"\(line\).law must be one of"),
])
def test_bad_moves_are_named_by_key(move, words):
    with pytest.raises(ConfigError, match=words):
        scenario_from_dict({"move": [move]})


def test_a_run_task_starts_at_its_path_start():
    """A design sweep of a run whose arc does not start at 0 deg: the task's start is the
    path's first point, not p = 0."""
    doc = {"path": {"type": "arc", "radius": 100.0, "start_deg": -160.0, "end_deg": -30.0,
                    "center": [0.0, 180.0]},
           "law": {"type": "min-jerk", "duration": 0.5}, "output": {"units": "si"},
           "design": {"l": [60.0, 90.0], "samples": 2}}
    task, _ = scenario_from_dict(doc).design_task()
    assert task.start == pytest.approx((100e-3 * math.cos(math.radians(-160.0)),
                                        0.18 + 100e-3 * math.sin(math.radians(-160.0))))


def test_robot_table_of_a_file(tmp_path):
    p = tmp_path / "r.toml"
    p.write_text("[robot]\nl1 = 80\nl2 = 80\nL1 = 90\nL2 = 90\nd = 50\n[motors]\npeak_torque = 1\n")
    rt = load_robot_table(p)
    assert isinstance(rt, RobotTable) and rt.geometry_mm.l1 == 80.0
    p.write_text("[robo]\nl1 = 80\n")
    with pytest.raises(ConfigError, match=r"config table \[robo\] is not known"):
        load_robot_table(p)
    with pytest.raises(ConfigError, match="does not exist"):
        load_robot_table(tmp_path / "none.toml")
