"""The main job: `dextar run` reproduces the paper end to end."""

import csv
import json
import signal
import subprocess
import sys
import time
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from dextar.cli import main
from dextar.dynamics import Model, inverse_dynamics, paper_inertia
from dextar.geometry import DEXTAR_MM
from dextar.laws import solve_optimal_law
from dextar.paths import Arc

pytestmark = pytest.mark.slow

FIGS = [f"fig{k}" for k in range(3, 10)]
#: The run's CSV columns in paper units (names carry the unit, see dextar.output.tables).
RUN_COLUMNS = ["t_T", "p", "dp_per_T", "ddp_per_T2", "x_L", "y_L", "dx_L_T", "dy_L_T",
               "ddx_L_T2", "ddy_L_T2", "phi_rad", "psi_rad", "dphi_rad_T", "dpsi_rad_T",
               "ddphi_rad_T2", "ddpsi_rad_T2", "tau1_mL2_T2", "tau2_mL2_T2",
               "tau1_paper_mL2_T2", "tau2_paper_mL2_T2", "power1_mL2_T3", "power2_mL2_T3",
               "kinetic_energy_mL2_T2", "force_B_mL_T2", "force_C_mL_T2", "force_P1_mL_T2",
               "force_P2_mL_T2", "effector_energy_mL2_T2", "effector_energy_fd_mL2_T2",
               "effector_energy_beta0_mL2_T2"]


@pytest.fixture(scope="session")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "dextar-out"
    assert main(["run", "--out", str(out), "--quiet"]) == 0
    return out


def read_csv(path):
    with open(path) as fh:
        rows = list(csv.reader(fh))
    return rows[0], np.array(rows[1:], dtype=float)


class _Html(HTMLParser):
    def __init__(self):
        super().__init__()
        self.imgs, self.tags = [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag == "img":
            self.imgs.append(dict(attrs)["src"])


def test_every_file_well_formed(run_dir):
    for f in FIGS:
        assert (run_dir / f"{f}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert (run_dir / f"{f}.svg").read_text().rstrip().endswith("</svg>")
    assert (run_dir / "workspace.png").read_bytes()[:4] == b"\x89PNG"
    assert (run_dir / "animation.gif").read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    head, data = read_csv(run_dir / "trajectory.csv")
    assert head == RUN_COLUMNS
    assert data.shape == (1001, len(RUN_COLUMNS)) and np.isfinite(data).all()
    t = data[:, 0]
    assert t[0] == 0.0 and t[-1] == 1.0 and np.allclose(np.diff(t), 1e-3)
    s = json.loads((run_dir / "summary.json").read_text())
    for key in ("units", "robot", "path", "law", "inertia", "cost", "torques", "paper_model",
                "beta_range_deg", "validation", "claims", "assumptions", "output"):
        assert key in s
    law = s["law"]
    assert law["type"] == "optimal" and law["duration"] == 1.0 and law["duration_s"] == 1.0
    assert law["status"] == 0 and law["success"] and "converged" in law["message"]
    assert "samples" not in law and s["output"]["samples"] == 1001
    assert s["units"]["system"] == "paper" and s["units"]["length_unit_in_mm"] == 87.0
    assert s["cost"]["total"] == pytest.approx(s["cost"]["kinetic"] + s["cost"]["inertial"])
    assert s["validation"]["power_balance_relative"] < 1e-8
    fw = s["validation"]["forward_resimulation"]
    assert s["validation"]["passed"] and fw["passed"] and fw["windows"] == len(fw["drift_rad"])
    assert fw["max_drift_ratio"] < 1e-8 and fw["max_drift_rad"] < 1e-9
    assert {"max", "rms", "max_relative", "rms_relative"} <= set(s["paper_model"]["error_vs_exact"])
    p = _Html()
    p.feed((run_dir / "report.html").read_text())
    assert "table" in p.tags
    assert len(p.imgs) >= 9 and all(src.startswith("data:image/png;base64,") for src in p.imgs[:-1])
    assert p.imgs[-1].startswith("data:image/gif;base64,")  # the animation is in the report
    assert not [f for f in run_dir.iterdir() if f.name.startswith(".")]


def test_csv_agrees_with_direct_calls(run_dir):
    head, data = read_csv(run_dir / "trajectory.csv")
    c = dict(zip(head, data.T, strict=True))
    robot = DEXTAR_MM.scaled(1 / 87)
    q = np.stack([c["phi_rad"], c["psi_rad"]], -1)
    dq = np.stack([c["dphi_rad_T"], c["dpsi_rad_T"]], -1)
    ddq = np.stack([c["ddphi_rad_T2"], c["ddpsi_rad_T2"]], -1)
    tau = inverse_dynamics(Model(robot, paper_inertia(robot)), q, dq, ddq)
    np.testing.assert_allclose(np.stack([c["tau1_mL2_T2"], c["tau2_mL2_T2"]], -1), tau, rtol=0,
                               atol=1e-12 * np.abs(tau).max())
    law = solve_optimal_law(Arc(120 / 87, 0, np.pi), eta=0.1, mass=1.0)
    s = law.evaluate(c["t_T"])[0]
    np.testing.assert_allclose(c["p"], s / (120 / 87), atol=1e-12)


def test_existing_directory_refused_then_forced(run_dir, capsys):
    assert main(["run", "--out", str(run_dir), "--quiet"]) == 2
    assert "--force" in capsys.readouterr().err


def _complete(path):
    data = path.read_bytes()
    if path.suffix == ".png":
        return data.endswith(b"IEND\xaeB`\x82")
    if path.suffix == ".svg":
        return data.rstrip().endswith(b"</svg>")
    if path.suffix == ".gif":
        return data.endswith(b";")
    if path.suffix == ".json":
        json.loads(data)
        return True
    if path.suffix == ".csv":
        return data.endswith(b"\n") and data.count(b"\n") == 1002
    if path.suffix == ".html":
        return data.rstrip().endswith(b"</html>")
    return False


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_killed_run_leaves_no_partial_file(tmp_path, sig):
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "dextar", "run", "--out", str(out),
                             "--quiet"], stderr=subprocess.PIPE)
    deadline = time.time() + 60
    # trajectory.csv is written before the figures are drawn (they are written together
    # when all are drawn): the signal lands while they are drawn
    while time.time() < deadline and not (out / "trajectory.csv").exists():
        time.sleep(0.01)
    time.sleep(0.2)
    proc.send_signal(sig)
    proc.wait(timeout=30)
    files = list(out.iterdir())
    assert files, "the run was killed before writing anything"
    assert all(_complete(f) for f in files), [f.name for f in files if not _complete(f)]
    assert not (out / "summary.json").exists() or proc.returncode == 0
    if sig == signal.SIGTERM:
        # on a loaded machine the run may end before the signal reaches it: then it is whole
        assert proc.returncode != 0 or (out / "summary.json").exists()
        assert b"Traceback" not in proc.stderr.read()
        assert not list(tmp_path.glob(".out.staging-*"))


def _processes_writing(out):
    """Processes whose command line names ``out`` (a run and its forked children)."""
    found = []
    for p in Path("/proc").glob("[0-9]*/cmdline"):
        try:
            if str(out).encode() in p.read_bytes():
                found.append(p.parent.name)
        except OSError:
            pass
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and fork: Linux")
def test_terminated_while_drawing_on_two_cores_leaves_no_process_and_no_traceback(tmp_path):
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "dextar", "run", "--out", str(out),
                             "--quiet"], stderr=subprocess.PIPE)
    deadline = time.time() + 60
    while time.time() < deadline and not (out / "trajectory.csv").exists():
        time.sleep(0.005)  # the CSV is written just before the figures are drawn
    time.sleep(0.2)
    drawing = _processes_writing(out)
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=30)
    err = proc.stderr.read()
    assert b"Traceback" not in err, err.decode()[-2000:]
    if proc.returncode in (0, -signal.SIGTERM):  # a loaded machine: the run had written its
        assert (out / "summary.json").exists()  # files (the signal came as it exited)
        return
    assert proc.returncode == 130 and b"interrupted" in err
    assert not (out / "summary.json").exists()
    assert not list(tmp_path.glob(".out.staging-*"))
    time.sleep(0.2)
    assert _processes_writing(out) == []  # the children ended with the run
    # the run, and when two CPUs are allowed its drawing child and, while it lasts, the child
    # computing the validation
    assert len(drawing) in (1, 2, 3)


def test_run_general_robot_without_paper_model(tmp_path, capsys):
    cfg = tmp_path / "g.toml"
    cfg.write_text('[robot]\nl1 = 70.0\nl2 = 75.0\nL1 = 90.0\nL2 = 85.0\nd = 50.0\n'
                   '[path]\ntype = "line"\nstart = [-40.0, 100.0]\nend = [40.0, 120.0]\n'
                   '[output]\nunits = "si"\nfigures = ["fig3", "fig9"]\n')
    out = tmp_path / "o"
    assert main(["run", str(cfg), "--out", str(out), "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert "not symmetric" in s["paper_model"]["not_applicable"]
    assert "claims" not in s and (out / "fig9.png").exists() and not (out / "fig6.png").exists()
    head, data = read_csv(out / "trajectory.csv")
    assert "tau1_Nm" in head and "x_m" in head and np.isfinite(data).all()
    assert not [h for h in head if "paper" in h or "effector_energy" in h]
    report = (out / "report.html").read_text()
    assert "not applicable" in report and "paper's claims" not in report
    assert "Five-bar l1 = 70, l2 = 75, L1 = 90, L2 = 85, d = 50 mm" in report


def _gif_delays(path):
    from PIL import Image

    im, delays = Image.open(path), []
    try:
        while True:
            delays.append(im.info["duration"])
            im.seek(im.tell() + 1)
    except EOFError:
        return delays


def test_a_very_long_motion_is_animated_sped_up_and_says_so(tmp_path):
    """Review 28 finding 2: a 1e9 s motion asked the animation for 1.7e7 frames of 60 s each
    (the run hung). Now at most ``animation_frames`` frames, and the report (as the GIF's
    title) says the animation is sped up, not real time; the paper's 1 s motion plays in real
    time (test_the_paper_runs_animation_is_real_time)."""
    cfg = tmp_path / "long.toml"
    cfg.write_text('[law]\ntype = "min-jerk"\nduration = 1e9\n'
                   '[output]\nsamples = 101\nfigures = ["animation"]\n')
    out = tmp_path / "o"
    t0 = time.perf_counter()
    assert main(["run", str(cfg), "--out", str(out), "--quiet"]) == 0
    assert time.perf_counter() - t0 < 60.0  # (about 2 s; it did not end in 10 minutes)
    delays = _gif_delays(out / "animation.gif")
    assert len(delays) == 41 and set(delays[:-1]) == {60_000}
    report = (out / "report.html").read_text()
    assert "sped up 4.17e+05 times (not real time" in report and "in real time" not in report


def test_the_paper_runs_animation_is_real_time(run_dir):
    delays = _gif_delays(run_dir / "animation.gif")
    assert len(delays) <= 41 and sum(delays[:-1]) == pytest.approx(1000.0, abs=5.0)
    report = (run_dir / "report.html").read_text()
    assert "optimal law), in real time." in report and "sped up" not in report
