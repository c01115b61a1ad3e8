"""Every command that reads a config says its notes (review 28, finding 4): a robot whose
lengths look written in metres and a file with no table, on stderr and beside an error.
Before, only plan, torques, simulate, program and run said them: ``dextar ik 0 120 --robot
metres.toml`` named the point out of reach of a 0.159 mm robot without a word of units."""

from __future__ import annotations

import pytest

from dextar.cli import main
from dextar.config import load_kinematic_config, load_scenario

METRES = "[robot]\nl1 = 0.072\nl2 = 0.072\nL1 = 0.087\nL2 = 0.087\nd = 0.06\n"
MM = "[robot]\nl1 = 72.0\nl2 = 72.0\nL1 = 87.0\nL2 = 87.0\nd = 60.0\n"
SAID = "looks like metres (0.087 m = 87 mm)"


@pytest.fixture
def files(tmp_path):
    out = {}
    for name, text in (("metres", METRES), ("mm", MM), ("empty", "# nothing yet\n")):
        out[name] = tmp_path / f"{name}.toml"
        out[name].write_text(text)
    return out


def _cli(capsys, *argv):
    capsys.readouterr()
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


def test_one_place_computes_the_notes_of_both_configs(files):
    """The robot-only config (ik, fk, workspace, poses, calibrate) and the scenario (the
    others) give the same metres note for the same robot; an empty file names what it
    stands for; a robot in mm and no file have none."""
    kc, sc = load_kinematic_config(files["metres"]), load_scenario(files["metres"])
    assert len(kc.notes) == 1 and kc.notes == sc.notes and SAID in kc.notes[0]
    assert load_kinematic_config(files["empty"]).notes == (
        f"{files['empty']} has no table: the robot is the DexTAR (l1 = l2 = 72, L1 = L2 = 87, "
        "d = 60 mm)",)
    assert "this runs the paper's example" in load_scenario(files["empty"]).notes[0]
    for cfg in (load_kinematic_config(files["mm"]), load_kinematic_config(None),
                load_scenario(files["mm"]), load_scenario(None)):
        assert cfg.notes == ()


@pytest.mark.slow
def test_ik_fk_and_workspace_say_the_notes(files, tmp_path, capsys):
    code, err = _cli(capsys, "ik", "0", "0.12", "--robot", files["metres"])
    assert code == 0 and err.startswith("dextar ik: note: ") and SAID in err
    # the point in mm is out of reach of a 0.159 mm robot: the note beside the error
    code, err = _cli(capsys, "ik", "0", "120", "--robot", files["metres"])
    assert code == 2 and err.count("\n") == 1 and "out of reach" in err and SAID in err
    code, err = _cli(capsys, "fk", "60", "120", "--robot", files["metres"])
    assert code == 0 and err.startswith("dextar fk: note: ") and SAID in err
    code, err = _cli(capsys, "workspace", "--robot", files["metres"], "--resolution", "41",
                     "--out", tmp_path / "w.png")
    assert code == 0 and err.startswith("dextar workspace: note: ") and SAID in err
    code, err = _cli(capsys, "ik", "0", "120", "--robot", files["empty"])
    assert code == 0 and "note: " in err and "has no table: the robot is the DexTAR" in err
    for argv in (("ik", "0", "120"), ("fk", "60", "120"),
                 ("workspace", "--resolution", "41", "--out", tmp_path / "w.png")):
        code, err = _cli(capsys, *argv, "--robot", files["mm"])
        assert code == 0 and "note" not in err, (argv, err)


@pytest.mark.slow
def test_poses_and_calibrate_say_the_notes(files, tmp_path, capsys):
    poses = tmp_path / "p.csv"
    code, err = _cli(capsys, "poses", files["metres"], "--count", "20", "--out", poses)
    assert code == 2 and "candidate poses" in err and SAID in err  # none: beside the error
    code, err = _cli(capsys, "poses", files["empty"], "--count", "20", "--out", poses,
                     "--quiet")
    assert code == 0 and err.startswith("dextar poses: note: ") and "has no table" in err
    code, err = _cli(capsys, "poses", files["mm"], "--count", "20", "--out", poses, "--quiet")
    assert code == 0 and "note" not in err
    # the poses' nominal points as measurements: the DexTAR's, read against a robot in metres
    code, err = _cli(capsys, "calibrate", poses, "--config", files["metres"], "--frame",
                     "robot", "--out", tmp_path / "c1")
    assert code == 2 and err.count("\n") == 1 and SAID in err
    # (--no-figures: the notes on stderr are checked, not the figures of the calibrations)
    code, err = _cli(capsys, "calibrate", poses, "--config", files["empty"], "--frame", "robot",
                     "--out", tmp_path / "c2", "--quiet", "--no-figures")
    assert code == 0 and err.startswith("dextar calibrate: note: ") and "has no table" in err
    code, err = _cli(capsys, "calibrate", poses, "--config", files["mm"], "--frame", "robot",
                     "--out", tmp_path / "c3", "--quiet", "--no-figures")
    assert code == 0 and "note" not in err


@pytest.mark.slow
def test_export_excite_and_identify_say_the_notes(files, tmp_path, capsys, excite_csv):
    code, err = _cli(capsys, "export", "mjcf", files["metres"], "--out", tmp_path / "m.xml")
    assert code == 2 and "out of reach" in err and SAID in err
    code, err = _cli(capsys, "export", "mjcf", files["empty"], "--out", tmp_path / "m.xml")
    assert code == 0 and err.startswith("dextar export: note: ") and "has no table" in err
    code, err = _cli(capsys, "excite", files["metres"], "--duration", "5", "--harmonics", "2",
                     "--out", tmp_path / "e.csv", "--quiet")
    assert err.startswith("dextar excite: note: ") and SAID in err
    # the pick-and-place robot's data against a robot in metres: a poor fit, and the note
    code, err = _cli(capsys, "identify", excite_csv, "--config", files["metres"], "--out",
                     tmp_path / "id", "--quiet", "--no-figures")  # (its words are checked)
    assert code == 1 and err.startswith("dextar identify: note: ") and SAID in err
