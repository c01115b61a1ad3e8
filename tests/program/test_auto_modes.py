"""Working modes chosen by the planner (``working_mode = "auto"``): the auto cycle is the
shortest of every hand-written sequence of modes for the same targets, a program that no
single mode reaches plans with auto and is refused with every fixed mode, and a plain program
keeps its mode where that is best."""

import itertools
import json
import re
from dataclasses import replace
from pathlib import Path

import pytest

from dextar.cli import main
from dextar.config import load_scenario
from dextar.errors import DextarError
from dextar.program import AUTO, Move, plan_program

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
MODES = ("++", "+-", "-+", "--")
#: Cycle times compared to this (s): the same motions planned twice agree to rounding
#: (measured: to the last bit); a mode's choice moves the cycle by milliseconds at least.
TOL = 1e-9


@pytest.fixture(scope="module")
def setup():
    """The DexTAR of examples/auto_modes.toml (SI), its motors, on a coarse grid (fast)."""
    sc = load_scenario(EXAMPLES / "auto_modes.toml")
    m = sc.si_model
    return dict(robot=m.robot, inertia=m.inertia, motors=sc.si_motors, grid=60,
                servo_rate_hz=500.0)


def plan(setup, moves, start, mode):
    return plan_program(setup["robot"], setup["inertia"], moves, start=start,
                        working_mode=mode, motors=setup["motors"], grid=setup["grid"],
                        servo_rate_hz=setup["servo_rate_hz"])


def mm(x, y):
    return (x * 1e-3, y * 1e-3)


def hand_written(start, start_mode, modes, targets, kind):
    """The program a user writes for one sequence of modes: a joint move to each target in
    its mode, or (lines) a joint move at the line's start where the mode changes, then the
    line."""
    moves, prev, at = [], start_mode, start
    for m, to in zip(modes, targets, strict=True):
        if kind == "joint":
            moves.append(Move("joint", {"to": to, "working_mode": m}))
        else:
            if m != prev:
                moves.append(Move("joint", {"to": at, "working_mode": m}))
            moves.append(Move("line", {"to": to}))
        prev, at = m, to
    return moves


def every_sequence(setup, start, targets, kind, start_modes):
    """The cycle time of every hand-written sequence of modes that plans (None: refused)."""
    out = {}
    for m0 in start_modes:
        for seq in itertools.product(MODES, repeat=len(targets)):
            moves = hand_written(start, m0, seq, targets, kind)
            try:
                out[(m0, *seq)] = plan(setup, moves, start, m0).cycle_time_s
            except DextarError:
                out[(m0, *seq)] = None
    return out


@pytest.mark.slow
def test_auto_joint_moves_are_the_shortest_of_every_sequence(setup):
    """Joint moves to two targets, the start's mode and each target's chosen: the 64
    hand-written sequences (4 start modes x 4 x 4) planned, the auto cycle equal to the
    shortest within TOL and never longer than any."""
    start, targets = mm(0, 100), [mm(-60, 60), mm(60, 60)]
    times = every_sequence(setup, start, targets, "joint", MODES)
    ok = {k: v for k, v in times.items() if v is not None}
    assert len(ok) >= 8 and max(ok.values()) > min(ok.values()) + 1e-3  # a real choice
    res = plan(setup, [Move("joint", {"to": t}) for t in targets], start, AUTO)
    assert all(res.cycle_time_s <= v + TOL for v in ok.values())
    assert res.cycle_time_s == pytest.approx(min(ok.values()), abs=TOL)
    c = res.mode_choice
    assert ok[(c.start_mode, *c.modes)] == pytest.approx(res.cycle_time_s, abs=TOL)


@pytest.mark.slow
def test_auto_lines_are_the_shortest_of_every_sequence(setup):
    """Lines to two targets from a start in +-, each line's mode chosen (a change of mode is
    a joint move at the line's start): the 16 hand-written sequences planned."""
    start, targets = mm(0, 100), [mm(-40, 60), mm(40, 60)]
    times = every_sequence(setup, start, targets, "line", ("+-",))
    ok = {k: v for k, v in times.items() if v is not None}
    assert len(ok) >= 4 and max(ok.values()) > min(ok.values()) + 1e-3
    res = plan(setup, [Move("line", {"to": t, "working_mode": AUTO}) for t in targets], start,
               "+-")
    assert all(res.cycle_time_s <= v + TOL for v in ok.values())
    assert res.cycle_time_s == pytest.approx(min(ok.values()), abs=TOL)


# (0, -15) mm: only -+ reaches it in assembly mode up; (0, -100) mm: only +-; (0, 100) mm:
# ++, +- and --.
PICK, PLACE, HOME = mm(0, -15), mm(0, -100), mm(0, 100)
ACROSS = [Move("joint", {"to": PICK}), Move("dwell", {"time": 0.1}),
          Move("joint", {"to": HOME})]


def test_no_single_mode_reaches_the_targets_but_auto_plans_them(setup):
    """From (0, -100) mm (+- only) to (0, -15) mm (-+ only) and up to (0, 100) mm."""
    res = plan(setup, ACROSS, PLACE, AUTO)
    c = res.mode_choice
    assert c.start_mode == "+-" and c.modes[:2] == ("-+", "-+") and c.modes[2] != "-+"
    assert [m.working_mode for m in res.timeline()] == list(c.modes)
    for mode in MODES:  # every fixed mode is refused, naming the point it does not reach
        with pytest.raises(DextarError, match=r"\((0, -15|0, -100)\) mm in working mode "
                           + mode.replace("+", r"\+")):
            plan(setup, ACROSS, PLACE, mode)


def test_a_target_no_mode_reaches_is_named(setup):
    moves = [Move("joint", {"to": PICK}), Move("joint", {"to": mm(0, 170)})]
    with pytest.raises(DextarError, match=r"move 1 \(joint\): working_mode = \"auto\": no "
                       r"working mode plans it to its target \(0, 170\) mm"):
        plan(setup, moves, HOME, AUTO)


def test_a_plain_program_keeps_its_mode_where_that_is_best(setup):
    """Two short lines in +-: changing the mode costs a joint move more than the lines could
    gain, so auto keeps +- and the cycle is the fixed program's."""
    moves = [Move("line", {"to": mm(-20, 110)}), Move("line", {"to": mm(20, 110)})]
    fixed = plan(setup, moves, HOME, "+-")
    auto = plan(setup, [replace(m, values={**m.values, "working_mode": AUTO}) for m in moves],
                HOME, "+-")
    assert auto.mode_choice.modes == ("+-", "+-") and auto.mode_choice.changes == ()
    assert auto.cycle_time_s == pytest.approx(fixed.cycle_time_s, abs=TOL)
    assert not any(m.mode_change for m in auto.timeline())


def test_a_blended_chain_keeps_one_mode(setup):
    moves = [Move("line", {"to": mm(-20, 110), "working_mode": AUTO}, blend=0.005),
             Move("line", {"to": mm(20, 110), "working_mode": "++"})]
    with pytest.raises(DextarError, match=r"move 1 \(line\) sets working_mode = \"\+\+\" "
                       r"but a blend makes it one motion with move 0"):
        plan(setup, moves, HOME, "+-")


@pytest.mark.slow
def test_the_command_reports_the_modes_it_chose(tmp_path, capsys):
    out = tmp_path / "auto"
    assert main(["program", "--no-figures", str(EXAMPLES / "auto_modes.toml"), "--out",
                 str(out)]) == 0
    text = capsys.readouterr().out
    assert "working modes chosen by the planner: start" in text
    assert "change of working mode to -+" in text
    doc = json.loads((out / "summary.json").read_text())
    moves = doc["moves"]
    assert {m["working_mode"] for m in moves} >= {"-+", "+-"}
    assert all(m["assembly_mode"] == "up" for m in moves)
    assert doc["mode_choice"]["changes_before_moves"] == [
        m["index"] for m in moves if m["mode_change"]]
    assert [m["working_mode"] for m in moves if not m["mode_change"]] == doc["mode_choice"][
        "modes"]
    for mode in MODES:  # the same file with any fixed mode is refused (exit 2, named)
        cfg = tmp_path / f"fixed{MODES.index(mode)}.toml"
        cfg.write_text((EXAMPLES / "auto_modes.toml").read_text().replace(
            'working_mode = "auto"', f'working_mode = "{mode}"'))
        assert main(["program", "--no-figures", str(cfg), "--out",
                     str(tmp_path / cfg.stem)]) == 2
        assert f"working mode {mode}" in capsys.readouterr().err


def test_a_line_with_its_own_mode_is_the_hand_written_change_and_line(setup):
    """working_mode = "++" on a line in a +- program: the planner changes the mode at the
    line's start by a joint move, the cycle the hand-written joint move and line's."""
    own = plan(setup, [Move("line", {"to": mm(20, 110), "working_mode": "++"})], HOME, "+-")
    hand = plan(setup, [Move("joint", {"to": HOME, "working_mode": "++"}),
                        Move("line", {"to": mm(20, 110)})], HOME, "+-")
    assert [(m.index, m.type, m.mode_change, m.working_mode) for m in own.timeline()] == [
        (0, "joint", True, "++"), (0, "line", False, "++")]
    assert own.cycle_time_s == pytest.approx(hand.cycle_time_s, abs=TOL)
    assert own.mode_choice.changes == (0,) and (own.move_index == 0).all()


@pytest.mark.slow
def test_a_robot_of_unequal_rods_plans_with_auto_where_no_single_mode_does(tmp_path, capsys):
    """Issue 31's robot of unequal rods (80/75/95/92/58 mm) on auto_modes.toml's cycle: auto
    plans it (measured 1.8429 s: start --, then -- -+ -+ -+ -- +- +- +-), every fixed working
    mode is refused (exit 2: a parallel singularity on the way in ++, +-, --; the start in the
    other assembly mode in -+)."""
    text = (EXAMPLES / "auto_modes.toml").read_text().replace(
        '[robot]\npreset = "dextar"\n',
        "[robot]\nl1 = 80.0\nl2 = 75.0\nL1 = 95.0\nL2 = 92.0\nd = 58.0\n")
    assert "l2 = 75.0" in text
    cfg = tmp_path / "u.toml"
    cfg.write_text(text)
    assert main(["program", str(cfg), "--out", str(tmp_path / "auto"), "--no-figures",
                 "--quiet"]) == 0
    s = json.loads((tmp_path / "auto" / "summary.json").read_text())
    modes = {m["working_mode"] for m in s["moves"]}
    assert len(modes) >= 3, modes  # the cycle needs three working modes
    for mode in ("++", "+-", "-+", "--"):
        cfg.write_text(text.replace('working_mode = "auto"', f'working_mode = "{mode}"'))
        assert main(["program", str(cfg), "--out", str(tmp_path / mode.replace("+", "p")),
                     "--no-figures", "--quiet"]) == 2, mode
    capsys.readouterr()


@pytest.mark.slow
def test_the_moves_figure_draws_each_working_mode_it_runs_in(setup):
    """The moves figure drew the start mode's workspace only, under moves run in other modes
    (whose singularity curves and assembly regions differ): now a panel per mode visited,
    each with the setpoints run in that mode."""
    import numpy as np

    from dextar.output.program import mode_samples, moves_figure

    res = plan(setup, ACROSS, PLACE, AUTO)
    c = res.mode_choice
    visited = list(dict.fromkeys((c.start_mode, *c.modes)))
    spans = mode_samples(res, c.start_mode)
    assert list(spans) == visited and len(visited) >= 2
    for pm in res.moves:  # every setpoint of a move in its mode's panel
        inside = (res.t > pm.start_s) & (res.t < pm.start_s + pm.duration_s)
        assert spans[pm.mode][inside].all()
    assert np.logical_or.reduce(list(spans.values())).all()
    fig = moves_figure(res, setup["robot"].scaled(1e3), c.start_mode)
    titles = [ax.get_title() for ax in fig.axes]
    assert [t for t in titles if t.startswith("the moves in")] == [
        f"the moves in working mode {m}" for m in visited]


#: A new user's program (a trial's): down a line, a dwell, back up it, across, down, a dwell
#: and an arc over the top; its map's legend at the lower right hid move 5's number and the
#: numbers of moves 0 and 2 touched.
TRIAL = """[robot]
l1 = 150.0
l2 = 150.0
L1 = 200.0
L2 = 200.0
d = 120.0
working_mode = "+-"
[inertia]
effector_mass = 0.2
payload = 0.5
[gravity]
vector = [0.0, -9810.0]
[motors]
peak_torque = 4.0
max_jerk = 2000.0
[program]
start = [-70.0, 230.0]
[[move]]
type = "line"
to = [-70.0, 180.0]
[[move]]
type = "dwell"
time = 0.15
[[move]]
type = "line"
to = [-70.0, 230.0]
blend = 10.0
[[move]]
type = "line"
to = [70.0, 230.0]
blend = 10.0
[[move]]
type = "line"
to = [70.0, 180.0]
[[move]]
type = "dwell"
time = 0.15
[[move]]
type = "arc"
via = [0.0, 280.0]
to = [-70.0, 230.0]
"""


@pytest.mark.slow
def test_the_moves_figure_legend_covers_no_map_and_numbers_do_not_touch(setup, tmp_path):
    """One legend for the figure, below the maps (each map's own legend, at its lower right,
    had hidden a move's number, and in a grid of maps it ran into the next row's title), and
    no two moves' numbers touch (a move back up a line it came down had its number 4 pixels
    from the first's): drawn, and measured in the figure's pixels."""
    from matplotlib.text import Annotation

    from dextar.config import load_scenario
    from dextar.output.program import moves_figure

    grid = plan(setup, ACROSS, PLACE, AUTO)
    (tmp_path / "trial.toml").write_text(TRIAL)
    sc = load_scenario(tmp_path / "trial.toml")
    one = sc.program_request().plan()
    for res, robot, mode in ((grid, setup["robot"].scaled(1e3), grid.mode_choice.start_mode),
                             (one, sc.robot_mm, sc.program_mode)):
        fig = moves_figure(res, robot, mode)
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        assert len(fig.legends) == 1 and all(ax.get_legend() is None for ax in fig.axes)
        box = fig.legends[0].get_window_extent(renderer)
        for ax in fig.axes:
            assert not box.overlaps(ax.get_tightbbox(renderer)), ax.get_title()
        for ax in fig.axes:
            # each number's circle with 3 pixels around it (numbers 4 pixels apart, as moves
            # 0 and 2 here were with the old gap, read as touching; now 12.6 pixels at least)
            marks = [a.get_bbox_patch().get_window_extent(renderer).padded(3) for a in ax.texts
                     if isinstance(a, Annotation)]
            assert marks or not ax.get_title().startswith(("Program", "the moves"))
            for i, a in enumerate(marks):
                for b in marks[i + 1:]:
                    assert not a.overlaps(b), (ax.get_title(), a, b)


def test_modes_that_fail_for_one_reason_are_named_together(tmp_path, capsys):
    """A blend that does not fit its move fails in every working mode the planner tries: the
    reason is given once, after the modes it holds in (it was repeated for each mode)."""
    cfg = tmp_path / "task.toml"
    cfg.write_text('[motors]\npeak_torque = 3.4\n[program]\nworking_mode = "auto"\n'
                   'start = [-40.0, 110.0]\n'
                   '[[move]]\ntype = "line"\nto = [-40.0, 120.0]\nblend = 30.0\n'
                   '[[move]]\ntype = "line"\nto = [0.0, 130.0]\nblend = 30.0\n'
                   '[[move]]\ntype = "line"\nto = [0.0, 400.0]\n')
    assert main(["program", str(cfg), "--out", str(tmp_path / "o"), "--no-figures"]) == 2
    err = capsys.readouterr().err
    assert err.count("its blend of 30 mm at its end does not fit its length of 10 mm") == 1, err
    assert re.search(r"in [+-]{2}, [+-]{2}(, [+-]{2})*: move 0 \(line\)", err), err
