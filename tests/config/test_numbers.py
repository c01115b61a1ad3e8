"""Every number a config gives is checked where it is read and named in the user's units
(issue 28, items 7 and 3): lengths beyond double precision's reach, NaN called NaN, the optimal
law's limits in s, kg and s^2/kg, a robot that looks written in metres and an empty config
said so."""

from __future__ import annotations

import pytest

from dextar.cli import main


def _run(tmp_path, capsys, text, *argv, command="plan"):
    cfg = tmp_path / "c.toml"
    cfg.write_text(text)
    out = tmp_path / ("out.csv" if command in ("plan", "torques") else "out")
    capsys.readouterr()
    code = main([command, str(cfg), "--out", str(out), *argv])
    return code, capsys.readouterr().err


@pytest.mark.parametrize("value, words", [("1e300", "beyond 1e+09 mm"),
                                          ("1e-200", "below 1e-06 mm")])
@pytest.mark.parametrize("command", ["plan", "run", "simulate"])
def test_lengths_beyond_double_precision_are_named_config_errors(tmp_path, capsys, value,
                                                                  words, command):
    """Before: `internal error: OverflowError` / `ZeroDivisionError`."""
    code, err = _run(tmp_path, capsys, f'[robot]\npreset = "dextar"\nl1 = {value}\nl2 = {value}\n',
                     *(["--quiet"] if command != "plan" else []), command=command)
    assert code == 2 and "internal error" not in err
    assert "config key [robot].l1" in err and words in err


def test_a_point_beyond_the_bound_is_named(tmp_path, capsys):
    code, err = _run(tmp_path, capsys, '[path]\ntype = "line"\nstart = [1e300, 0.0]\n'
                     'end = [0.0, 100.0]\n')
    assert code == 2 and "config key [path].start" in err and "beyond" in err


def test_lengths_within_the_bounds_plan(tmp_path, capsys):
    """The DexTAR a million times larger, its path too: planned (the bound is not a limit
    of the kinematics)."""
    k = 1e6
    code, err = _run(tmp_path, capsys, f"[robot]\nl1 = {72 * k}\nl2 = {72 * k}\nL1 = {87 * k}\n"
                     f"L2 = {87 * k}\nd = {60 * k}\n[path]\ntype = \"arc\"\nradius = {120 * k}\n")
    assert code == 0, err


def test_nan_is_called_nan(tmp_path, capsys):
    code, err = _run(tmp_path, capsys, "[robot]\nl1 = nan\n")
    assert code == 2 and "[robot].l1 must be finite, got NaN" in err
    code, err = _run(tmp_path, capsys, '[path]\ntype = "line"\nstart = [nan, 0.0]\n'
                     'end = [0.0, 100.0]\n')
    assert code == 2 and "x is NaN" in err


def test_ik_of_nan_says_nan_not_out_of_reach(capsys):
    """Before: "out of reach by inf mm (|P - A| = nan mm)"."""
    assert main(["ik", "nan", "200"]) == 2
    err = capsys.readouterr().err
    assert "(nan, 200) mm is not a number (x is NaN)" in err and "inf mm" not in err
    assert main(["ik", "0", "120"]) == 0


def test_the_optimal_law_speaks_the_users_units(tmp_path, capsys):
    """Before: "eta = 1e-19 is too small for duration 1 and mass 1" (paper units, where the
    duration is the time unit)."""
    code, err = _run(tmp_path, capsys, "[law]\nduration = 1e9\n")
    assert code == 2
    assert "eta = 0.1 s^2/kg" in err and "duration 1e+09 s" in err and "mass 1 kg" in err
    assert "1e-19" not in err
    code, err = _run(tmp_path, capsys, "[law]\nduration = 2.0\n")
    assert code == 0, err


METRES = "[robot]\nl1 = 0.12\nl2 = 0.12\nL1 = 0.18\nL2 = 0.18\nd = 0.1\n"


def test_a_robot_in_metres_is_said_so(tmp_path, capsys):
    """Before: a 0.12 mm robot, without a hint. Its path in metres plans (a note on stderr);
    the default path in mm is out of its reach (the error carries the note)."""
    code, err = _run(tmp_path, capsys, METRES + '[path]\ntype = "line"\nstart = [-0.05, 0.2]\n'
                     'end = [0.05, 0.2]\n')
    assert code == 0 and "note:" in err and "looks like metres (0.18 m = 180 mm)" in err
    code, err = _run(tmp_path, capsys, METRES)
    assert code == 2 and "out of reach" in err and "looks like metres" in err


def test_a_robot_in_mm_has_no_note(tmp_path, capsys):
    code, err = _run(tmp_path, capsys, "[robot]\nl1 = 72.0\nl2 = 72.0\nL1 = 87.0\nL2 = 87.0\n"
                     "d = 60.0\n")
    assert code == 0 and "note" not in err


def test_an_empty_config_says_it_runs_the_papers_example(tmp_path, capsys):
    code, err = _run(tmp_path, capsys, "# nothing yet\n")
    assert code == 0 and "has no table: this runs the paper's example" in err
    code, err = _run(tmp_path, capsys, "[law]\neta = 0.1\n")
    assert code == 0 and "note" not in err
