"""`dextar simulate`'s verdict from its tracking error (issue 28, item 4): followed within
`[control].tolerance_mm` (default 3 % of the reach), else exit 1 with the files written and
the time and the error named."""

from __future__ import annotations

import json

import pytest

from dextar.cli import main
from dextar.geometry import DEXTAR_MM
from dextar.simulation import TRACKING_TOLERANCE, tracking_tolerance

pytestmark = pytest.mark.slow

#: The issue's robot and task: 0.4 kg at the effector, gravity, friction; its motors hold
#: 1.5 N m, at 0.3 N m it falls (before: max task error 272.6 mm, saturated 100 %, exit 0).
ROBOT = """
[robot]
l1 = 120.0
l2 = 120.0
L1 = 180.0
L2 = 180.0
d = 100.0
[path]
type = "arc"
radius = 40.0
center = [0.0, 220.0]
start_deg = 0.0
end_deg = 180.0
[law]
type = "min-jerk"
duration = 1.0
[inertia]
effector_mass = 0.1
payload = 0.3
[friction]
viscous = 0.005
coulomb = 0.02
[gravity]
vector = [0.0, -9810.0]
[output]
units = "si"
samples = 201
[control]
"""


def _simulate(tmp_path, control, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text(ROBOT + control)
    out = tmp_path / "sim"
    capsys.readouterr()
    code = main(["simulate", str(cfg), "--out", str(out), "--json"])
    o, e = capsys.readouterr()
    return code, json.loads(o), e, out


def test_a_falling_robot_is_not_followed_exit_1_with_its_files(tmp_path, capsys):
    code, rep, err, out = _simulate(tmp_path, "torque_limit = 0.3\n", capsys)
    assert code == 1 and rep["status"] == 2 and not rep["followed"]
    assert rep["max_task_error_mm"] > 100 and rep["tolerance_mm"] == pytest.approx(9.0)
    assert 0 < rep["left_tolerance_at_s"] < 0.5
    assert "left the tolerance 9 mm at t = " in err and "task error" in err
    for name in ("tracking.csv", "tracking.png", "tracking.json"):
        assert (out / name).exists()
    assert json.loads((out / "tracking.json").read_text())["followed"] is False


@pytest.fixture(scope="module")
def strong(tmp_path_factory):
    """The issue's robot with 1.5 N m motors and the default tolerance, simulated once for
    the two tests that read it (the same command line and config): (exit status, the
    printed JSON, stderr, the folder)."""
    import contextlib
    import io

    cfg = tmp_path_factory.mktemp("strong") / "c.toml"
    cfg.write_text(ROBOT + "torque_limit = 1.5\n")
    out = cfg.parent / "sim"
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(["simulate", str(cfg), "--out", str(out), "--json"])
    return code, json.loads(o.getvalue()), e.getvalue(), out


def test_motors_strong_enough_follow_within_the_default(strong):
    code, rep, err, _ = strong
    # measured 0.62 mm against the default 9 mm
    assert code == 0 and rep["followed"] and rep["status"] == 0 and rep["complete"]
    assert rep["max_task_error_mm"] < 0.2 * rep["tolerance_mm"] and err == ""


def test_tracking_json_gives_the_tolerance_used_in_both_places(strong):
    """Review 28 finding 16: without [control].tolerance_mm, tracking.json gave
    control.tolerance_mm null beside the top-level tolerance_mm of the default used; now the
    value used in both (9 mm: 3 % of this robot's 300 mm reach)."""
    code, rep, _, out = strong
    written = json.loads((out / "tracking.json").read_text())
    for r in (rep, written):
        assert r["tolerance_mm"] == pytest.approx(9.0)
        assert r["control"]["tolerance_mm"] == r["tolerance_mm"]
        assert r["control"]["tolerance"] == pytest.approx(9e-3)  # SI: m


@pytest.mark.parametrize("tol, code", [(0.1, 1), (5.0, 0)])
def test_the_tolerance_is_the_users(tmp_path, capsys, tol, code):
    """The same motion (0.62 mm off) is not followed within 0.1 mm and followed within 5."""
    got, rep, err, _ = _simulate(tmp_path, f"torque_limit = 1.5\ntolerance_mm = {tol}\n",
                                 capsys)
    assert got == code and rep["followed"] is (code == 0) and rep["tolerance_mm"] == tol
    assert rep["control"]["tolerance_mm"] == tol
    if code:
        assert f"left the tolerance {tol:g} mm" in err


def test_the_default_tolerance_is_a_share_of_the_reach():
    assert tracking_tolerance(DEXTAR_MM) == pytest.approx(TRACKING_TOLERANCE * 159.0)


def test_a_tolerance_that_is_not_positive_is_refused(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text(ROBOT + "tolerance_mm = -1\n")
    assert main(["simulate", str(cfg), "--out", str(tmp_path / "s")]) == 2
    assert "[control].tolerance_mm" in capsys.readouterr().err


def test_a_trial_state_at_a_singularity_is_a_singularity_met(tmp_path, capsys):
    """Found by the falling-simulation fuzz shape: the integrator tried a state exactly at a
    parallel singularity and the controller's dynamics divided by zero (an internal error);
    it is the singularity met, named with its time: exit 1, the files written."""
    cfg = tmp_path / "c.toml"
    cfg.write_text('[path]\ntype = "arc"\nradius = 40.0\ncenter = [0.0, 110.0]\n'
                   '[law]\ntype = "min-jerk"\nduration = 3.0\n[inertia]\neffector_mass = 0.1\n'
                   '[friction]\nviscous = 0.005\n[gravity]\nvector = [0.0, -9810.0]\n'
                   '[control]\ntorque_limit = 0.1\nnatural_frequency_hz = 2.0\n'
                   '[output]\nsamples = 201\n')
    code = main(["simulate", str(cfg), "--out", str(tmp_path / "s"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 1 and "internal error" not in err
    assert "met a singularity at t = " in err and (tmp_path / "s" / "tracking.json").exists()


@pytest.mark.parametrize("limit, saturates", [(1.5, False), (0.52, True)])
def test_a_simulation_stopped_by_its_step_budget_is_incomplete(tmp_path, capsys, monkeypatch,
                                                               limit, saturates):
    """Review 28 finding 6. Before: a plant stopped by its step budget (MAX_STEPS) was status 1,
    worded "the controlled robot left the motion ... after the torque limit saturated a motor
    during 0.0 % of it". Now its own status, 3, "simulation incomplete", exit 1 with the
    files; the saturation named only where the limit saturated (at 1.5 N m the motion does
    not saturate; at 0.52 N m it saturates and is followed within 3.3 mm, measured). The
    budget is lowered to 200 steps (the 1 s motion takes about 600; 100,000 took 125 s of
    CPU on a 2000 s motion at 100 Hz, measured)."""
    from dextar.simulation import control

    monkeypatch.setattr(control, "MAX_STEPS", 200)
    code, rep, err, out = _simulate(tmp_path, f"torque_limit = {limit}\n", capsys)
    assert code == 1 and rep["status"] == control.INCOMPLETE == 3
    assert not rep["followed"] and not rep["complete"]
    assert err.startswith("dextar simulate: simulation incomplete: the integration was "
                          "stopped after 200 steps (its budget) at t = ") and err.count("\n") == 1
    assert "of the motion's 1 s; until then the controlled robot followed within 9 mm" in err
    assert "left the motion" not in err and "not followed" not in err
    assert ("saturated a motor" in err) == saturates == (rep["saturated_fraction"] > 0)
    t = json.loads((out / "tracking.json").read_text())
    assert t["status"] == 3 and t["complete"] is False
    rows = (out / "tracking.csv").read_text().splitlines()
    assert 10 < len(rows) - 1 < 201  # the motion up to the stop, not the whole of it
