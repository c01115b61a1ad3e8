"""Programs with jerk limits, drive units and a cycle fitted within the RMS ratings: the
limits on every written sample (the example and another geometry), csp.csv and pvt.csv
reconstructing setpoints.csv, fit-rms at the rating and a shorter cycle beyond it, and bad
input named."""

import csv
import json

import numpy as np
import pytest

from dextar.cli import main

from .test_program import EXAMPLES

LIMITS = "max_acceleration = 60.0\nmax_jerk = 3000.0\n"
DRIVE = ('[drive]\ngear_ratio = 353.5\nencoder_counts = 4096\nrated_torque_Nm = 0.0115\n'
         'pvt_period_ms = 10\n')
#: The encoders' zeros (the joint angles at which they read 0), as calibration writes them.
OFFSET = 'encoder_offset_deg = [90.0, 0.0]\n'


def columns(path):
    with open(path) as fh:
        rows = list(csv.reader(fh))
    data = np.array(rows[1:], float)
    return dict(zip(rows[0], data.T, strict=True))


def task(extra_motors="", tables="", program="", moves=None):
    text = (EXAMPLES / "pick_place.toml").read_text()
    text = text.replace("knee_speed_rpm = 1 ", extra_motors + "knee_speed_rpm = 1 ")
    if "[drive]" in tables:
        text = text.replace('working_mode = "+-"\n', 'working_mode = "+-"\n' + OFFSET, 1)
    head, sep, rest = text.partition("[[move]]")
    if moves is not None:
        rest = moves
    head = head.replace('law = "time-optimal"\n', 'law = "time-optimal"\n' + program)
    return head + tables + "\n" + sep + rest


@pytest.fixture(scope="session")
def smooth(tmp_path_factory):
    d = tmp_path_factory.mktemp("smooth")
    cfg = d / "pp.toml"
    cfg.write_text(task(LIMITS, DRIVE))
    assert main(["program", "--no-figures", str(cfg), "--out", str(d / "o"), "--quiet"]) == 0
    return d / "o"


def check_limits(sp, amax, jmax, peak, wmax, moves):
    t = sp["t_s"]
    ddq = np.stack([sp["ddphi_rad_s2"], sp["ddpsi_rad_s2"]], -1)
    jerk = np.diff(ddq, axis=0) / np.diff(t)[:, None]
    assert np.abs(jerk).max() <= jmax * (1 + 1e-2)
    assert np.abs(jerk).max() > 0.9 * jmax  # the jerk limit is used
    assert np.abs(ddq).max() <= amax * (1 + 1e-3)
    tau = np.stack([sp["tau1_Nm"], sp["tau2_Nm"]], -1)
    assert np.abs(tau).max() <= peak * (1 + 1e-3)
    dq = np.stack([sp["dphi_rad_s"], sp["dpsi_rad_s"]], -1)
    assert np.abs(dq).max() <= wmax * (1 + 1e-3)
    # every motion starts and ends at rest with zero acceleration: within a tick of its ends
    # the acceleration is at most one tick of jerk
    dt = t[1] - t[0]
    ends = [0.0] + [m["start_s"] + m["duration_s"] for m in moves
                    if not m["blended_with_next"]]
    for te in ends:
        near = np.abs(t - te) <= dt * (1 + 1e-9)
        assert np.abs(ddq[near]).max() <= jmax * dt * 1.02


@pytest.mark.slow
def test_jerk_limits_hold_on_every_written_sample(smooth):
    sp = columns(smooth / "setpoints.csv")
    s = json.loads((smooth / "summary.json").read_text())
    check_limits(sp, 60.0, 3000.0, 3.4, 30 * 2 * np.pi / 60, s["moves"])
    assert s["status"] == "fits"
    assert all(m["peak_jerk_ratio"] <= 1 + 1e-2 for m in s["motors"])


def test_jerk_limits_on_another_geometry(tmp_path):
    cfg = tmp_path / "other.toml"
    other = task("max_acceleration = 40.0\nmax_jerk = 1500.0\n", moves=(
        '\ntype = "line"\nto = [30.0, 150.0]\n[[move]]\ntype = "joint"\nto = [-30.0, 120.0]\n'))
    other = other.replace('preset = "dextar"', 'l1 = 70.0\nl2 = 70.0\nL1 = 110.0\nL2 = 110.0\n'
                          'd = 60.0')
    cfg.write_text(other)
    assert main(["program", "--no-figures", str(cfg), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    check_limits(columns(tmp_path / "o" / "setpoints.csv"), 40.0, 1500.0, 3.4,
                 30 * 2 * np.pi / 60, s["moves"])


@pytest.mark.slow
def test_csp_and_pvt_reconstruct_the_setpoints(smooth):
    from dextar.program.drive import hermite

    sp, csp, pvt = (columns(smooth / f"{n}.csv") for n in ("setpoints", "csp", "pvt"))
    s = json.loads((smooth / "summary.json").read_text())
    per_rad = 353.5 * 4096 / (2 * np.pi)
    # the setpoints' angles are encoder readings (geometric angle - [robot].encoder_offset_deg)
    q = np.stack([sp["phi_rad"], sp["psi_rad"]], -1)
    assert s["encoder_offset_deg"] == [90.0, 0.0]
    offset = 0.0
    counts = np.stack([csp["pos1_counts"], csp["pos2_counts"]], -1)
    assert np.all(counts == np.round(counts))
    # counts back to radians within one count
    assert np.abs(counts / per_rad + offset - q).max() <= 1.0 / per_rad
    assert np.abs(csp["vel1_counts_s"] / per_rad - sp["dphi_rad_s"]).max() < 1e-9
    tau_pm = 1000 * sp["tau1_Nm"] / 353.5 / 0.0115
    assert np.abs(csp["torque1_permille"] - tau_pm).max() <= 0.5 + 1e-9
    # the cubic through the PVT points within the reported error, and the error is a real one
    pk = np.stack([pvt["pos1_counts"], pvt["pos2_counts"]], -1)
    vk = np.stack([pvt["vel1_counts_s"], pvt["vel2_counts_s"]], -1)
    cubic = hermite(sp["t_s"], pvt["t_s"], pk, vk)
    err = np.abs(cubic - (q - offset) * per_rad).max()
    reported = s["drive"]["pvt_max_error_counts"]
    assert err <= reported * (1 + 1e-9) and err > 0.5 * reported > 0
    assert np.allclose(np.diff(pvt["t_s"])[:-1], 0.01)
    m = s["drive"]["motors"][0]
    assert m["peak_speed_rpm"] == pytest.approx(np.abs(sp["dphi_rad_s"]).max() * 353.5 * 60
                                                / (2 * np.pi))
    assert 0 <= m["rotor_torque_share_rms"] <= 1


FIT = ('[robot]\npreset = "dextar"\n[inertia]\neffector_mass = 0.08\npayload = 0.05\n'
       'proximal_mass = 0.03\ndistal_mass = 0.02\n[friction]\ncoulomb = 0.02\nviscous = 0.01\n'
       '[gravity]\nvector = [0.0, -9810.0]\n[motors]\npeak_torque = {peak}\nrms_torque = 1.0\n'
       '[program]\nstart = [-40.0, 110.0]\n{cycle}[[move]]\ntype = "line"\nto = [40.0, 110.0]\n'
       '[[move]]\ntype = "dwell"\ntime = 0.05\n[[move]]\ntype = "line"\nto = [-40.0, 110.0]\n')


@pytest.mark.slow
def test_fit_rms_plans_at_the_rating_and_stronger_motors_never_lose(tmp_path):
    """With 4 N m peaks the task as planned exceeds its 1 N m RMS rating; fitted, it is
    within it, bound by a rating, and faster than with 2 N m motors (which fit as
    planned); a cycle 1 % shorter (the moves planned at higher peaks) exceeds the rating."""
    import tomllib

    from dextar.config import scenario_from_dict
    from dextar.program.plan import rms_ratios

    def req(peak, cycle):
        doc = tomllib.loads(FIT.format(peak=peak, cycle=f'cycle = "{cycle}"\n'))
        return scenario_from_dict(doc).program_request()

    strong = req(4.0, "as-planned").plan()
    assert max(rms_ratios(strong)) > 1.0
    fitted = req(4.0, "fit-rms").plan()
    assert fitted.rms_fit is not None and "RMS rating of motor" in fitted.rms_fit.bound_by
    assert max(rms_ratios(fitted)) <= 1.0
    weak = req(2.0, "fit-rms").plan()
    assert fitted.cycle_time_s <= weak.cycle_time_s * (1 + 1e-9)
    r = req(4.0, "as-planned")
    scale = fitted.rms_fit.peak_scale
    for k in range(1, 30):  # the first higher peak scale whose cycle is 1 % shorter
        m = r.motors
        s2 = min(1.0, scale * (1 + 0.02 * k))
        faster = r.plan_with(type(m)((m.peak_torque[0] * s2, m.peak_torque[1] * s2),
                                     m.max_speed, m.knee_speed))
        if faster.cycle_time_s <= 0.99 * fitted.cycle_time_s:
            break
    assert faster.cycle_time_s <= 0.99 * fitted.cycle_time_s
    assert max(rms_ratios(faster)) > 1.0


@pytest.mark.parametrize("motors, drive, words", [
    ("max_jerk = 0.0\n", "", r"\[motors\]\.max_jerk must be positive"),
    ("max_acceleration = -5.0\n", "", r"\[motors\]\.max_acceleration must be positive"),
    ("max_torque_rate = [10.0, 0.0]\n", "", r"\[motors\]\.max_torque_rate"),
    ("", "[drive]\ngear_ratio = 0\n", r"\[drive\]\.gear_ratio must be positive"),
    ("", "[drive]\nencoder_counts = 10.5\n", r"\[drive\]\.encoder_counts .* whole numbers"),
])
def test_bad_input_named(tmp_path, capsys, motors, drive, words):
    import re

    cfg = tmp_path / "bad.toml"
    cfg.write_text(task(motors, drive))
    assert main(["program", str(cfg), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert re.search(words, err) and err.count("\n") == 1, err


def test_a_jerk_limit_needs_a_peak_torque(tmp_path, capsys):
    cfg = tmp_path / "bad.toml"
    text = task()
    text = text.replace("peak_torque = 3.4 ", "max_jerk = 100.0 ").replace(
        "max_speed_rpm = 30 ", "").replace("knee_speed_rpm = 1 ", "")
    cfg.write_text(text)
    assert main(["program", str(cfg), "--out", str(tmp_path / "o")]) == 2
    assert "[motors].max_jerk needs peak_torque" in capsys.readouterr().err
