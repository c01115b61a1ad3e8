"""Robot programs: the examples plan within the motors, the setpoints are consistent (finite
differences, sizing, a PD loop on our forward dynamics tracks them), mode changes cross a
serial singularity, and bad programs are refused by name."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from dextar.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
COLUMNS = ["t_s", "move", "x_mm", "y_mm", "phi_rad", "psi_rad", "dphi_rad_s", "dpsi_rad_s",
           "ddphi_rad_s2", "ddpsi_rad_s2", "tau1_Nm", "tau2_Nm"]


def read(path):
    with open(path) as fh:
        rows = list(csv.reader(fh))
    return rows[0], np.array(rows[1:], float)


@pytest.fixture(scope="session")
def pick_place(tmp_path_factory):
    out = tmp_path_factory.mktemp("pp") / "out"
    assert main(["program", "--no-figures", str(EXAMPLES / "pick_place.toml"), "--out", str(out),
                 "--quiet"]) == 0
    assert not [*out.glob("*.png"), *out.glob("*.svg"), *out.glob("*.html")]  # --no-figures
    head, data = read(out / "setpoints.csv")
    return dict(zip(head, data.T, strict=True)), json.loads((out / "summary.json").read_text())


@pytest.mark.slow
def test_figures_and_report_are_written(pick_place_program):
    from html.parser import HTMLParser

    out = pick_place_program  # (exit 0: tests/conftest.py)
    for name in ("moves", "motion", "operating_points"):
        assert (out / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert (out / f"{name}.svg").read_text().rstrip().endswith("</svg>")

    class Imgs(HTMLParser):
        def __init__(self):
            super().__init__()
            self.n = 0

        def handle_starttag(self, tag, attrs):
            self.n += tag == "img"

    p = Imgs()
    report = (out / "report.html").read_text()
    p.feed(report)
    assert p.n == 3 and "fits the motors" in report and "Motor sizing" in report


def test_setpoints_columns_and_time_grid(pick_place):
    cols, s = pick_place
    assert list(cols) == COLUMNS
    t = cols["t_s"]
    assert t[0] == 0.0 and np.allclose(np.diff(t), 1e-3) and t[-1] >= s["cycle_time_s"]
    assert t[-1] - s["cycle_time_s"] < 1e-3
    assert s["status"] == "fits" and len(s["moves"]) == 8 and s["violations"] == []
    starts = [m["start_s"] for m in s["moves"]]
    assert starts == sorted(starts) and s["moves"][0]["start_s"] == 0.0
    assert sum(m["duration_s"] for m in s["moves"]) == pytest.approx(s["cycle_time_s"])


def test_rates_are_the_derivatives_of_the_angles(pick_place):
    cols, _ = pick_place
    t = cols["t_s"]
    for q, dq in (("phi_rad", "dphi_rad_s"), ("psi_rad", "dpsi_rad_s")):
        fd = np.gradient(cols[q], t)
        scale = np.abs(cols[dq]).max()
        # away from the instants where the acceleration jumps (time-optimal knots, move ends)
        assert np.median(np.abs(fd - cols[dq])) < 1e-3 * scale
        assert np.quantile(np.abs(fd - cols[dq]), 0.99) < 2e-2 * scale


def test_sizing_recomputed_from_the_setpoints(pick_place):
    cols, s = pick_place
    t = cols["t_s"]
    for i, m in enumerate(s["motors"]):
        tau, dq = cols[f"tau{i + 1}_Nm"], cols[("dphi_rad_s", "dpsi_rad_s")[i]]
        assert m["peak_torque_Nm"] == pytest.approx(np.abs(tau).max())
        rms = np.sqrt(np.trapezoid(tau**2, t) / t[-1])
        assert m["rms_torque_Nm"] == pytest.approx(rms, rel=1e-9)
        assert m["peak_speed_rad_s"] == pytest.approx(np.abs(dq).max())
        assert m["energy_J"] == pytest.approx(np.trapezoid(np.maximum(tau * dq, 0), t), rel=1e-9)
        assert m["peak_torque_ratio"] <= 1 + 1e-3 and m["peak_speed_ratio"] <= 1 + 1e-3
    # the thresholds of "fits" as the sizing applies them, stated with the result
    from dextar.program.sizing import SIZING_TOL, SIZING_TOL_RATES

    assert s["tolerances"] == {"other": SIZING_TOL, **SIZING_TOL_RATES} == {
        "other": 1e-3, "jerk": 1e-2, "torque_rate": 1e-2}


def test_dwell_holds_still_against_gravity(pick_place):
    cols, s = pick_place
    dwell = s["moves"][1]
    sel = (cols["t_s"] > dwell["start_s"] + 1e-3) & (cols["t_s"] < dwell["start_s"]
                                                    + dwell["duration_s"] - 1e-3)
    assert sel.sum() > 150
    assert np.abs(cols["dphi_rad_s"][sel]).max() == 0.0
    assert np.ptp(cols["tau1_Nm"][sel]) < 1e-12 and abs(cols["tau1_Nm"][sel][0]) > 1e-3


@pytest.mark.slow
def test_pd_loop_on_our_forward_dynamics_tracks_the_setpoints(tmp_path):
    """A drive with the setpoints' feedforward torques and a soft PD loop (which cannot hide
    a wrong feedforward) tracks the mode-change program on our forward dynamics; the same
    loop with the feedforward 10 % off does not."""
    from dextar.config import load_scenario
    from dextar.dynamics import Model
    from dextar.dynamics.forward import forward_dynamics

    out = tmp_path / "mc"
    cfg = EXAMPLES / "mode_change.toml"
    assert main(["program", "--no-figures", str(cfg), "--out", str(out), "--quiet"]) == 0
    head, data = read(out / "setpoints.csv")
    c = dict(zip(head, data.T, strict=True))
    m = load_scenario(str(cfg)).si_model
    model = Model(m.robot, m.inertia, "up", tol=0.0)
    t = c["t_s"]
    q_sp = np.stack([c["phi_rad"], c["psi_rad"]], -1)
    dq_sp = np.stack([c["dphi_rad_s"], c["dpsi_rad_s"]], -1)
    tau_sp = np.stack([c["tau1_Nm"], c["tau2_Nm"]], -1)
    kp, kd = 20.0, 0.3  # N m/rad, N m s/rad: a soft position loop (~70 Hz on the rods)

    def error(gain):
        def torque(time, q, dq):
            # the drive interpolates between the 1 kHz setpoints (feedforward and references)
            k = min(int(time * 1000.0), len(t) - 2)
            f = (time - t[k]) / (t[k + 1] - t[k])
            qs = q_sp[k] + f * (q_sp[k + 1] - q_sp[k])
            dqs = dq_sp[k] + f * (dq_sp[k + 1] - dq_sp[k])
            ff = tau_sp[k] + f * (tau_sp[k + 1] - tau_sp[k])
            return gain * ff + kp * (qs - q) + kd * (dqs - dq)

        res = forward_dynamics(model, torque, q_sp[0], dq_sp[0], t, rtol=1e-5, atol=1e-10,
                               method="RK45", max_step=1e-3)
        assert res.success
        return np.abs(res.q - q_sp).max()

    # measured: 5.4e-4 rad with the setpoints' feedforward (the 1 ms interpolation), 2.8e-3
    # rad with it 10 % off (the loop alone holds 2.6e-3 rad of the error); both to 1e-6 of
    # the integrator's tolerance, deterministic
    assert error(1.0) < 1e-3
    assert error(1.1) > 2e-3


def test_mode_change_crosses_a_serial_singularity_smoothly(tmp_path):
    out = tmp_path / "mc"
    assert main(["program", "--no-figures", str(EXAMPLES / "mode_change.toml"), "--out", str(out),
                 "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    joint = s["moves"][1]
    assert joint["type"] == "joint" and joint["min_type1_distance"] < 0.02
    assert joint["min_type2_distance"] > 0.1
    _, data = read(out / "setpoints.csv")
    assert np.isfinite(data).all() and np.abs(np.diff(data[:, 4:6], axis=0)).max() < 0.05


PROGRAM = ('[motors]\npeak_torque = 0.5\nmax_speed_rpm = 120\n[gravity]\nvector = [0.0, -9810.0]\n'
           '[inertia]\neffector_mass = 0.08\nproximal_mass = 0.03\ndistal_mass = 0.02\n'
           '[program]\nstart = [0.0, 100.0]\n')


@pytest.mark.parametrize("moves, words", [
    ('[[move]]\ntype = "line"\nto = [0.0, 300.0]\n', "move 0 (line): the path leaves the "
     "workspace"),
    ('[[move]]\ntype = "arc"\nvia = [10.0, 100.0]\nto = [20.0, 100.0]\n',
     "move 0 (arc): the start, 'via' and 'to' points are collinear"),
    ('[[move]]\ntype = "jump"\n', "[[move]] 0 (jump).type must be one of line, arc, dwell, "
     "joint"),
    ('', "the task has no move"),
    ('[[move]]\ntype = "line"\nto = [10.0, 110.0]\nblend = 5.0\n[[move]]\ntype = "line"\n'
     'to = [0.0, 100.0]\n', "move 0 (line), blended with move 1: the blend at the end of move "
     "0, (10, 110) mm, into move 1: the path turns back"),
    # (the corner named in a longer chain: the move whose blend to change, its end in mm)
    ('[[move]]\ntype = "line"\nto = [10.0, 110.0]\nblend = 2.0\n[[move]]\ntype = "line"\n'
     'to = [10.0, 130.0]\nblend = 2.0\n[[move]]\ntype = "line"\nto = [10.0, 115.0]\n',
     "move 1 (line), in the motion blended from move 0: the blend at the end of move 1, "
     "(10, 130) mm, into move 2: the path turns back by 180.0 deg"),
    ('[[move]]\ntype = "joint"\nto_deg = [0.0, 180.0]\nlaw = "min-jerk"\n',
     "move 0 (joint): at t = "),
    ('[[move]]\ntype = "joint"\nto_deg = [0.0, 180.0]\nlaw = "min-jerk"\n',
     "crosses a parallel (type 2) singularity"),
])
def test_bad_programs_named(tmp_path, capsys, moves, words):
    cfg = tmp_path / "p.toml"
    cfg.write_text(PROGRAM + moves)
    code = main(["program", str(cfg), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and words in err and err.count("\n") == 1, err
    assert not (tmp_path / "o" / "setpoints.csv").exists()


def test_dwell_beyond_the_motors_is_refused(tmp_path, capsys):
    cfg = tmp_path / "p.toml"
    cfg.write_text(PROGRAM.replace("peak_torque = 0.5", "peak_torque = 0.01")
                   + '[[move]]\ntype = "dwell"\ntime = 0.5\n')
    assert main(["program", str(cfg), "--out", str(tmp_path / "o")]) == 2
    assert "move 0 (dwell): the motor at" in capsys.readouterr().err


def test_a_program_that_exceeds_the_motors_exits_1_with_its_files(tmp_path, capsys):
    cfg = tmp_path / "p.toml"
    cfg.write_text(PROGRAM + '[[move]]\ntype = "line"\nto = [30.0, 120.0]\nlaw = "min-jerk"\n'
                   'duration = 0.01\n')
    out = tmp_path / "o"
    assert main(["program", "--no-figures", str(cfg), "--out", str(out), "--json"]) == 1
    io = capsys.readouterr()
    s = json.loads(io.out)
    assert s["status"] == "exceeds" and s["violations"][0]["move"] == 0
    assert {"motor", "quantity", "value", "limit", "move", "t_s"} <= set(s["violations"][0])
    assert "above its limit" in io.err
    assert (out / "setpoints.csv").exists() and (out / "summary.json").exists()


def test_blended_corners_do_not_stop(pick_place):
    cols, s = pick_place
    up, over, down = s["moves"][2], s["moves"][3], s["moves"][4]
    assert up["blended_with_next"] and over["blended_with_next"]
    assert not down["blended_with_next"]
    for corner in (over["start_s"], down["start_s"]):  # where the blends hand over
        k = int(np.argmin(np.abs(cols["t_s"] - corner)))
        speed = np.hypot(np.gradient(cols["x_mm"], cols["t_s"]), np.gradient(cols["y_mm"],
                                                                             cols["t_s"]))
        assert speed[k] > 50.0  # mm/s: moving through the corner
    # position and velocity continuous across the chain (no jump between setpoints)
    sel = (cols["t_s"] >= up["start_s"]) & (cols["t_s"] <= down["start_s"] + down["duration_s"])
    dx = np.diff(cols["x_mm"][sel])
    dv = np.diff(cols["dphi_rad_s"][sel])
    amax = np.abs(cols["ddphi_rad_s2"][sel]).max()
    assert np.abs(dx).max() < 1.0 and np.abs(dv).max() <= 1.01 * amax * 1e-3
    # the move column follows the pieces of the chain
    moves = cols["move"][sel]
    assert set(np.unique(moves)) == {2.0, 3.0, 4.0} and np.all(np.diff(moves) >= 0)


def test_a_blend_rounds_the_corner_within_its_radius():
    from dextar.paths import Arc, Line
    from dextar.paths.composite import blended

    a, b = Line((-40.0, 110.0), (-40.0, 90.0)), Line((-40.0, 90.0), (0.0, 90.0))
    path, owner = blended([a, b], [5.0])
    assert owner == [0, 0, 1]
    blend = path.pieces[1].position(np.linspace(0, 1, 201))
    assert np.linalg.norm(blend - np.array([-40.0, 90.0]), axis=1).max() <= 5.0 + 1e-9
    s = np.linspace(0, path.length, 4001)
    p = path.parameter_at(s)
    _, r1, _, _ = path.derivatives(p)
    tangent = r1 / np.linalg.norm(r1, axis=1)[:, None]
    kappa = path.curvature(p)[0]
    assert np.abs(np.diff(tangent, axis=0)).max() < 0.01  # G1
    for sj in path._starts[1:-1]:  # G2: the curvature has no jump at the joins
        k_before, k_after = path.curvature(path.parameter_at([sj - 1e-7, sj + 1e-7]))[0]
        assert abs(k_before - k_after) < 1e-4 * np.abs(kappa).max()
    np.testing.assert_allclose(path.arc_length(p), s, atol=1e-9)
    # into an arc too, and a reversal is refused
    c = Arc(20.0, 0.0, np.pi / 2, center=(-20.0, 90.0))
    blended([Line((-0.0, 60.0), (0.0, 90.0)), c], [4.0])
    with pytest.raises(Exception, match="turns back"):
        blended([a, Line((-40.0, 90.0), (-40.0, 100.0))], [5.0])
    with pytest.raises(Exception, match="do not fit"):
        blended([a, b], [25.0])


def test_a_chain_takes_the_law_of_its_first_move(tmp_path, capsys):
    cfg = tmp_path / "p.toml"
    cfg.write_text(PROGRAM + '[[move]]\ntype = "line"\nto = [20.0, 110.0]\nblend = 3.0\n'
                   '[[move]]\ntype = "line"\nto = [20.0, 130.0]\nlaw = "min-jerk"\n')
    assert main(["program", str(cfg), "--out", str(tmp_path / "o")]) == 2
    assert "blend makes it one motion" in capsys.readouterr().err


@pytest.mark.slow
def test_the_docs_program_plans_within_the_motors(tmp_path):
    """The task file the docs' programs guide shows (examples/program_tour.toml: a tight
    blended turn, time-optimal under a steep torque-speed envelope) plans, and its setpoints
    stay within the motors (a missed torque peak between the law's check samples once made it
    exceed by 16 %)."""
    guide = (EXAMPLES.parent / "docs" / "guides" / "programs.rst").read_text()
    assert "examples/program_tour.toml" in guide  # the file the guide shows
    out = tmp_path / "o"
    assert main(["program", "--no-figures", str(EXAMPLES / "program_tour.toml"), "--out",
                 str(out), "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "fits" and s["moves"][0]["blended_with_next"]
    assert all(m["peak_torque_ratio"] <= 1 + 1e-3 for m in s["motors"])


def test_fit_by_time_scaling_equals_resampling():
    """For a law that only stretches with its duration (min-jerk), the motors' ratio at any
    duration from one sampling equals the ratio of the law resampled at that duration; the
    shortcut declines a law whose shape changes with the duration (the optimal law)."""
    from dextar.config import load_scenario
    from dextar.dynamics import Model, inverse_dynamics
    from dextar.laws import LawRequest, law_type
    from dextar.paths import Line
    from dextar.program.laws import stretched_ratio
    from dextar.trajectory import sample_trajectory
    from dextar.units import SI

    sc = load_scenario(EXAMPLES / "pick_place.toml")
    m = sc.si_model
    model = Model(m.robot, m.inertia, "up")
    motors = sc.si_motors
    path = Line((-0.04, 0.09), (0.04, 0.12))

    def traj(law, times=None):
        return sample_trajectory(m.robot, path, law, mode=sc.mode, samples=401, times=times,
                                 units=SI)

    for name, extra in (("min-jerk", {}), ("optimal", {"eta": 0.1})):
        def build(T, name=name, extra=extra):
            return law_type(name).build(LawRequest(path, {"duration": T, **extra}, 0.13, None,
                                                   SI))

        fast = stretched_ratio(build, traj, model, motors)
        if name == "optimal":
            assert fast is None
            continue
        for T in (0.05, 0.3, 2.0):
            tr = traj(build(T))
            ref = max(motors.ratios(inverse_dynamics(model, tr.q, tr.dq, tr.ddq), tr.dq))
            assert fast(T) == pytest.approx(ref, rel=1e-9)


def test_chain_grid_resolves_each_blend_and_keeps_the_joints():
    """A blended chain is one motion with ``grid`` segments shared by length; each blend gets
    at least 20, each piece at least 10, and every piece starts on a grid point."""
    from dextar.paths import Arc, Line
    from dextar.paths.composite import Quintic, blended
    from dextar.program.plan import BLEND_SEGMENTS, chain_grid

    pieces = [Line((-40.0, 90.0), (-40.0, 110.0)),
              Arc(40.0, -np.pi, 0.0, center=(0.0, 110.0), clockwise=True),  # over the top
              Line((40.0, 110.0), (40.0, 90.0))]
    path, _ = blended(pieces, [5.0, 5.0])
    for grid in (30, 100, 400):
        s = chain_grid(path, grid)
        assert s[0] == 0.0 and s[-1] == path.length and np.all(np.diff(s) > 0)
        starts = path.starts
        assert np.abs(s[:, None] - starts[None, :]).min(axis=0).max() <= 1e-12 * path.length
        for k, piece in enumerate(path.pieces):
            inside = ((s > starts[k] + 1e-12) & (s <= starts[k + 1] + 1e-12)).sum()
            least = BLEND_SEGMENTS if isinstance(piece, Quintic) else 10
            share = int(np.ceil(grid * piece.length / path.length))
            assert inside == max(least, share)


@pytest.mark.parametrize("T0", [3e-4, 0.0371, 0.05, 0.7, 123.0])
def test_shortest_duration_within_the_limits_is_bracketed(T0):
    """The fitted duration is the smallest T with ratio(T) <= 1 to 1e-6, on the feasible side,
    for a smooth ratio, one with a kink and one infinite below a speed limit."""
    from dextar.program.laws import shortest_within

    for ratio in (lambda T: (T0 / T) ** 2,
                  lambda T: max((T0 / T) ** 2, 0.5 + 0.5 * T0 / T),
                  lambda T: np.inf if T < 0.9 * T0 else (T0 / T) ** 3):
        T = shortest_within(ratio)
        assert ratio(T) <= 1.0 and T0 <= T <= T0 * (1 + 2e-6), (T0, T)


def test_no_speed_ratio_without_a_speed_limit(tmp_path, capsys):
    """A ratio to a limit the program does not set is left out of the summary and shown as
    "-" in the report (it was written as 0); with the limit set it is the peak speed over it.
    The words name every file written: the report and the figures too, unless --no-figures."""
    cfg = tmp_path / "task.toml"
    text = ('[motors]\npeak_torque = 3.4\n[program]\nstart = [-40.0, 110.0]\n'
            '[[move]]\ntype = "line"\nto = [40.0, 110.0]\n')
    cfg.write_text(text)
    assert main(["program", str(cfg), "--out", str(tmp_path / "a")]) == 0
    for m in json.loads((tmp_path / "a" / "summary.json").read_text())["motors"]:
        assert "peak_speed_ratio" not in m, m
        assert m["peak_speed_rad_s"] > 1.0
    assert ("peak speed / maximum speed</td><td>-</td><td>-</td>"
            in (tmp_path / "a" / "report.html").read_text())
    wrote = capsys.readouterr().out.splitlines()[-1]
    assert "report.html" in wrote and "operating_points" in wrote, wrote
    assert (tmp_path / "a" / "operating_points.svg").is_file()
    cfg.write_text(text.replace("peak_torque = 3.4\n", "peak_torque = 3.4\nmax_speed_rpm = 300\n"))
    assert main(["program", str(cfg), "--out", str(tmp_path / "b"), "--no-figures"]) == 0
    wrote = capsys.readouterr().out.splitlines()[-1]
    assert "report.html" not in wrote and wrote.endswith("summary.json"), wrote
    for m in json.loads((tmp_path / "b" / "summary.json").read_text())["motors"]:
        assert m["peak_speed_ratio"] == pytest.approx(m["peak_speed_rad_s"] / (300 * np.pi / 30))


def test_each_move_of_a_blended_chain_has_its_own_singularity_distances():
    """A chain's moves each report their smallest distances along their own stretch of the
    path (they all reported the chain's): here the second line reaches out towards the
    boundary of the workspace, the first stays inside it. Each move's figure lies between
    the smallest over its own setpoints' poses and the smallest with a setpoint either side
    (the setpoints, 1 ms apart, straddle where the moves meet), to 2e-3 (the checked poses'
    spacing; measured: the first move's type-1 figure 0.9324 between 0.9299 and 0.9408)."""
    from dextar.dynamics import paper_inertia
    from dextar.geometry import DEXTAR_MM
    from dextar.kinematics.checker import pose_distances
    from dextar.motors import MotorLimits
    from dextar.program import Move, plan_program

    robot = DEXTAR_MM.scaled(1e-3)
    res = plan_program(robot, paper_inertia(robot).scaled_masses(0.1),
                       [Move("line", {"to": (0.0, 0.12)}, blend=0.008),
                        Move("line", {"to": (0.0, 0.15)})], start=(-0.04, 0.11),
                       working_mode="+-", motors=MotorLimits((2.0, 2.0)))
    timing = res.timeline()
    assert [m.blended_with_next for m in timing] == [True, False]
    own = []
    for m in timing:
        at = np.flatnonzero(res.move_index == m.index)
        d = pose_distances(robot, res.q[at], res.P[at])
        wide = np.arange(max(at[0] - 1, 0), min(at[-1] + 2, len(res.t)))
        w = pose_distances(robot, res.q[wide], res.P[wide])
        own.append((float(d.type1.min()), float(d.type2.min())))
        for got, lo, hi in ((m.min_type1_distance, w.type1.min(), own[-1][0]),
                            (m.min_type2_distance, w.type2.min(), own[-1][1])):
            assert lo - 2e-3 <= got <= hi + 2e-3, (m.index, got, lo, hi)
    # the two moves' figures differ by far more than that: the check can tell them apart
    assert own[0][0] - own[1][0] > 0.05 or own[0][1] - own[1][1] > 0.05, own


def test_a_key_a_move_type_does_not_know_is_refused_by_name():
    """Move's values hold its type's keys only: a key there that the type does not read
    (a blend passed among them, a misspelling) was ignored, the move planned without it."""
    from dextar.dynamics import paper_inertia
    from dextar.errors import ParameterError
    from dextar.geometry import DEXTAR_MM
    from dextar.motors import MotorLimits
    from dextar.program import Move, plan_program

    robot = DEXTAR_MM.scaled(1e-3)

    def plan(*moves):
        return plan_program(robot, paper_inertia(robot).scaled_masses(0.1), list(moves),
                            start=(-0.04, 0.11), working_mode="+-",
                            motors=MotorLimits((2.0, 2.0)))

    first = Move("line", {"to": (-0.03, 0.11)})
    with pytest.raises(ParameterError, match=r"move 1 \(line\): 'blend' is not a key of a "
                       r"line move; its keys: assembly_mode, to, working_mode \(blend is an "
                       r"argument of Move itself"):
        plan(first, Move("line", {"to": (0.0, 0.12), "blend": 0.008}))
    with pytest.raises(ParameterError, match=r"move 0 \(dwell\): 'to' is not a key"):
        plan(Move("dwell", {"time": 0.1, "to": (0.0, 0.1)}), first)
    # the config's name of a key whose SI value a Move holds under another
    with pytest.raises(ParameterError, match=r"'to_deg' is not a key of a joint move; its "
                       r"keys: .*to_q.* \(to_deg is the config's key; a Move takes to_q, in SI\)"):
        plan(Move("joint", {"to_deg": (60.0, 120.0)}))
    # the same moves with the keys in their places plan
    res = plan(Move("line", {"to": (-0.03, 0.11)}, blend=0.004), Move("line", {"to": (0.0, 0.12)}),
               Move("dwell", {"time": 0.1}))
    assert [m.blended_with_next for m in res.timeline()] == [True, False, False]
