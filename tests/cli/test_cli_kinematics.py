import json
import subprocess
import sys

import pytest

from dextar.cli import main


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_ik_json(capsys):
    code, out, _ = run(["ik", "0", "120", "--json"], capsys)
    d = json.loads(out)
    assert code == 0 and d["mode"] == "+-"
    assert d["phi_deg"] == pytest.approx(60.5118, abs=1e-4)
    assert d["psi_deg"] == pytest.approx(119.4882, abs=1e-4)


def test_fk_json_round_trip(capsys):
    code, out, _ = run(["fk", "60.51178523", "119.48821477", "--json"], capsys)
    d = json.loads(out)
    assert code == 0 and d["assembly"] == "up"
    assert d["x_mm"] == pytest.approx(0.0, abs=1e-6) and d["y_mm"] == pytest.approx(120.0, abs=1e-6)


def test_negative_coordinates_and_mode(capsys):
    code, out, _ = run(["ik", "-10", "120", "--mode", "--", "--json"], capsys)
    assert code == 0 and json.loads(out)["mode"] == "--"


def test_robot_file(tmp_path, capsys):
    f = tmp_path / "r.toml"
    f.write_text('[robot]\nl1 = 80\nl2 = 80\nL1 = 100\nL2 = 100\nd = 50\nworking_mode = "+-"\n')
    code, out, _ = run(["ik", "0", "150", "--robot", str(f), "--json"], capsys)
    assert code == 0
    # closed form for this robot: law of cosines at A = (25, 0), elbow "+" (right of A -> P)
    import math

    rho = math.hypot(-25.0, 150.0)
    alpha = math.acos((80**2 + rho**2 - 100**2) / (2 * 80 * rho))
    phi = math.degrees(math.atan2(150.0, -25.0) - alpha)
    d = json.loads(out)
    assert d["phi_deg"] == pytest.approx(phi, abs=1e-9)
    assert d["psi_deg"] == pytest.approx(180.0 - phi, abs=1e-9)  # the mirror image


@pytest.mark.parametrize(
    "content, word",
    [
        ("[robot]\nl1 = 'x'\n", "[robot].l1 must be a number"),
        ("[robot]\nfoo = 1\n", "[robot].foo is not known"),
        ("[robot]\nl1 = 1\n", "[robot].l2 is required"),
        ("[robot]\npreset = 'dextar'\nd = -3\n", "[robot].d must be positive, got -3"),
        ("[robot]\nworking_mode = '+x'\n", "working mode '+x'"),
        ("[robt]\n", "[robt] is not known"),
        ("[robot\n", "not valid TOML"),
    ],
)
def test_bad_toml_named(tmp_path, capsys, content, word):
    f = tmp_path / "bad.toml"
    f.write_text(content)
    code, out, err = run(["ik", "0", "120", "--robot", str(f)], capsys)
    assert code == 2 and out == ""
    assert word in err and err.count("\n") == 1


def test_unreachable_is_one_line_exit_2(capsys):
    code, _, err = run(["ik", "500", "0"], capsys)
    assert code == 2 and "out of reach of leg 1" in err and err.count("\n") == 1


def test_workspace_writes_png(tmp_path, capsys):
    out = tmp_path / "ws.png"
    code, _, _ = run(["workspace", "--out", str(out), "--resolution", "50"], capsys)
    assert code == 0 and out.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow
def test_real_process_no_traceback():
    r = subprocess.run([sys.executable, "-m", "dextar.cli", "fk", "0", "180"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.strip().endswith("outside [0, 174]")
    r = subprocess.run([sys.executable, "-m", "dextar.cli", "ik", "x"], capture_output=True,
                       text=True)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


def test_every_example_config_serves_the_robot_option(capsys):
    from pathlib import Path

    for cfg in sorted((Path(__file__).resolve().parents[2] / "examples").glob("*.toml")):
        code, _, err = run(["ik", "0", "120", "--robot", str(cfg)], capsys)
        assert code == 0, (cfg.name, err)


@pytest.mark.parametrize("phi, psi, said", [
    ("nan", "30", "encoder reading phi = NaN deg is not a number"),
    ("30", "-inf", "encoder reading psi = -inf deg is infinite"),
    ("1e300", "30", "encoder reading phi = 1e+300 deg is beyond 10000 deg: not a reading in "
     "degrees"),
    ("30", "-12000", "encoder reading psi = -12000 deg is beyond 10000 deg: not a reading in "
     "degrees")])
def test_fk_names_readings_that_are_none_in_the_users_words(capsys, phi, psi, said):
    """Review 28 finding 10. Before: `fk nan 30` said "q has a non-finite value at index 0"
    (internal names, no NaN, no deg, no phi); `fk 1e300 30` answered a point, exit 0. The
    bound is a measured-poses file's (calibration.data.MAX_DEG)."""
    code, out, err = run(["fk", phi, psi], capsys)
    assert code == 2 and out == "" and err == f"dextar fk: error: {said}\n"


@pytest.mark.parametrize("phi, psi", [("9999", "-9999"), ("-180", "180"), ("400", "30")])
def test_fk_takes_readings_of_several_turns(capsys, phi, psi):
    code, out, err = run(["fk", phi, psi, "--json"], capsys)
    assert code == 0 and err == "" and json.loads(out)["phi_deg"] == float(phi)


@pytest.mark.parametrize("argv, said", [
    (["poses", "--count", "30", "--margin", "nan"], "singularity margin NaN must be in [0, 1)"),
    (["poses", "--count", "30", "--seed", "-1"], "seed -1 must be a whole number, 0 or more"),
])
def test_other_number_options_are_named_not_internal_errors(tmp_path, capsys, argv, said):
    """Before: `poses --seed -1` was `internal error: ValueError: expected non-negative
    integer`; `--margin nan` was called nan."""
    code, out, err = run([*argv, "--out", str(tmp_path / "p.csv")], capsys)
    assert code == 2 and err == f"dextar poses: error: {said}\n"
    assert not (tmp_path / "p.csv").exists()
