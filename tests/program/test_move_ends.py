"""Every move ends where it was sent, in the program's assembly mode (issue 28, item 0): a
start or a target that its working mode reaches only in the other assembly mode is refused by
name, and every motion's end (the forward kinematics of its last setpoint) is checked against
its target before the program is said to fit."""

from __future__ import annotations

import csv

import numpy as np
import pytest

import dextar as dx
from dextar.cli import main
from dextar.errors import AssemblyError
from dextar.program import Move, plan_program

ROBOT = dx.DEXTAR_MM.scaled(1e-3)


def _task(tmp_path, program, moves, robot=""):
    cfg = tmp_path / "task.toml"
    cfg.write_text(f'[robot]\npreset = "dextar"\n{robot}[motors]\npeak_torque = 2.0\n'
                   f"[program]\n{program}\n{moves}")
    return cfg


def _program(tmp_path, capsys, *args, **kw):
    cfg = _task(tmp_path, *args, **kw)
    out = tmp_path / "out"
    code = main(["program", str(cfg), "--out", str(out), "--no-figures", "--quiet"])
    return code, capsys.readouterr().err, out


JOINT_TO_100_10 = '[[move]]\ntype = "joint"\nto = [100.0, 10.0]\nworking_mode = "--"\n'


def test_a_joint_target_of_the_other_assembly_is_refused_by_name(tmp_path, capsys):
    """Before: exit 0, "fits the motors", the last setpoint at (-39.1, 110.9) mm."""
    code, err, out = _program(tmp_path, capsys, 'start = [-100.0, 10.0]\nworking_mode = "--"',
                              JOINT_TO_100_10)
    assert code == 2 and not out.exists()
    assert "move 0 (joint)" in err and "(100, 10) mm" in err and "working mode --" in err
    assert "assembly mode down" in err and "assembly mode up" in err


def test_a_start_of_the_other_assembly_is_refused_by_name(tmp_path, capsys):
    """Before: a dwell at (0, 35) mm in +- was planned (exit 0) with the torques of the pose
    at (0, 54.4) mm."""
    code, err, _ = _program(tmp_path, capsys, 'start = [0.0, 35.0]\nworking_mode = "+-"',
                            '[[move]]\ntype = "dwell"\ntime = 0.1\n')
    assert code == 2 and "the start (0, 35) mm in working mode +-" in err
    assert "assembly mode down" in err and "assembly mode up" in err


def test_the_same_start_in_its_own_assembly_mode_is_planned_there(tmp_path, capsys):
    code, err, out = _program(tmp_path, capsys, 'start = [0.0, 35.0]\nworking_mode = "+-"',
                              '[[move]]\ntype = "dwell"\ntime = 0.1\n',
                              robot='assembly_mode = "down"\n')
    assert code == 0, err
    with open(out / "setpoints.csv") as fh:
        rows = list(csv.reader(fh))
    q = np.array([float(v) for v in rows[-1][4:6]])
    P = dx.direct_kinematics(dx.DEXTAR_MM, q, "down")
    assert np.allclose(P, [0.0, 35.0], atol=1e-9)


def test_a_joint_target_of_the_programs_assembly_ends_there(tmp_path, capsys):
    code, err, out = _program(tmp_path, capsys, 'start = [-100.0, 10.0]\nworking_mode = "--"',
                              '[[move]]\ntype = "joint"\nto = [-60.0, 40.0]\n'
                              'working_mode = "--"\n')
    assert code == 0, err
    with open(out / "setpoints.csv") as fh:
        rows = list(csv.reader(fh))
    P = dx.direct_kinematics(dx.DEXTAR_MM, np.array([float(v) for v in rows[-1][4:6]]), "up")
    assert np.allclose(P, [-60.0, 40.0], atol=1e-9)


def test_the_end_check_catches_a_move_that_ends_elsewhere(monkeypatch):
    """Without the target's assembly check the joint move ends 155 mm away; the end check
    names it before any "fits"."""
    import dextar.program.move_types as mt

    monkeypatch.setattr(mt, "check_assembly", lambda *a, **k: None)
    with pytest.raises(AssemblyError, match=r"move 0 \(joint\): sent to \(100, 10\) mm, it "
                       r"ends at \(-39\.1\d*, 110\.8\d*\) mm"):
        plan_program(ROBOT, dx.dynamics.paper_inertia(ROBOT).scaled_masses(0.1),
                     [Move("joint", {"to": (0.1, 0.01), "working_mode": "--"},
                           law="min-jerk", duration=0.5)],
                     start=(-0.1, 0.01), working_mode="--")
