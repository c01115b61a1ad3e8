"""dextar excite and dextar identify from the command line: files, columns, a config that
reproduces the identified base parameters, and bad input refused in one line (exit 2)."""

import csv
import json

import numpy as np
import pytest

from dextar.cli import main
from dextar.config import load_scenario
from dextar.dynamics.regressor import standard_parameters
from dextar.identification.base import base_parameters

from ..program.test_program import EXAMPLES, read

CONFIG = str(EXAMPLES / "pick_place.toml")
COLUMNS = ["t_s", "phi_rad", "psi_rad", "dphi_rad_s", "dpsi_rad_s", "ddphi_rad_s2",
           "ddpsi_rad_s2", "tau1_Nm", "tau2_Nm"]


def test_excite_writes_a_rest_to_rest_periodic_motion(excite_csv, capsys):
    head, data = read(excite_csv)
    assert head == COLUMNS
    c = dict(zip(head, data.T, strict=True))
    assert len(c["t_s"]) == 10001 and c["t_s"][-1] == pytest.approx(10.0)
    for k in ("dphi_rad_s", "dpsi_rad_s"):
        assert abs(c[k][0]) < 1e-12 and abs(c[k][-1]) < 1e-9
    dt = 1e-3
    fd = np.gradient(c["phi_rad"], dt)
    assert np.abs(fd[1:-1] - c["dphi_rad_s"][1:-1]).max() < 1e-4 * np.abs(c["dphi_rad_s"]).max()


def test_excite_prints_its_condition_number(tmp_path, capsys):
    assert main(["excite", CONFIG, "--out", str(tmp_path / "e.csv"), "--duration", "5",
                 "--harmonics", "3", "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert 1 < payload["condition_number"] < 1e3
    assert payload["periods"] == 1 and payload["samples"] == 5001


def test_identify_writes_a_config_that_reproduces_the_base_parameters(excite_csv, tmp_path,
                                                                      capsys):
    out = tmp_path / "id"
    assert main(["identify", str(excite_csv), "--config", CONFIG, "--validate",
                 str(excite_csv), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "identified 11 base parameters" in text
    assert {p.name for p in out.iterdir()} == {"identified.toml", "parameters.csv",
                                               "summary.json", "fit.png", "report.html"}
    s = json.loads((out / "summary.json").read_text())
    for key in ("status", "n_samples", "condition_number", "rms_residual_Nm",
                "validation_rms_error_Nm", "validation_rms_error_prior_Nm", "method"):
        assert key in s
    assert s["status"] == "identified" and s["n_samples"] == 10001
    head, *_ = (out / "parameters.csv").read_text().splitlines()
    assert head == "name,meaning,value,std,rel_std_percent,unit"
    # the identified config loads and its model has exactly the identified base parameters
    model = load_scenario(out / "identified.toml").si_model
    base = base_parameters(model)
    beta = np.array([p["value"] for p in s["base_parameters"]])
    assert np.allclose(base.of(standard_parameters(model.inertia)), beta, rtol=1e-9)
    # data from our own model with its own prior: both predict it
    assert max(s["validation_rms_error_Nm"]) < 1e-3
    # and every command takes it
    assert main(["torques", str(out / "identified.toml"), "--out", str(tmp_path / "t.csv")]) == 0


@pytest.mark.parametrize("edit, message", [
    (lambda rows: [r[:-1] for r in rows], "lacks the column tau2_Nm"),
    (lambda rows: rows[:5] + [rows[5][:7] + ["nan", rows[5][8]]] + rows[6:],
     "tau1_Nm, tau2_Nm is NaN or infinite at row 6"),
    (lambda rows: rows[:5] + [["x", *rows[5][1:]]] + rows[6:], "row 6, column t_s: 'x' is not"),
    (lambda rows: rows[:1] + rows[1:][::-1], "t_s does not increase"),
])
def test_bad_data_exit_2_with_one_line(excite_csv, tmp_path, capsys, edit, message):
    with open(excite_csv) as fh:
        rows = list(csv.reader(fh))
    bad = tmp_path / "bad.csv"
    with open(bad, "w", newline="") as fh:
        csv.writer(fh).writerows(edit(rows))
    assert main(["identify", str(bad), "--config", CONFIG, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err, err
    assert not (tmp_path / "o").exists()


def test_bad_options_exit_2(excite_csv, tmp_path, capsys):
    assert main(["identify", str(tmp_path / "missing.csv"), "--out", str(tmp_path / "o")]) == 2
    assert "cannot be read" in capsys.readouterr().err
    assert main(["identify", str(excite_csv), "--config", CONFIG, "--cutoff-hz", "600",
                 "--out", str(tmp_path / "o")]) == 2
    assert "below the Nyquist frequency 500 Hz" in capsys.readouterr().err
    assert main(["excite", CONFIG, "--out", str(tmp_path / "e.csv"), "--harmonics", "1"]) == 2
    assert "--harmonics 1 must be an integer from 2 to 20" in capsys.readouterr().err
    assert main(["excite", CONFIG, "--out", str(tmp_path / "e.txt")]) == 2
    assert "must end in .csv" in capsys.readouterr().err
