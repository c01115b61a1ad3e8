import csv
import json
import re
import subprocess
import sys

import numpy as np
import pytest

from dextar.cli import main

PLAN_COLUMNS = ["t_T", "p", "dp_per_T", "ddp_per_T2", "x_L", "y_L", "dx_L_T", "dy_L_T",
                "ddx_L_T2", "ddy_L_T2", "phi_rad", "psi_rad", "dphi_rad_T", "dpsi_rad_T",
                "ddphi_rad_T2", "ddpsi_rad_T2"]


def read_csv(path):
    with open(path) as fh:
        rows = list(csv.reader(fh))
    return rows[0], np.array(rows[1:], dtype=float)


def test_plan_default_is_paper(tmp_path, capsys):
    out = tmp_path / "plan.csv"
    assert main(["plan", "--out", str(out), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    head, data = read_csv(out)
    assert head[:16] == PLAN_COLUMNS
    assert data.shape == (1001, 16)
    assert d["law"] == "optimal" and d["cost"] == pytest.approx(d["cost_kinetic"] + d["cost_inertial"])
    # p from 0 to pi, x = R cos p with R = 120/87
    np.testing.assert_allclose(data[[0, -1], 1], [0, np.pi], atol=1e-9)
    np.testing.assert_allclose(data[:, 4], 120 / 87 * np.cos(data[:, 1]), atol=1e-12)


@pytest.mark.parametrize("table, law", [
    ('[law]\ntype = "uniform"\n', "uniform"),
    ('[law]\ntype = "min-jerk"\nduration = 2.0\n', "min-jerk"),
    ('[law]\ntype = "trapezoid"\nvmax = 1000.0\namax = 4000.0\n', "trapezoid"),
    ('[law]\ntype = "time-optimal"\ntorque_limit = 0.15\nspeed_limit_deg_s = 400\n',
     "time-optimal"),
    ('[path]\ntype = "line"\nstart = [-50.0, 100.0]\nend = [50.0, 120.0]\n', "optimal"),
    ('[path]\ntype = "expression"\nx = "40*cos(p)"\ny = "110 + 20*sin(p)"\np0 = 0\np1 = 3\n',
     "optimal"),
    ('[path]\ntype = "spline"\nwaypoints = [[40.0, 100.0], [0.0, 120.0], [-40.0, 100.0]]\n',
     "optimal"),
])
def test_plan_configs(tmp_path, capsys, table, law):
    cfg = tmp_path / "c.toml"
    cfg.write_text(table)
    out = tmp_path / "p.csv"
    assert main(["plan", str(cfg), "--out", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["law"] == law
    head, data = read_csv(out)
    assert np.isfinite(data).all() and head[:16] == PLAN_COLUMNS



def test_the_laws_speed_limit_holds_with_the_motors_limits(tmp_path, capsys):
    """[law].speed_limit_deg_s was left out unless [law].torque_limit was given (a new user's
    trial: 600 deg/s, the motors' 100 rpm, under a 360 deg/s limit, the law "within the
    limits"): with the motors' limits the lower of the two speed limits holds."""
    table = ('[output]\nunits = "si"\n[path]\ntype = "line"\nstart = [-50.0, 100.0]\n'
             'end = [50.0, 120.0]\n[motors]\npeak_torque = 3.0\nmax_speed_rpm = 100.0\n'
             '[law]\ntype = "time-optimal"\n')
    peaks = {}
    for name, extra in (("motors", ""), ("law", "speed_limit_deg_s = 240.0\n")):
        cfg = tmp_path / f"{name}.toml"
        cfg.write_text(table + extra)
        out = tmp_path / f"{name}.csv"
        assert main(["plan", str(cfg), "--out", str(out)]) == 0
        # the grid's segments in mm (they were in metres without a unit)
        assert re.search(r"\(400 segments of 0\.2\d+ mm", capsys.readouterr().out)
        names, data = read_csv(out)
        dq = data[:, [names.index("dphi_rad_s"), names.index("dpsi_rad_s")]]
        peaks[name] = np.degrees(np.abs(dq).max())
    assert 600.0 * 0.99 < peaks["motors"] <= 600.0 * 1.001, peaks  # 100 rpm
    assert 240.0 * 0.99 < peaks["law"] <= 240.0 * 1.001, peaks

def test_torques_columns(tmp_path, capsys):
    out = tmp_path / "t.csv"
    assert main(["torques", "--out", str(out)]) == 0
    head, data = read_csv(out)
    for c in ("tau1_mL2_T2", "tau2_mL2_T2", "tau1_paper_mL2_T2", "tau2_paper_mL2_T2",
              "power1_mL2_T3", "power2_mL2_T3", "kinetic_energy_mL2_T2", "force_B_mL_T2",
              "force_C_mL_T2", "force_P1_mL_T2", "force_P2_mL_T2"):
        assert c in head
    assert head[:16] == PLAN_COLUMNS  # the same names as plan for the same quantities
    cols = dict(zip(head, data.T, strict=True))
    np.testing.assert_allclose(cols["power1_mL2_T3"], cols["tau1_mL2_T2"] * cols["dphi_rad_T"])
    words = capsys.readouterr().out
    assert "paper model (42) error" in words
    # each motor's peak with its unit (it read "peak |tau| = 39.46, 39.46 [m L^2/T^2]")
    peak = np.abs(data[:, [head.index("tau1_mL2_T2"), head.index("tau2_mL2_T2")]]).max(axis=0)
    assert (f"peak |tau|: motor A {peak[0]:.6g} m L^2/T^2, motor D {peak[1]:.6g} m L^2/T^2"
            in words), words


@pytest.mark.slow
def test_simulate_and_export(tmp_path, capsys):
    out = tmp_path / "sim"
    assert main(["simulate", "--out", str(out), "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert 0 < rep["max_task_error_mm"] < 5.0
    assert (out / "tracking.png").read_bytes()[:4] == b"\x89PNG"
    head, data = read_csv(out / "tracking.csv")
    assert "task_error_mm" in head and len(data) == 1001
    xml = tmp_path / "m.xml"
    assert main(["export", "mjcf", "--out", str(xml)]) == 0
    text = xml.read_text()
    assert "<connect" in text and 'joint="phi"' in text and 'joint="psi"' in text


def test_export_loads_in_mujoco(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    xml = tmp_path / "m.xml"
    cfg = tmp_path / "c.toml"
    cfg.write_text("[gravity]\nvector = [0.0, -9810.0]\n[inertia]\nrotor_inertia = 50.0\n"
                   "[output]\nunits = \"si\"\n")
    assert main(["export", "mjcf", str(cfg), "--out", str(xml)]) == 0
    m = mujoco.MjModel.from_xml_path(str(xml))
    assert m.nu == 2 and m.neq == 1 and m.njnt == 4
    assert m.opt.gravity[1] == pytest.approx(-9.81)


@pytest.mark.parametrize("content, word", [
    ('[law]\ntype = "fast"\n', "[law].type"),
    ('[law]\neta = -1.0\n', "[law].eta must be positive"),
    ('[law]\ntype = "time-optimal"\n', "[law].torque_limit is required"),
    ('[path]\ntype = "line"\nstart = [0.0, 100.0]\n', "[path].end is required"),
    ('[path]\nradius = "big"\n', "[path].radius must be a number"),
    ('[inertia]\ndistal_mass = -0.1\n', "[inertia].distal_mass must be at least 0"),
    ('[inertia]\nproximal_mass = [0.1, 0.2, 0.3]\n', "[inertia].proximal_mass"),
    ('[output]\nunits = "imperial"\n', "[output].units"),
    ('[output]\nfigures = ["fig99"]\n', "fig99"),
    ('[path]\nradius = 200.0\n',
     "leaves the workspace at 0 mm along the path (from the start of the motion): point (200, 0) mm"),
    ('[gravity]\nvector = 9.81\n', "[gravity].vector"),
    ('[control]\nnatural_frequency_hz = 0\n', "natural_frequency_hz"),
])
def test_bad_configs_named(tmp_path, capsys, content, word):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(content)
    code = main(["torques", str(cfg), "--out", str(tmp_path / "x.csv")])
    err = capsys.readouterr().err
    assert code == 2 and word in err and err.count("\n") == 1
    assert not (tmp_path / "x.csv").exists()


def test_missing_config_file(capsys):
    assert main(["plan", "/nonexistent/c.toml", "--out", "/tmp/x.csv"]) == 2
    assert "does not exist" in capsys.readouterr().err


@pytest.mark.slow
def test_no_traceback_for_bad_out(tmp_path):
    r = subprocess.run([sys.executable, "-m", "dextar.cli", "plan", "--out",
                        str(tmp_path / "x.txt")], capture_output=True, text=True)
    assert r.returncode == 2 and "Traceback" not in r.stderr and ".csv" in r.stderr
