"""Moves across the parallel (type 2) singularity curve (issue 31): ``assembly_mode`` on a
line or an arc, planned time-optimal under the degeneracy condition; the crossing's time,
residual and torque peak in summary.json; what cannot cross refused by name."""

import io
import json
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from dextar import jobs
from dextar.cli import main
from dextar.config import load_scenario
from dextar.errors import AssemblyError, InfeasibleError, ParameterError
from dextar.motors import MotorLimits
from dextar.output.program import crossing_points, motion_figure, moves_figure, program_report
from dextar.program import Move, plan_program

from ..crossing_cases import CASES
from .test_program import read

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    """``dextar program`` on the example without its figures (they are checked below, drawn
    and not rendered): the setpoints, summary.json and what it printed."""
    out = tmp_path_factory.mktemp("x") / "out"
    printed = io.StringIO()
    with redirect_stdout(printed):
        assert main(["program", str(EXAMPLES / "type2_crossing.toml"), "--out", str(out),
                     "--no-figures"]) == 0
    head, data = read(out / "setpoints.csv")
    return (dict(zip(head, data.T, strict=True)), json.loads((out / "summary.json").read_text()),
            printed.getvalue())


@pytest.mark.slow
def test_the_example_crosses_down_and_back_within_the_motors(example):
    cols, summ, printed = example
    assert summ["status"] == "fits"
    modes = [m["assembly_mode"] for m in summ["moves"]]
    assert modes == ["down", "down", "down", "up"]
    (down,), (up,) = summ["moves"][0]["crossings"], summ["moves"][3]["crossings"]
    for c in (down, up):
        # the condition holds to rounding (measured 5e-15 and 9e-15 of its terms)
        assert c["condition_holds"] and c["residual_ratio"] < 1e-10
        assert max(c["torque_peak_ratio"]) <= 1 + 1e-3
        assert c["neighbourhood_s"][0] < c["time_s"] < c["neighbourhood_s"][1]
        assert abs(c["point_mm"][1] - 44.0) < 0.5  # the rods horizontal, y = 44 mm
    assert (down["assembly_before"], up["assembly_after"]) == ("up", "up")
    tau = np.stack([cols["tau1_Nm"], cols["tau2_Nm"]], -1)
    assert np.isfinite(tau).all() and np.abs(tau).max() <= 0.5 * (1 + 1e-3)
    # the setpoints pass the crossing's time, and the printed lines say both crossings
    t = cols["t_s"]
    assert t.min() < down["time_s"] < t.max()
    assert "move 0 crosses the parallel singularity curve" in printed
    assert "move 3 crosses the parallel singularity curve" in printed
    assert "assembly mode up -> down" in printed and "assembly mode down -> up" in printed


@pytest.mark.slow
def test_the_examples_figures_and_report_mark_its_crossings():
    """moves.png stars both crossings where summary.json puts them; every panel of
    motion.png has a red dash-dot line at each crossing's time; the report has their table
    (the figures drawn, not rendered: what is drawn is what is checked)."""
    sc = load_scenario(EXAMPLES / "type2_crossing.toml")
    job = jobs.program(sc)
    points = [c["point_mm"] for m in job.summary.as_json()["moves"] for c in m["crossings"]]
    times = [c["time_s"] for m in job.summary.as_json()["moves"] for c in m["crossings"]]
    assert len(points) == 2
    fig = moves_figure(job.result, sc.robot_mm, sc.program_mode)
    (stars,) = [ln for ln in fig.axes[0].get_lines() if ln.get_label() == "type-2 crossing"]
    assert np.allclose(np.column_stack(stars.get_data()), points, atol=1e-6)
    fig = motion_figure(job.result)
    for ax in fig.axes:
        marks = [ln.get_xdata()[0] for ln in ax.get_lines()
                 if ln.get_linestyle() == "-." and ln.get_color() == "red"]
        assert np.allclose(marks, times, atol=1e-9), ax.get_ylabel()
    assert "Crossings of the parallel singularity curve" in program_report(job.summary, {})


def _moves(case, **extra):
    return [Move("line", {"to": case.end, **extra}), Move("dwell", {"time": 0.05})]


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_python_api_plans_the_crossing_on_both_robots(name):
    case = CASES[name]
    res = plan_program(case.robot, case.inertia, _moves(case, assembly_mode="down"),
                       start=case.start, working_mode="+-", motors=case.motors)
    pm = res.moves[0]
    assert (pm.assembly, pm.end_assembly) == ("up", "down") and len(pm.crossings) == 1
    assert np.abs(res.tau).max() <= case.peak * (1 + 1e-3)
    (c,) = case.crossings
    assert np.allclose(crossing_points(res), 1e3 * c.P, atol=1e-9)
    # the dwell holds the robot in assembly mode down (its torques are the down pose's)
    assert res.timeline()[1].assembly_mode == "down"


def test_assembly_mode_without_a_crossing_is_refused_by_name():
    case = CASES["dextar"]
    with pytest.raises(AssemblyError, match=r"move 0 \(line\): assembly_mode = \"down\", but "
                                            r"its path .* does not cross"):
        plan_program(case.robot, case.inertia, [Move("line", {"to": (0.010, 0.060),
                                                              "assembly_mode": "down"})],
                     start=case.start, working_mode="+-", motors=case.motors)
    # asking for the mode it is already in is no change: planned
    plan_program(case.robot, case.inertia, [Move("line", {"to": (0.010, 0.060),
                                                          "assembly_mode": "up"})],
                 start=case.start, working_mode="+-", motors=case.motors)


def test_a_crossing_without_the_key_is_refused_as_before():
    case = CASES["dextar"]
    with pytest.raises(Exception, match="parallel"):
        plan_program(case.robot, case.inertia, [Move("line", {"to": case.end})],
                     start=case.start, working_mode="+-", motors=case.motors)


def test_a_law_that_ignores_the_condition_is_refused_by_name():
    case = CASES["dextar"]
    with pytest.raises(ParameterError, match="needs law = \"time-optimal\".*min-jerk"):
        plan_program(case.robot, case.inertia,
                     [Move("line", {"to": case.end, "assembly_mode": "down"}, law="min-jerk",
                           duration=0.3)],
                     start=case.start, working_mode="+-", motors=case.motors)


def test_a_joint_move_keeps_its_assembly_mode():
    case = CASES["dextar"]
    with pytest.raises(AssemblyError, match="a joint move stays in assembly mode up"):
        plan_program(case.robot, case.inertia,
                     [Move("joint", {"to": case.end, "assembly_mode": "down"})],
                     start=case.start, working_mode="+-", motors=case.motors)


def test_a_crossing_the_motors_cannot_make_is_refused_with_the_reason():
    """Back up across the curve against gravity at 0.3 N m: the condition asks the effector
    to decelerate at about g there, which no motion within 0.3 N m reaches; at 0.5 N m it
    plans."""
    case = CASES["dextar"]
    moves = [Move("line", {"to": case.start, "assembly_mode": "up"})]
    start = (0.0, 0.030)
    from dataclasses import replace
    weak = replace(case.motors, peak_torque=(0.3, 0.3))
    with pytest.raises(InfeasibleError, match="the crossing of the parallel .* cannot be made "
                                              "within the motors' limits"):
        plan_program(case.robot, case.inertia, moves, start=start, working_mode="+-",
                     assembly="down", motors=weak)
    res = plan_program(case.robot, case.inertia, moves, start=start, working_mode="+-",
                       assembly="down", motors=MotorLimits((0.5, 0.5)))
    assert res.moves[0].end_assembly == "up"


def test_a_blended_chain_and_an_arc_cross_where_their_members_ask():
    """The member of a blended chain that asks for "down" crosses (the chain is one motion),
    and an arc brings the robot back up; every torque within the motors."""
    case = CASES["dextar"]
    moves = [Move("line", {"to": (-0.005, 0.060)}, blend=0.003),
             Move("line", {"to": (0.005, 0.025), "assembly_mode": "down"}),
             Move("arc", {"via": (0.0, 0.055), "to": case.start, "assembly_mode": "up"})]
    res = plan_program(case.robot, case.inertia, moves, start=case.start, working_mode="+-",
                       motors=case.motors)
    tl = res.timeline()
    assert [m.assembly_mode for m in tl] == ["up", "down", "up"]
    assert [len(m.crossings) for m in tl] == [0, 1, 1]
    for m in tl[1:]:
        (c,) = m.crossings
        assert m.start_s < c["time_s"] < m.start_s + m.duration_s and c["condition_holds"]
    assert np.abs(res.tau).max() <= case.peak * (1 + 1e-3)
    # a chain whose member asks for a mode its piece does not reach is refused, naming it
    bad = [moves[0], Move("line", {"to": (0.005, 0.050), "assembly_mode": "down"})]
    with pytest.raises(AssemblyError, match=r"move 1 \(line\): assembly_mode"):
        plan_program(case.robot, case.inertia, bad, start=case.start, working_mode="+-",
                     motors=case.motors)
