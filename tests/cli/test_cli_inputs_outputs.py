"""Inputs and outputs a new user meets: mode aliases, stdout output, JSON summaries, errors in
the user's units, saturation reported, printed paths."""

import csv
import io
import json

import numpy as np
import pytest

from dextar.cli import main


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("argv", [["--mode=--"], ["--mode", "--"], ["--mode", "mm"],
                                  ["--mode=mm"], ["--mode", "MM"]])
def test_mode_minus_minus_every_spelling(argv, capsys):
    code, out, _ = run(["ik", "0", "120", *argv, "--json"], capsys)
    assert code == 0 and json.loads(out)["mode"] == "--"


@pytest.mark.parametrize("alias, mode", [("pm", "+-"), ("mp", "-+"), ("--", "--")])
def test_config_takes_the_same_aliases(tmp_path, capsys, alias, mode):
    f = tmp_path / "r.toml"
    f.write_text(f'[robot]\nworking_mode = "{alias}"\n')
    code, out, err = run(["ik", "0", "120", "--robot", str(f), "--json"], capsys)
    assert code == 0, err
    assert json.loads(out)["mode"] == mode


def test_bad_mode_named_the_same_way_in_both(tmp_path, capsys):
    code, _, err = run(["ik", "0", "120", "--mode", "+x"], capsys)
    assert code == 2 and "working mode '+x' is not one of" in err
    f = tmp_path / "r.toml"
    f.write_text('[robot]\nworking_mode = "+x"\n')
    code, _, err2 = run(["ik", "0", "120", "--robot", str(f)], capsys)
    assert code == 2 and "working mode '+x' is not one of" in err2


def test_two_waypoint_spline_is_the_straight_line(tmp_path, capsys):
    a, b = [40.0, 100.0], [-40.0, 110.0]
    sp, ln = tmp_path / "s.toml", tmp_path / "l.toml"
    sp.write_text(f'[path]\ntype = "spline"\nwaypoints = [{a}, {b}]\n')
    ln.write_text(f'[path]\ntype = "line"\nstart = {a}\nend = {b}\n')
    got = []
    for cfg in (sp, ln):
        code, out, err = run(["plan", str(cfg), "--out", "-"], capsys)
        assert code == 0, err
        rows = list(csv.reader(io.StringIO(out)))
        got.append(np.array(rows[1:], float))
    xy = slice(4, 6)
    np.testing.assert_allclose(got[0][:, xy], got[1][:, xy], atol=1e-12)


def test_errors_speak_mm_and_seconds(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text('[path]\ntype = "line"\nstart = [0.0, 100.0]\nend = [0.0, 300.0]\n'
                   '[output]\nunits = "si"\n')
    code, _, err = run(["plan", str(cfg), "--out", str(tmp_path / "x.csv")], capsys)
    assert code == 2 and "point (0, 156.2) mm is out of reach of leg 1 by 0.0548" in err


def test_expression_error_quotes_the_text_as_typed(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text('[path]\ntype = "expression"\nx = "40*cos(p)"\ny = "100 + log(p - 2)"\n'
                   'p0 = 0\np1 = 1\n')
    code, _, err = run(["plan", str(cfg), "--out", str(tmp_path / "x.csv")], capsys)
    assert code == 2 and err.count("\n") == 1
    assert "'100 + log(p - 2)'" in err and "*" not in err.split("'100")[0][-5:]
    assert "0.011494" not in err  # no rescaled text


def test_out_dash_writes_csv_to_stdout_and_words_to_stderr(capsys):
    code, out, err = run(["plan", "--out", "-"], capsys)
    assert code == 0
    rows = list(csv.reader(io.StringIO(out)))
    assert rows[0][0] == "t_T" and len(rows) == 1002
    assert "motion time 1 T (1 s)" in err and "wrote stdout" in err
    code, out, err = run(["torques", "--out", "-", "--json"], capsys)
    assert code == 0 and out.startswith("t_T,") and json.loads(err)["law"] == "optimal"


def test_plan_prints_the_motion_time_and_cost_only_for_the_optimal_law(tmp_path, capsys):
    code, out, _ = run(["plan", "--out", str(tmp_path / "a.csv")], capsys)
    assert code == 0 and "motion time 1 T (1 s)" in out and "cost Phi" in out
    cfg = tmp_path / "t.toml"
    cfg.write_text('[law]\ntype = "time-optimal"\ntorque_limit = 0.15\n[output]\nunits = "si"\n')
    code, out, _ = run(["plan", str(cfg), "--out", str(tmp_path / "b.csv"), "--json"], capsys)
    d = json.loads(out)
    assert code == 0 and d["law"] == "time-optimal" and "cost" not in d
    assert d["status"] == 0 and d["success"] and 0.1 < d["duration_s"] < 2.0
    assert d["duration"] == d["duration_s"]


@pytest.mark.slow
def test_workspace_and_run_json_print_the_whole_summary(tmp_path, capsys):
    code, out, _ = run(["workspace", "--out", str(tmp_path / "w.png"), "--resolution", "40",
                        "--json"], capsys)
    d = json.loads(out)
    assert code == 0 and d["reachable_area_mm2"] > 0 and d["robot_mm"]["L1"] == 87.0
    assert 0 < d["dexterity_mean"] <= d["dexterity_max"] <= 1
    cfg = tmp_path / "c.toml"
    cfg.write_text('[output]\nfigures = ["fig9"]\nsamples = 101\n')
    code, out, _ = run(["run", str(cfg), "--out", str(tmp_path / "o"), "--json"], capsys)
    s = json.loads(out)
    assert code == 0 and s["law"]["type"] == "optimal" and "validation" in s and "files" in s


@pytest.mark.slow
def test_printed_paths_have_no_double_slash(tmp_path, capsys):
    code, out, _ = run(["simulate", "--out", str(tmp_path / "sim") + "/"], capsys)
    assert code == 0 and "//" not in out and str(tmp_path / "sim" / "tracking.csv") in out
    cfg = tmp_path / "c.toml"
    cfg.write_text('[output]\nfigures = ["fig9"]\nsamples = 51\n')
    code, out, _ = run(["run", str(cfg), "--out", str(tmp_path / "r") + "/"], capsys)
    assert code == 0 and "//" not in out


@pytest.mark.slow
def test_simulate_reports_saturation(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    # the motion needs 0.3 N m at its peak; saturated, it is 7.2 mm off: within 10 mm
    cfg.write_text('[control]\ntorque_limit = 0.2\ntolerance_mm = 10.0\n')
    code, out, err = run(["simulate", str(cfg), "--out", str(tmp_path / "s"), "--json"], capsys)
    rep = json.loads(out)
    assert code == 0 and 0.2 < rep["saturated_fraction"] < 0.6 and rep["status"] == 0
    assert rep["followed"] and rep["tolerance_mm"] == 10.0
    assert err.count("\n") == 1 and "warning" in err and "saturates a motor during" in err
    saved = json.loads((tmp_path / "s" / "tracking.json").read_text())
    assert saved["saturated_fraction"] == rep["saturated_fraction"]
    head = (tmp_path / "s" / "tracking.csv").read_text().splitlines()[0].split(",")
    assert "saturated" in head and "tau1_mL2_T2" in head


def test_law_samples_points_to_output_samples(tmp_path, capsys):
    cfg = tmp_path / "c.toml"
    cfg.write_text("[law]\nsamples = 11\n")
    code, _, err = run(["plan", str(cfg), "--out", str(tmp_path / "x.csv")], capsys)
    assert code == 2 and "[law].samples is not known: use [output].samples" in err


def test_an_interrupt_a_library_swallows_is_still_reported_as_the_interrupt(monkeypatch, capsys):
    """A SIGTERM whose KeyboardInterrupt a library catches, failing later with another error
    (or a module import it cut short), ends as "interrupted" (130), not as an internal error;
    the caller's signal handlers are back after main returns."""
    import os
    import signal
    import time

    from dextar.commands import ik

    def run(args):
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5)
        except KeyboardInterrupt:  # a library swallowing it
            pass
        raise ValueError("a half-initialised module")

    monkeypatch.setattr(ik, "run", run)
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    assert main(["ik", "0", "120"]) == 130
    assert capsys.readouterr().err == "dextar ik: interrupted\n"
    assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before
    # the same error without an interrupt is a bug, named as one
    monkeypatch.setattr(ik, "run", lambda args: (_ for _ in ()).throw(ValueError("a bug")))
    assert main(["ik", "0", "120"]) == 2
    assert "internal error: ValueError: a bug" in capsys.readouterr().err
