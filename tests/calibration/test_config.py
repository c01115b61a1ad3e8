"""The calibrated config as the commands read it: its model comes back to the last digit,
its encoder counts, its instrument noise; a fit kept with its outliers writes a diagnosis,
not a config."""

import json
import math
import tomllib

import numpy as np
import pytest

import dextar.calibration as cal
from dextar import FiveBar
from dextar.config import load_kinematics, load_scenario
from dextar.output import calibration as out

from .conftest import COUNT, NOMINAL, true_robot

#: A calibrated model (stored values, SI), the instrument frame anywhere.
MODEL = cal.KinematicModel(FiveBar(0.07213456789, 0.0719876543, 0.08712345, 0.0869012345,
                                   0.0600987654), math.radians(0.31234567),
                           math.radians(-0.4876543), 1.2345678, -0.3456789,
                           math.radians(-139.0764467))


def test_calibrated_config_loads_with_its_model(tmp_path):
    path = tmp_path / "calibrated.toml"
    path.write_text(out.calibrated_toml(MODEL, working_mode="-+", assembly_mode="up",
                                        encoder_counts=2.0**17, sigma_mm=0.02,
                                        extra={"output": {"units": "si"},
                                               "program": {"start": [0.0, 110.0]}}))
    sc = load_scenario(path)
    back = sc.kinematic_model
    np.testing.assert_allclose(back.vector(), MODEL.vector(), rtol=1e-14, atol=0)
    assert sc.mode == "-+" and sc.output.units == "si"
    assert sc.robot_table.encoder_counts == 2**17 and sc.instrument_table.sigma_mm == 0.02
    assert "encoder_counts = 131072\n" in path.read_text()       # an integer, as typed
    rt, inst = load_kinematics(path)                               # what ik and fk read
    assert rt == sc.robot_table and inst == sc.instrument_table
    # points measured in the robot frame: no frame, the instrument's noise kept
    path.write_text(out.calibrated_toml(MODEL, working_mode="+-", assembly_mode="up",
                                        frame_identified=False, sigma_mm=0.05))
    sc = load_scenario(path)
    assert sc.instrument_table.frame == (0.0, 0.0, 0.0) and sc.instrument_table.sigma_mm == 0.05
    assert sc.kinematic_model.phi_offset == pytest.approx(MODEL.phi_offset, rel=1e-14)
    assert "instrument" not in tomllib.loads(
        out.calibrated_toml(MODEL, working_mode="+-", assembly_mode="up",
                            frame_identified=False))


def test_a_fit_with_its_outliers_is_a_diagnosis(four_modes):
    rng = np.random.default_rng(3)
    data = cal.measure(true_robot(rng), four_modes.readings, 1, rng, point_std=0.02e-3,
                       count=COUNT)
    P = data.points.copy()
    P[[4, 9]] += [[1e-3, 0.0], [0.0, -0.7e-3]]
    bad = cal.PoseData(data.readings, P, data.modes, data.assembly)
    with pytest.raises(cal.OutlierError) as e:
        cal.calibrate(bad, NOMINAL)
    assert set(e.value.rows) == {6, 11}
    res = cal.calibrate(bad, NOMINAL, outlier_factor=1e300)     # what the command keeps
    files = out.calibration_files(res, data="m.csv", working_mode="+-", assembly_mode="up",
                                  figures=False, outliers=e.value.rows,
                                  outlier_message=str(e.value))
    assert set(files) == {"parameters.csv", "summary.json"}
    s = json.loads(files["summary.json"])
    assert s["status"] == "outliers" and s["status_code"] == 3 and not s["success"]
    assert s["outlier_rows"] == list(e.value.rows) and s["message"] == str(e.value)
    ok = out.calibration_files(cal.calibrate(data, NOMINAL), data="m.csv", working_mode="+-",
                               assembly_mode="up", figures=False)
    assert "calibrated.toml" in ok and json.loads(ok["summary.json"])["outlier_rows"] == []
