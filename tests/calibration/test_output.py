"""The calibration's files as the command will write them: texts parse, numbers round-trip,
figures are drawn without pyplot, no NaN reaches a file."""

import csv
import io
import json
import math
import tomllib

import numpy as np
import pytest
from matplotlib.figure import Figure

import dextar.calibration as cal
from dextar import FiveBar
from dextar.output import calibration as out

from .conftest import COUNT, NOMINAL


@pytest.fixture(scope="session")
def result(four_modes, held_out):
    rng = np.random.default_rng(7)
    true = cal.perturbed(NOMINAL, rng)
    data = cal.measure(true, four_modes.readings, 1, rng, point_std=0.02e-3, count=COUNT)
    held = cal.measure(true, held_out, 1, rng, point_std=0.02e-3, count=COUNT)
    return cal.calibrate(data, NOMINAL, validation=held), held


def test_parameters_csv_in_mm_and_degrees(result):
    res, _ = result
    rows = list(csv.DictReader(io.StringIO(out.parameters_csv(res))))
    assert [r["name"] for r in rows] == list(cal.NAMES)
    assert list(rows[0]) == ["name", "nominal", "value", "std", "unit"]
    by = {r["name"]: r for r in rows}
    assert by["l1"]["nominal"] == "72.0" and by["l1"]["unit"] == "mm"
    assert by["phi_offset"]["unit"] == "deg"
    assert float(by["L2"]["value"]) == pytest.approx(1e3 * res.calibrated.robot.L2, rel=1e-14)
    assert float(by["theta0"]["std"]) == pytest.approx(
        math.degrees(res.parameter("theta0").std), rel=1e-14)


def test_summary_is_json_with_the_issues_fields(result):
    res, _ = result
    maps = [cal.accuracy_map(res.calibrated, res.identifiable, res.covariance, m,
                             resolution=41) for m in ("+-", "--")]
    s = out.calibration_summary(res, data="measured.csv", accuracy=maps,
                                encoder_counts=2**17)
    text = json.dumps(s, allow_nan=False)
    back = json.loads(text)
    for key in ("status", "n_poses", "identifiable", "not_identifiable",
                "rms_error_before_mm", "rms_error_after_mm", "max_error_before_mm",
                "max_error_after_mm", "validation"):
        assert key in back
    assert back["status"] == "calibrated" and back["n_poses"] == 60
    assert set(back["validation"]) == {"n_poses", "rms_error_before_mm", "rms_error_after_mm",
                                       "max_error_before_mm", "max_error_after_mm"}
    assert back["rms_error_after_mm"] == pytest.approx(1e3 * res.rms_error_after)
    assert set(back["accuracy"]["modes"]) == {"+-", "--"}
    html = out.calibration_report(s, {"residuals": b"\x89PNG"})
    assert html.startswith("<!DOCTYPE html>") and "theta0" in html and "data:image/png" in html


def test_calibrated_config_parses_and_round_trips(result):
    res, _ = result
    text = out.calibrated_toml(res.calibrated, working_mode="+-", assembly_mode="up",
                               encoder_counts=2**17, comment="calibrated by dextar",
                               extra={"units": "si", "robot": {"preset": "dextar"},
                                      "inertia": {"payload": 0.1, "tip": {"m": 1.0}},
                                      "move": [{"type": "line", "to": [1.0, 2.0]}]})
    doc = tomllib.loads(text)
    r = doc["robot"]
    assert r["L1"] == pytest.approx(1e3 * res.calibrated.robot.L1, rel=1e-14)
    assert r["encoder_offset_deg"][1] == pytest.approx(
        math.degrees(res.calibrated.psi_offset), rel=1e-14)
    assert r["encoder_counts"] == 2**17 and "preset" not in r
    back = cal.KinematicModel.from_config_units(
        FiveBar(*(r[k] for k in ("l1", "l2", "L1", "L2", "d"))),
        encoder_offset_deg=r["encoder_offset_deg"],
        instrument=(doc["instrument"]["x0_mm"], doc["instrument"]["y0_mm"],
                    doc["instrument"]["theta0_deg"]))
    np.testing.assert_allclose(back.vector(), res.calibrated.vector(), rtol=1e-13, atol=1e-16)
    assert doc["units"] == "si" and doc["inertia"]["tip"] == {"m": 1.0}
    assert doc["move"] == [{"type": "line", "to": [1.0, 2.0]}]
    no_frame = tomllib.loads(out.calibrated_toml(res.calibrated, working_mode="+-",
                                                 assembly_mode="up", frame_identified=False))
    assert "instrument" not in no_frame


@pytest.mark.slow
def test_figures_are_drawn(result, four_modes):
    """The figures calibration_files does not draw (it draws the residuals with held-out
    poses and the accuracy maps with the poses)."""
    res, _ = result
    figs = [out.residuals_figure(res), out.poses_figure(four_modes, NOMINAL.robot)]
    assert all(isinstance(f, Figure) for f in figs)
    assert len(figs[0].axes) == 2 and len(figs[1].axes) == 1


def test_poses_csv_and_summary(four_modes):
    rows = list(csv.DictReader(io.StringIO(out.poses_csv(four_modes))))
    assert list(rows[0]) == ["mode", "assembly", "phi_deg", "psi_deg", "x_mm", "y_mm"]
    assert len(rows) == 60 and rows[0]["mode"] == "+-" and rows[0]["assembly"] == "up"
    s = out.poses_summary(four_modes)
    json.dumps(s, allow_nan=False)
    assert s["index"] == "O1" and s["o1"] == four_modes.observability.o1
    assert sum(s["modes"].values()) == 60


@pytest.mark.slow
def test_every_file_of_the_command(result, tmp_path):
    res, held = result
    files = out.calibration_files(res, data="measured.csv", working_mode="+-",
                                  assembly_mode="up", encoder_counts=2**17, validation=held,
                                  resolution=41, dpi=30)
    assert set(files) == {"calibrated.toml", "parameters.csv", "summary.json",
                          "residuals.png", "accuracy.png", "report.html"}
    s = json.loads(files["summary.json"])
    assert set(s["accuracy"]["modes"]) == set(res.data.modes)
    assert tomllib.loads(files["calibrated.toml"])["robot"]["encoder_counts"] == 2**17
    assert files["accuracy.png"].startswith(b"\x89PNG")
    assert files["residuals.png"].startswith(b"\x89PNG")
    for name, content in files.items():
        (tmp_path / name).write_bytes(content if isinstance(content, bytes)
                                      else content.encode())
    assert "nan" not in files["summary.json"].lower()
