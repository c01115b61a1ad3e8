"""The main job: `dextar run` reproduces the paper end to end."""

import csv
import json
import signal
import subprocess
import sys
import time
from html.parser import HTMLParser

import numpy as np
import pytest

from dextar.cli import main
from dextar.dynamics import Model, inverse_dynamics, paper_inertia
from dextar.geometry import DEXTAR_MM
from dextar.laws import solve_optimal_law
from dextar.output.run import RUN_COLUMNS
from dextar.paths import Arc

FIGS = [f"fig{k}" for k in range(3, 10)]


@pytest.fixture(scope="module")
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
    assert head == list(RUN_COLUMNS)
    assert data.shape == (1001, len(RUN_COLUMNS)) and np.isfinite(data).all()
    t = data[:, 0]
    assert t[0] == 0.0 and t[-1] == 1.0 and np.allclose(np.diff(t), 1e-3)
    s = json.loads((run_dir / "summary.json").read_text())
    for key in ("units", "robot", "path", "law", "inertia", "cost", "torques", "paper_model",
                "beta_range_deg", "validation", "claims", "assumptions"):
        assert key in s
    assert s["units"]["system"] == "paper" and s["units"]["length_unit_in_mm"] == 87.0
    assert s["cost"]["total"] == pytest.approx(s["cost"]["kinetic"] + s["cost"]["inertial"])
    assert s["validation"]["power_balance_relative"] < 1e-8
    assert s["validation"]["forward_resimulation"]["final_error_relative_to_range"] < 1e-6
    assert {"max", "rms", "max_relative", "rms_relative"} <= set(s["paper_model"]["error_vs_exact"])
    p = _Html()
    p.feed((run_dir / "report.html").read_text())
    assert "table" in p.tags
    assert len(p.imgs) >= 8 and all(src.startswith("data:image/png;base64,") for src in p.imgs)
    assert not [f for f in run_dir.iterdir() if f.name.startswith(".")]


def test_csv_agrees_with_direct_calls(run_dir):
    head, data = read_csv(run_dir / "trajectory.csv")
    c = dict(zip(head, data.T, strict=True))
    robot = DEXTAR_MM.scaled(1 / 87)
    q = np.stack([c["phi"], c["psi"]], -1)
    dq = np.stack([c["dphi"], c["dpsi"]], -1)
    ddq = np.stack([c["ddphi"], c["ddpsi"]], -1)
    tau = inverse_dynamics(Model(robot, paper_inertia(robot)), q, dq, ddq)
    np.testing.assert_allclose(np.stack([c["tau1"], c["tau2"]], -1), tau, rtol=0,
                               atol=1e-12 * np.abs(tau).max())
    law = solve_optimal_law(Arc(120 / 87, 0, np.pi), eta=0.1, mass=1.0)
    s = law.evaluate(c["t"])[0]
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
    while time.time() < deadline and not (out / "fig4.png").exists():
        time.sleep(0.01)
    proc.send_signal(sig)
    proc.wait(timeout=30)
    files = list(out.iterdir())
    assert files, "the run was killed before writing anything"
    assert all(_complete(f) for f in files), [f.name for f in files if not _complete(f)]
    assert not (out / "summary.json").exists() or proc.returncode == 0
    if sig == signal.SIGTERM:
        assert proc.returncode != 0 and b"Traceback" not in proc.stderr.read()
        assert not list(tmp_path.glob(".out.staging-*"))


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
    assert "tau1" in head and "tau1_paper" not in head and np.isfinite(data).all()
    assert "not applicable" in (out / "report.html").read_text()
