"""dextar excite and dextar identify from the command line: files, columns, a config that
reproduces the identified base parameters, and bad input refused in one line (exit 2)."""

import contextlib
import csv
import io
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from dextar.cli import main
from dextar.config import load_scenario
from dextar.dynamics.regressor import standard_parameters
from dextar.identification.base import base_parameters

from ..program.test_program import EXAMPLES, read

pytestmark = pytest.mark.slow

CONFIG = str(EXAMPLES / "pick_place.toml")
COLUMNS = ["t_s", "phi_rad", "psi_rad", "dphi_rad_s", "dpsi_rad_s", "ddphi_rad_s2",
           "ddpsi_rad_s2", "tau1_Nm", "tau2_Nm"]


@dataclass(frozen=True)
class Ran:
    """A command run once for the file's tests: its exit status, folder and words."""
    code: int
    out: Path
    stdout: str
    stderr: str


def ran(argv: list[str], out: Path) -> Ran:
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        code = main([*argv, "--out", str(out)])
    return Ran(code, out, stdout.getvalue(), stderr.getvalue())


# The two identifications of the recording that three tests each read (the same command
# line, the same files and words): run once for the file, not once per test (2-4 s each).
@pytest.fixture(scope="module")
def identified(excite_csv, tmp_path_factory):
    """``identify`` with the right config: identified, exit 0."""
    return ran(["identify", str(excite_csv), "--config", CONFIG, "--quiet", "--no-figures"],
               tmp_path_factory.mktemp("identified") / "ok")  # (no test reads its figures)


@pytest.fixture(scope="module")
def identified_poorly(excite_csv, tmp_path_factory):
    """``identify`` without --config (the DexTAR without gravity): a poor fit, exit 1."""
    return ran(["identify", str(excite_csv), "--quiet"],
               tmp_path_factory.mktemp("identified") / "poor")


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
    # the coverage floors and what the design reached (met: 47-117 % of the range, 77-99 %
    # of the speed, 43-47 % of the acceleration allowed, against floors of 20 / 20 / 10 %)
    cov = payload["coverage"]
    assert cov["met"] and not cov["missed"] and payload["status"] == 0
    assert set(cov["floors"]) == {"range", "speed", "acceleration", "condition_number"}
    for key in ("range", "speed", "acceleration"):
        assert min(cov["fractions"][key]) >= cov["floors"][key]
    # the peak speed against the motors' rating too (30 rpm): what the floors cannot see
    assert cov["advisory"] and cov["rated_speed_rad_s"] == pytest.approx([np.pi, np.pi])
    assert cov["speed_of_rated"] == pytest.approx(np.array(cov["peak_speed_rad_s"]) / np.pi)


def test_excite_below_its_advisory_floors_is_exit_0_with_a_warning(tmp_path, capsys,
                                                                   monkeypatch):
    """A floor no motion meets (1000 % of the range): the design is written and kept, exit
    0 with a warning naming the floor (the floors are advisory: no measured case ties
    missing one to a worse model; identification.excite's doc); it was exit 1. The summary
    says what each figure is a fraction of, never "allowed" (a range may exceed the one-motor
    free range it is measured against: 126 % "of what is allowed" was printed)."""
    from dextar.identification import excite

    monkeypatch.setattr(excite, "RANGE_FLOOR", 10.0)
    monkeypatch.setattr(excite, "ATTEMPTS", 1)
    out = tmp_path / "e.csv"
    # 2 harmonics (the smallest): no motion of any size meets a 1000 % floor, and the words
    # checked do not depend on the size (3 harmonics took 2.7 s of CPU, 2 take 1.2 s)
    assert main(["excite", CONFIG, "--out", str(out), "--duration", "5", "--harmonics",
                 "2"]) == 0
    cap = capsys.readouterr()
    assert out.exists() and "allowed" not in cap.out
    assert "% of the rated 3.14 / 3.14 rad/s" in cap.out and "advisory floors 1000 / 20 / 10 %"\
        in cap.out
    assert "dextar excite: warning: the excitation stays below its advisory coverage floors " \
           "after 1 design: motor A's range" in cap.err and "(floor 1000 %)" in cap.err


def test_identify_writes_a_config_that_reproduces_the_base_parameters(excite_csv, tmp_path,
                                                                      capsys):
    out = tmp_path / "id"
    assert main(["identify", str(excite_csv), "--config", CONFIG, "--validate",
                 str(excite_csv), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "identified: 11 base parameters" in text
    assert {p.name for p in out.iterdir()} == {"identified.toml", "parameters.csv",
                                               "summary.json", "fit.png", "report.html"}
    s = json.loads((out / "summary.json").read_text())
    for key in ("status", "n_samples", "condition_number", "rms_residual_Nm",
                "validation_rms_error_Nm", "validation_rms_error_prior_Nm", "method"):
        assert key in s
    assert s["status"] == "identified" and s["n_samples"] == 10001
    head, *_ = (out / "parameters.csv").read_text().splitlines()
    assert head == "name,meaning,value,std,rel_std_percent,unit,poorly_determined"
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
    (lambda rows: rows[:1] + [[repr(1e3 * float(r[0])), *r[1:]] for r in rows[1:]],
     "Is the time in milliseconds?"),
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


def test_a_poor_fit_is_exit_1_with_its_files_and_causes(identified_poorly, identified):
    """The pick-and-place robot's data (gravity, a gripper) identified as the default DexTAR
    without gravity: computed, written, exit 1, the likely causes named (measured fit quality
    97.8 % / 92.6 % against the 20 % limit)."""
    out = identified_poorly.out
    assert identified_poorly.code == 1
    err = identified_poorly.stderr
    assert "no --config: the robot is assumed to be the DexTAR" in err
    assert "poor fit: the model leaves" in err and "gravity left out" in err
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "poor fit" and min(s["fit_quality"]) > 0.5
    assert (out / "identified.toml").exists() and (out / "report.html").exists()
    # the right config fits: exit 0, a fit quality far below the limit
    assert identified.code == 0
    s = json.loads((identified.out / "summary.json").read_text())
    assert s["status"] == "identified" and max(s["fit_quality"]) < 0.01
    # --no-figures: the data files, no fit.png or report.html
    assert {p.name for p in identified.out.iterdir()} == {"identified.toml", "parameters.csv",
                                                          "summary.json"}
    # without --task the verdict is along the recorded motion, its poses and speeds named
    assert s["prediction_uncertainty_reference"].startswith("the recorded motion (motor A ")
    assert {"rel_std", "poorly_determined"} <= set(s["base_parameters"][0])
    head = (identified.out / "parameters.csv").read_text().splitlines()[0]
    assert head.endswith(",poorly_determined")


def test_a_model_not_identified_says_so_first_and_model_refuses_it(excite_csv, tmp_path,
                                                                   capsys, identified,
                                                                   identified_poorly):
    """identified.toml's first line names the status as calibrated.toml's does; a model
    whose first line says it is not identified is refused by --model (exit 2, named). The
    former file began "# identified by dextar from DATA (constrained, ...)" whatever the
    status, and program --model took it: exit 0, "fits"."""
    poor, ok = identified_poorly.out, identified.out
    assert identified_poorly.code == 1
    first = (poor / "identified.toml").read_text().splitlines()[0]
    assert first.startswith(f"# identified by dextar from {excite_csv} (poor fit: "), first
    assert "gravity left out" in first and first.endswith("refuses this file as --model)")
    capsys.readouterr()
    assert main(["plan", CONFIG, "--model", str(poor / "identified.toml"), "--out",
                 str(tmp_path / "p.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "with the status 'poor fit', not 'identified'" in err
    assert str(poor / "identified.toml") in err and not (tmp_path / "p.csv").exists()
    # the first line deleted (the way out the message names): the model is taken (this one,
    # the DexTAR's fit to another robot's data, is unfit for planning: loaded only)
    edited = tmp_path / "edited.toml"
    edited.write_text("\n".join((poor / "identified.toml").read_text().splitlines()[1:]))
    assert load_scenario(CONFIG, model=edited).source.endswith(f"the model of {edited}")
    # an identified model: its first line says so, and --model takes it
    assert identified.code == 0
    first = (ok / "identified.toml").read_text().splitlines()[0]
    assert first.startswith(f"# identified by dextar from {excite_csv} (identified: "), first
    assert main(["plan", CONFIG, "--model", str(ok / "identified.toml"), "--out",
                 str(tmp_path / "q.csv")]) == 0


def test_validation_reports_the_excited_region(excite_csv, tmp_path, capsys):
    """The paper's semicircle on the same robot is outside what the excitation visited: the
    validation says what fraction is inside and warns that the prediction extrapolates."""
    sc = load_scenario(CONFIG)
    doc = dict(sc.doc)
    doc.update({"law": {"type": "optimal", "duration": 1.0}, "output": {"units": "si"}})
    from dextar.config import scenario_from_dict
    from dextar.dynamics import inverse_dynamics

    tr = scenario_from_dict({k: v for k, v in doc.items() if k != "move"}).trajectory(
        samples=2001)
    tau = inverse_dynamics(sc.si_model, tr.q, tr.dq, tr.ddq)
    semi = tmp_path / "semi.csv"
    np.savetxt(semi, np.column_stack([tr.t, tr.q, tau]), delimiter=",", comments="",
               header="t_s,phi_rad,psi_rad,tau1_Nm,tau2_Nm")
    out = tmp_path / "v"
    assert main(["identify", str(excite_csv), "--config", CONFIG, "--validate", str(semi),
                 "--out", str(out), "--quiet", "--no-figures"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert 0.0 <= s["validation_inside_fraction"] < 1.0
    assert "the prediction extrapolates there" in capsys.readouterr().err


def test_excite_covers_a_task_with_the_motors_headroom(tmp_path, capsys):
    assert main(["excite", CONFIG, "--task", CONFIG, "--out", str(tmp_path / "e.csv"),
                 "--duration", "5", "--json"]) == 0
    p = json.loads(capsys.readouterr().out)
    assert min(p["headroom"]) > 0.5  # the old design used 4-7 % of the torque
    assert 0.0 < p["task_coverage"] <= 1.0 and len(p["task_speed_ratio"]) == 2


def test_every_config_command_takes_a_model_file(identified, tmp_path):
    """--model identified.toml: the identified robot, inertia, friction and gravity, the
    task's other tables kept."""
    out = identified.out
    assert identified.code == 0
    model = out / "identified.toml"
    ident = load_scenario(model).si_model.inertia
    assert load_scenario(CONFIG, model=model).si_model.inertia == ident
    assert main(["program", CONFIG, "--model", str(model), "--out", str(tmp_path / "p"),
                 "--quiet", "--no-figures"]) == 0  # (its exit status is checked)
    assert main(["plan", "--model", str(model), "--out", str(tmp_path / "q.csv")]) == 0
    bad = tmp_path / "bad.toml"
    bad.write_text("[motors]\npeak_torque = 1.0\n")
    assert main(["plan", "--model", str(bad), "--out", str(tmp_path / "r.csv")]) == 2


def test_a_motion_too_small_for_its_task_is_exit_1(tmp_path, capsys):
    """A stored excitation at a quarter of its size with 20 mN m of noise, identified for the
    pick-and-place program (--task): the program's torques predicted within 85-99 % (1
    sigma; limit 2 %): "poorly determined", exit 1, every file written, the reason named."""
    from dextar.identification.excite import FourierTrajectory

    from ..identification.conftest import synthetic
    from ..identification.excitations import EXCITATIONS

    sc = load_scenario(CONFIG)
    tr = EXCITATIONS[0]
    small = FourierTrajectory(tr.q0, 0.25 * tr.a, 0.25 * tr.b, tr.base_hz)
    d = synthetic(sc.si_model, small, 10.0, seed=3, noise=0.02)
    data = tmp_path / "small.csv"
    np.savetxt(data, np.column_stack([d.t, d.q, d.tau]), delimiter=",", comments="",
               header="t_s,phi_rad,psi_rad,tau1_Nm,tau2_Nm")
    out = tmp_path / "id"
    assert main(["identify", str(data), "--config", CONFIG, "--task", CONFIG, "--out",
                 str(out), "--quiet", "--no-figures"]) == 1  # (no test reads its figures)
    err = capsys.readouterr().err
    assert "dextar identify: poorly determined:" in err and f"along the task {CONFIG}" in err
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "poorly determined" and s["reasons"]
    assert min(s["prediction_uncertainty"]) > 10 * s["prediction_uncertainty_limit"]
    assert (out / "identified.toml").exists()
