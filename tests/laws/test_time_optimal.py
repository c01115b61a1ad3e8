import re

import numpy as np
import pytest

import dextar as dx
from dextar.dynamics import Model, inverse_dynamics, paper_inertia
from dextar.dynamics import time_optimal_law as solve_time_optimal_law
from dextar.laws import MinimumJerkLaw
from dextar.paths import Arc, Line
from dextar.trajectory import sample_trajectory

ROBOT = dx.DEXTAR_MM.scaled(1 / 87)
SEMI = Arc(120 / 87, 0.0, np.pi)
MODEL = Model(ROBOT, paper_inertia(ROBOT))


def peak_torque(model, path, law, n=2001):
    tr = sample_trajectory(ROBOT, path, law, samples=n)
    return np.abs(inverse_dynamics(model, tr.q, tr.dq, tr.ddq)).max(axis=0)


@pytest.fixture(scope="session")
def law():
    return solve_time_optimal_law(MODEL, SEMI, torque_limit=(20.0, 20.0), grid=400)


def test_faster_than_any_scaled_min_jerk(law):
    lo, hi = 0.2, 5.0  # bisection: shortest min-jerk duration within the limits
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if peak_torque(MODEL, SEMI, MinimumJerkLaw(SEMI.length, mid)).max() \
            > 20.0 else (lo, mid)
    assert law.duration < hi
    assert law.duration < 0.8 * hi  # bang-bang beats the smooth law by a margin


def test_limits_respected_up_to_discretisation(law):
    ratio = peak_torque(MODEL, SEMI, law, n=8001) / 20.0
    assert ratio.max() <= law.max_torque_ratio + 1e-3
    assert law.max_torque_ratio <= 1.0 + 1e-3 and law.success


def test_a_limit_is_active_everywhere(law):
    """Time optimality: at (almost) every grid point one motor is at its limit."""
    tr = sample_trajectory(ROBOT, SEMI, law, times=law.knots_t[1:-1])
    ratio = np.abs(inverse_dynamics(MODEL, tr.q, tr.dq, tr.ddq)).max(axis=1) / 20.0
    assert np.median(ratio) > 0.99 and ratio.min() > 0.9


def test_rest_to_rest_and_consistent(law):
    y = law.evaluate(np.array([0.0, law.duration]))
    assert y[1][0] == 0.0 and y[1][1] == pytest.approx(0.0, abs=1e-9)
    assert y[0][1] == pytest.approx(SEMI.length, rel=1e-9)
    t = np.linspace(0, law.duration, 20001)
    s, ds, _, _ = law.evaluate(t)
    np.testing.assert_allclose(np.gradient(s, t)[1:-1], ds[1:-1], atol=1e-3 * ds.max())


def test_speed_limit():
    law = solve_time_optimal_law(MODEL, SEMI, torque_limit=(20.0, 20.0), speed_limit=(5.0, 5.0))
    tr = sample_trajectory(ROBOT, SEMI, law, samples=4001)
    assert np.abs(tr.dq).max() <= 5.0 * (1 + 1e-4)  # exact at the grid points
    assert np.abs(tr.dq).max() > 4.99  # and it is used


def test_gravity_beyond_limits_is_an_error():
    heavy = Model(ROBOT, paper_inertia(ROBOT).with_(gravity=(0.0, -100.0)))
    line = Line((-0.4, 1.2), (0.4, 1.3))
    with pytest.raises(dx.InfeasibleError, match=r"motor at D needs 93\.1.* to hold the robot "
                       r"still against gravity at arc length s = 0 .*above its limit 1"):
        solve_time_optimal_law(heavy, line, torque_limit=(1.0, 1.0))


CIRCLE = {"path": {"type": "arc", "radius": 30.0, "center": [0.0, 120.0], "start_deg": -90.0,
                   "end_deg": 270.0},  # both joints reverse twice on the way
          "law": {"type": "time-optimal", "torque_limit": [0.5, 0.6], "speed_limit_deg_s": 900.0,
                  "grid": 400},
          "inertia": {"effector_mass": 0.1, "proximal_mass": 0.03, "distal_mass": 0.02,
                      "rotor_inertia": 2.0},
          "friction": {"coulomb": [0.05, 0.04], "viscous": 2e-4},
          "gravity": {"vector": [0.0, -9810.0]},
          "output": {"units": "si", "samples": 1001}}


def test_limits_hold_on_the_output_through_velocity_reversals():
    from dextar.analysis import analyze, torque_limit_ratio
    from dextar.config import scenario_from_dict

    sc = scenario_from_dict(CIRCLE)
    an = analyze(sc.inputs(), sc.law())
    law = an.law
    assert law.success and law.status == 0 and "within the limits" in law.message
    # the written samples and a much denser sampling: torques within 1 + 1e-3 of the limits
    assert torque_limit_ratio(an) <= 1 + 1e-3
    dense = sc.trajectory(law, samples=40001)
    tau = inverse_dynamics(sc.model(dense.assembly), dense.q, dense.dq, dense.ddq)
    limit = np.array(law.torque_limit)
    assert (np.abs(tau) / limit).max() <= 1 + 1e-3
    assert (np.abs(tau) / limit).max() > 0.99  # and the limits are used
    assert np.abs(dense.dq).max() <= law.speed_limit[0] * (1 + 1e-3)
    # the joints do reverse on this path, where Coulomb friction flips
    assert all((np.diff(np.sign(dense.dq[1:-1, i])) != 0).sum() >= 2 for i in range(2))


def test_infeasible_names_point_arc_length_motor_and_torque(tmp_path, capsys):
    from dextar.cli import main

    cfg = tmp_path / "heavy.toml"
    cfg.write_text('[path]\ntype = "line"\nstart = [-40.0, 100.0]\nend = [40.0, 120.0]\n'
                   '[law]\ntype = "time-optimal"\ntorque_limit = 0.05\n'
                   '[inertia]\neffector_mass = 1.0\n[gravity]\nvector = [0.0, -9810.0]\n'
                   '[output]\nunits = "si"\n')
    code = main(["plan", str(cfg), "--out", str(tmp_path / "p.csv")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert re.search(r"motor at [AD] needs [\d.]+ N m to hold the robot still against gravity "
                     r"at P = \(-?[\d.]+, [\d.]+\) mm \(arc length s = [\d.]+ mm\), above its "
                     r"limit 0\.05 N m", err), err
    assert not (tmp_path / "p.csv").exists()


MOTORS = {"path": {"type": "line", "start": [-60.0, 95.0], "end": [60.0, 125.0]},
          "inertia": {"effector_mass": 0.1, "proximal_mass": 0.03, "distal_mass": 0.02,
                      "rotor_inertia": 2.0},
          "friction": {"coulomb": 0.01, "viscous": 1e-4},
          "gravity": {"vector": [0.0, -9810.0]},
          "law": {"type": "time-optimal"},
          "output": {"units": "si", "samples": 2001}}


def test_motors_table_with_a_torque_speed_envelope_holds_on_the_output():
    from dextar.config import scenario_from_dict

    flat = scenario_from_dict({**MOTORS, "motors": {"peak_torque": 0.5,
                                                     "max_speed_rpm": 150}})
    knee = scenario_from_dict({**MOTORS, "motors": {"peak_torque": 0.5, "max_speed_rpm": 150,
                                                     "knee_speed_rpm": 60}})
    law_flat, law_knee = flat.law(), knee.law()
    assert law_flat.success and law_knee.success
    assert law_knee.duration > law_flat.duration * 1.001  # the envelope costs time
    motors = knee.motors
    dense = knee.trajectory(law_knee, samples=20001)
    tau = inverse_dynamics(knee.model(dense.assembly), dense.q, dense.dq, dense.ddq)
    torque_ratio, speed_ratio = motors.ratios(tau, dense.dq)
    assert torque_ratio <= 1 + 1e-3 and speed_ratio <= 1 + 1e-3
    assert torque_ratio > 0.99  # and the envelope is used: above the knee somewhere
    assert (np.abs(dense.dq) > motors.knee_speed[0]).any()


def test_motors_table_errors_named():
    from dextar.config import scenario_from_dict
    from dextar.errors import ConfigError

    for motors, word in (({"rms_torque": 0.3}, r"\[motors\]\.peak_torque is required"),
                         ({"peak_torque": 0.5, "knee_speed_rpm": 60},
                          r"\[motors\]\.knee_speed_rpm needs max_speed_rpm"),
                         ({"peak_torque": 0.5, "max_speed_rpm": 50, "knee_speed_rpm": 60},
                          r"must be below max_speed_rpm"),
                         ({"peak_torque": -1.0}, r"\[motors\]\.peak_torque must be positive")):
        with pytest.raises(ConfigError, match=word):
            scenario_from_dict({**MOTORS, "motors": motors})


def test_a_graded_grid_holds_the_limits_and_converges_with_the_uniform_one():
    """A grid of arc lengths finer at one end: the limits hold on a dense sampling, and its
    duration lies between the uniform grids of its coarsest and finest steps (the
    discretisation's loss grows with the step)."""
    S = SEMI.length
    u = np.linspace(0.0, 1.0, 301)
    s = S * (0.4 * u + 0.6 * u**2)  # steps from 0.4 S/300 to 1.6 S/300
    graded = solve_time_optimal_law(MODEL, SEMI, torque_limit=(20.0, 20.0), grid=s)
    fine = solve_time_optimal_law(MODEL, SEMI, torque_limit=(20.0, 20.0), grid=750)
    coarse = solve_time_optimal_law(MODEL, SEMI, torque_limit=(20.0, 20.0), grid=187)
    np.testing.assert_allclose(graded.knots_s, s, rtol=0, atol=1e-12 * S)
    assert graded.success and "300 segments of" in graded.message and " to " in graded.message
    assert fine.duration < graded.duration < coarse.duration
    ratio = peak_torque(MODEL, SEMI, graded, n=8001) / 20.0
    assert ratio.max() <= 1 + 1e-3 and ratio.max() > 0.99


@pytest.mark.parametrize("grid, words", [
    (5, "at least 10 segments"), (50.5, "whole number"),
    (np.nan, "whole number"), (np.inf, "whole number"), (None, "whole number"),
    ("400", "whole number"), (True, "whole number"),
    (np.linspace(0.0, 1.0, 8), "at least 11 points"),
    (np.r_[0.0, 0.5, 0.4, np.linspace(0.6, SEMI.length, 10)], "strictly increasing"),
    (np.linspace(0.1, SEMI.length, 20), "from 0 to the path's length"),
    (np.linspace(0.0, 2 * SEMI.length, 20), "from 0 to the path's length"),
    (np.r_[np.linspace(0.0, 1.0, 12), np.nan, SEMI.length], "finite")])
def test_bad_grids_are_named(grid, words):
    """(NaN, infinity and None raised Python's own errors, not the package's.)"""
    with pytest.raises(dx.DextarError, match=words):
        solve_time_optimal_law(MODEL, SEMI, torque_limit=(20.0, 20.0), grid=grid)


@pytest.mark.parametrize("grid", [400, 400.0, np.int64(400), np.array(400)])
def test_a_whole_grid_of_any_number_type_is_taken(grid):
    """A whole float, a numpy integer or a 0-d array is a number of segments."""
    law = solve_time_optimal_law(MODEL, SEMI, torque_limit=(20.0, 20.0), grid=grid)
    assert law.success and law.knots_s.size >= 401


@pytest.mark.parametrize("third, words", [
    (dict(max_jerk=(3000.0, 2500.0)), "max_jerk (3000, 2500) rad/s^3"),
    (dict(max_torque_rate=(40.0, 40.0)), "max_torque_rate (40, 40) N m/s")])
def test_a_third_order_limit_is_refused_by_the_second_order_law(third, words):
    """The second-order law cannot hold a jerk or torque-rate limit: it says so and names
    the law that can (its check had measured the jerk, 2e12 times over, and asked for a
    finer grid, which never helps); the same motors without it plan."""
    from dextar.errors import ParameterError
    from dextar.motors import MotorLimits

    with pytest.raises(ParameterError, match=re.escape(words) + ".*solve_jerk_limited_law"):
        solve_time_optimal_law(MODEL, SEMI, motors=MotorLimits((20.0, 20.0), **third))
    assert solve_time_optimal_law(MODEL, SEMI, motors=MotorLimits((20.0, 20.0))).status == 0


def test_the_grid_is_refined_where_the_check_finds_an_excess():
    """A corner blended within 7.4 mm (a 2 mm quintic between two lines) on 400 equal
    segments: the segments where the check samples exceed the torque limit are split, and
    the law uses its torque (ratio 1.0002) within 2 % of the law on 6400 segments (0.1946
    against 0.1914 s). Tightening alone (no split) used 63 % of the torque and took 0.56 s,
    three times as long, with status 0."""
    from dextar.config import load_scenario
    from dextar.dynamics import RobotAlongPath
    from dextar.laws import solve_time_optimal_law as solve
    from dextar.motors import MotorLimits
    from dextar.paths.composite import blended

    from ..program.test_program import EXAMPLES

    model = load_scenario(str(EXAMPLES / "jerk_pick_place.toml")).si_model
    path, _ = blended((Line((-0.0681, 0.176), (0.0367, 0.1868)),
                       Line((0.0367, 0.1868), (-0.0246, 0.193))), (0.00736,))
    dyn = RobotAlongPath(model, path, "+-")
    motors = MotorLimits((1.5, 1.5))
    law, fine = solve(dyn, motors=motors, grid=400), solve(dyn, motors=motors, grid=6400)
    assert law.status == fine.status == 0
    assert law.max_torque_ratio >= 0.98, law.message  # (0.63 without the split)
    assert law.duration <= 1.02 * fine.duration, (law.duration, fine.duration)  # (2.9 x)
    assert len(law.knots_s) > 401  # (split where the excess was)


def test_a_refined_grid_without_motion_goes_back_to_the_grid_before(monkeypatch):
    """Where the refined grid finds no motion (its friction tangent interpolated) but the grid
    before found one, the law goes back to that grid and tightens the limits as without a
    split (never a new "no motion"): the same law as with the split off."""
    from dextar.config import load_scenario
    from dextar.dynamics import RobotAlongPath
    from dextar.errors import InfeasibleError
    from dextar.laws import solve_time_optimal_law as solve
    from dextar.laws import time_optimal
    from dextar.motors import MotorLimits
    from dextar.paths.composite import blended

    from ..program.test_program import EXAMPLES

    model = load_scenario(str(EXAMPLES / "jerk_pick_place.toml")).si_model
    path, _ = blended((Line((-0.0681, 0.176), (0.0367, 0.1868)),
                       Line((0.0367, 0.1868), (-0.0246, 0.193))), (0.00736,))
    dyn = RobotAlongPath(model, path, "+-")
    motors = MotorLimits((1.5, 1.5))
    monkeypatch.setattr(time_optimal, "MAX_SPLIT", 0)
    plain = solve(dyn, motors=motors, grid=400)
    monkeypatch.setattr(time_optimal, "MAX_SPLIT", 2)
    real = time_optimal._reachability

    def none_when_refined(co, *a, **kw):
        if len(co.s) > 401:
            raise InfeasibleError("no motion on the refined grid")
        return real(co, *a, **kw)

    monkeypatch.setattr(time_optimal, "_reachability", none_when_refined)
    law = solve(dyn, motors=motors, grid=400)
    assert law.status == plain.status == 0
    assert law.duration == plain.duration and len(law.knots_s) == 401


@pytest.mark.parametrize("excess, split", [(0.005, False), (0.05, True)])
def test_a_small_excess_is_tightened_and_a_large_one_split(monkeypatch, excess, split):
    """The check's first ratio made ``1 + excess`` in one segment: at most 1e-2 over, the
    limits are tightened (two solves, the grid as given: splitting every excess slowed the
    design sweep by 16 %); above it, that segment is split."""
    from dextar.laws import time_optimal

    real, real_ratios = time_optimal._segment_ratios, time_optimal.ratios_by_kind
    first = {"segments": True, "ratios": True}  # (each faked at its first call only)

    def once(cons, js, n):
        out = real(cons, js, n)
        if first.pop("segments", False):
            out[n // 2] = 1 + excess
        return out

    def ratios(cons, js):
        out = dict(real_ratios(cons, js))
        if first.pop("ratios", False):
            out["torque"] = 1 + excess
        return out

    monkeypatch.setattr(time_optimal, "_segment_ratios", once)
    monkeypatch.setattr(time_optimal, "ratios_by_kind", ratios)
    law = solve_time_optimal_law(MODEL, SEMI, torque_limit=(20.0, 20.0), grid=400)
    assert law.status == 0
    assert (len(law.knots_s) > 401) == split, len(law.knots_s)
    assert ("tightened" in law.message) != split, law.message


def test_an_unchecked_law_is_the_reachability_law_and_says_so():
    """``check=False`` (a start for another law): the law the check would have kept where it
    passes (the same knots), never sampled through the exact model, status 2 and "not
    checked"; the checked one's status 0. A grid too coarse for the check (it tightens the
    limits) gives a faster unchecked law than the checked one, which holds them."""
    from dextar.dynamics import RobotAlongPath
    from dextar.laws import time_optimal

    class Counted:
        def __init__(self, dyn):
            self.dyn, self.length, self.sampled = dyn, dyn.length, 0

        def coefficients(self, s):
            return self.dyn.coefficients(s)

        def samples(self, law, times):
            self.sampled += 1
            return self.dyn.samples(law, times)

    dyn = Counted(RobotAlongPath(MODEL, SEMI, "+-"))
    checked = time_optimal.solve_time_optimal_law(dyn, torque_limit=(20.0, 20.0), grid=400)
    assert checked.status == 0 and "tightened" not in checked.message and dyn.sampled > 0
    dyn.sampled = 0
    draft = time_optimal.solve_time_optimal_law(dyn, torque_limit=(20.0, 20.0), grid=400,
                                                check=False)
    assert draft.status == 2 and draft.message.startswith("not checked")
    assert dyn.sampled == 0
    np.testing.assert_array_equal(draft.knots_v, checked.knots_v)
    coarse = time_optimal.solve_time_optimal_law(dyn, torque_limit=(20.0, 20.0), grid=12)
    rough = time_optimal.solve_time_optimal_law(dyn, torque_limit=(20.0, 20.0), grid=12,
                                                check=False)
    assert coarse.status == 0 and "tightened" in coarse.message
    assert rough.status == 2 and rough.duration < coarse.duration
