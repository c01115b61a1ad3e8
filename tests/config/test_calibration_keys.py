"""The calibration's config keys: [robot].encoder_offset_deg and encoder_counts, the
[instrument] table; read by key, refused by key, converted once (a task file speaks encoder
readings, the domain geometric angles)."""

import math

import numpy as np
import pytest

from dextar import DEXTAR_MM
from dextar.calibration import KinematicModel
from dextar.config import load_kinematics, scenario_from_dict
from dextar.config.kinematic import InstrumentTable, RobotTable
from dextar.errors import ConfigError


def test_defaults_are_a_robot_seen_from_its_own_frame():
    sc = scenario_from_dict({})
    assert sc.robot_table.encoder_offset_deg == (0.0, 0.0)
    assert sc.robot_table.encoder_counts is None
    assert sc.instrument_table == InstrumentTable() and sc.instrument_table.sigma_mm is None
    assert sc.kinematic_model == KinematicModel(DEXTAR_MM.scaled(1e-3))
    assert load_kinematics(None) == (RobotTable(), None)


def test_values_reach_the_model_in_si(tmp_path):
    doc = {"robot": {"preset": "dextar", "L1": 87.5, "encoder_offset_deg": [0.25, -0.5],
                     "encoder_counts": 4096},
           "instrument": {"x0_mm": 1200.0, "y0_mm": -400, "theta0_deg": 130.0,
                          "sigma_mm": 0.02}}
    sc = scenario_from_dict(doc)
    m = sc.kinematic_model
    assert m.robot.L1 == pytest.approx(0.0875, rel=1e-15)
    assert (m.phi_offset, m.psi_offset) == (math.radians(0.25), math.radians(-0.5))
    assert (m.x0, m.y0, m.theta0) == (1.2, -0.4, math.radians(130.0))
    assert sc.robot_table.encoder_counts == 4096 and sc.instrument_table.sigma_mm == 0.02
    f = tmp_path / "c.toml"
    f.write_text('[robot]\nencoder_offset_deg = [0.25, -0.5]\n[instrument]\nx0_mm = 3.0\n')
    rt, inst = load_kinematics(f)
    assert rt.encoder_offset_deg == (0.25, -0.5) and inst is not None and inst.x0_mm == 3.0
    assert rt.geometric_deg((10.0, 20.0)) == (10.25, 19.5)


def test_instrument_frame_conversions_are_the_models():
    inst = InstrumentTable(1200.0, -400.0, 130.0)
    model = KinematicModel(DEXTAR_MM.scaled(1e-3), x0=1.2, y0=-0.4,
                           theta0=math.radians(130.0))
    P = (12.5, 140.0)
    M = inst.to_instrument_mm(P)
    assert M == pytest.approx(tuple(1e3 * model.to_instrument(np.array(P) * 1e-3)),
                              abs=1e-9)
    assert inst.to_robot_mm(M) == pytest.approx(P, abs=1e-9)


@pytest.mark.parametrize("doc, words", [
    ({"robot": {"encoder_offset_deg": 0.3}}, "[robot].encoder_offset_deg must be a pair [phi, "
     "psi] in degrees, got float 0.3"),
    ({"robot": {"encoder_offset_deg": [0.0, 200.0]}},
     "[robot].encoder_offset_deg must be at most 180, got 200.0"),
    ({"robot": {"encoder_offset_deg": ["a", 0]}}, "[robot].encoder_offset_deg must be a number"),
    ({"robot": {"encoder_counts": 0}}, "[robot].encoder_counts must be positive, got 0"),
    ({"robot": {"encoder_count": 4096}}, "[robot].encoder_count is not known"),
    ({"instrument": {"x0": 1.0}}, "[instrument].x0 is not known; known keys: x0_mm"),
    ({"instrument": {"sigma_mm": -0.01}}, "[instrument].sigma_mm must be positive"),
    ({"instrument": {"theta0_deg": "30"}}, "[instrument].theta0_deg must be a number"),
    ({"instrument": 3}, "config key 'instrument' must be a table [instrument]"),
])
def test_bad_keys_are_named(doc, words):
    with pytest.raises(ConfigError) as e:
        scenario_from_dict(doc)
    assert words in str(e.value)


def test_a_joint_move_speaks_encoder_readings():
    """to_deg = [80, 130] readings: the domain's geometric target is reading + offset."""
    move = {"type": "joint", "to_deg": [80.0, 130.0]}
    plain = scenario_from_dict({"move": [move]})
    off = scenario_from_dict({"robot": {"encoder_offset_deg": [1.0, -2.0]}, "move": [move]})
    assert plain.moves[0].get("to_q") == pytest.approx(np.radians([80.0, 130.0]), abs=0)
    assert off.moves[0].get("to_q") == pytest.approx(np.radians([81.0, 128.0]), abs=1e-15)
    line = {"type": "line", "to": [0.0, 100.0]}      # points are points: unchanged
    sc = scenario_from_dict({"robot": {"encoder_offset_deg": [1.0, -2.0]}, "move": [line]})
    assert sc.moves[0].get("to") == pytest.approx((0.0, 0.1), abs=1e-16)
