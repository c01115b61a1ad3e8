"""``dextar export mjcf`` speaks SI (m, kg, s) unless ``--units paper``: a MuJoCo user loads
a model whose gravity is 9.81 m/s^2 and whose masses are kilograms, whatever the config's
``[output].units`` (the paper's, by default) says."""

import json
import xml.etree.ElementTree as ET

import pytest

from dextar.cli import main

#: gravity in mm/s^2, a 0.5 kg effector with a 0.1 kg payload; rods of the DexTAR
#: (l = 72 mm, L = 87 mm), proximal rods 0.08 x and distal rods 0.1 x the effector's mass
CONFIG = """\
[gravity]
vector = [0.0, -9810.0]

[inertia]
effector_mass = 0.5
payload = 0.1
"""
#: proximal 2 x 0.04, distal 2 x 0.05, effector and payload 0.6 (kg)
TOTAL_KG = 0.78


def _export(tmp_path, capsys, extra="", *argv):
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG + extra)
    xml = tmp_path / "m.xml"
    code = main(["export", "mjcf", str(cfg), "--out", str(xml), "--json", *argv])
    payload = json.loads(capsys.readouterr().out)
    assert code == 0
    return ET.parse(xml).getroot(), xml.read_text(), payload


def _figures(root):
    gravity = [float(v) for v in root.find("option").get("gravity").split()]
    masses = [float(e.get("mass")) for e in root.iter("inertial")]
    capsule = root.find(".//body[@name='proximal1']/geom").get("fromto").split()
    return gravity, sum(masses), float(capsule[3])


@pytest.mark.parametrize("units", ["", '[output]\nunits = "paper"\n', '[output]\nunits = "si"\n'])
def test_export_is_si_by_default(tmp_path, capsys, units):
    """Before: gravity 112.8 (9.81 m/s^2 in rod lengths of 87 mm per second^2), masses
    relative to the effector's, l1 = 0.83 (in units of L): paper units unless told."""
    root, text, payload = _export(tmp_path, capsys, units)
    gravity, mass, l1 = _figures(root)
    assert gravity == pytest.approx([0.0, -9.81, 0.0], abs=1e-12)
    assert mass == pytest.approx(TOTAL_KG, rel=1e-12)
    assert l1 == pytest.approx(0.072, rel=1e-12)
    assert "SI units: m, kg, s" in text and payload["units"]["system"] == "si"


def test_paper_units_only_when_asked(tmp_path, capsys):
    root, text, payload = _export(tmp_path, capsys, "", "--units", "paper")
    gravity, mass, l1 = _figures(root)
    # length unit L = 87 mm, mass unit m = 0.5 kg, time unit T = 1 s
    assert gravity[1] == pytest.approx(-9810.0 / 87.0, rel=1e-12)
    assert mass == pytest.approx(TOTAL_KG / 0.5, rel=1e-12)
    assert l1 == pytest.approx(72.0 / 87.0, rel=1e-12)
    assert "paper units: length L = 87 mm" in text and payload["units"]["system"] == "paper"


def test_the_si_model_weighs_what_the_config_says_in_mujoco(tmp_path, capsys):
    """MuJoCo itself reads 9.81 m/s^2 and 0.78 kg (bodies' masses; the world's is 0)."""
    mujoco = pytest.importorskip("mujoco")
    _, _, payload = _export(tmp_path, capsys)
    m = mujoco.MjModel.from_xml_path(payload["out"])
    assert m.opt.gravity[1] == pytest.approx(-9.81, abs=1e-12)
    assert float(m.body_mass.sum()) == pytest.approx(TOTAL_KG, rel=1e-9)
