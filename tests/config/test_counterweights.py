"""[inertia] counterweights: read in config units, folded into the proximal rods of every
command's model, written back by a model file to the same model, refused by name."""

import tomllib

import numpy as np
import pytest

from dextar.cli import main
from dextar.config import scenario_from_dict
from dextar.dynamics import Counterweight, Model, inverse_dynamics
from dextar.output.config_file import model_toml

DOC = {"inertia": {"effector_mass": 0.2, "counterweight_mass": [0.3, 0.2],
                   "counterweight_distance": 30.0, "counterweight_inertia": [10.0, 0.0]},
       "gravity": {"vector": [0.0, -9810.0]}, "output": {"units": "si"}}


def test_counterweights_are_folded_into_the_rods():
    sc = scenario_from_dict(DOC)
    ine = sc.si_model.inertia
    assert ine.counterweights == (Counterweight(0.3, 0.03, 1e-5), Counterweight(0.2, 0.03))
    plain = scenario_from_dict({k: v for k, v in DOC.items() if k != "inertia"} | {
        "inertia": {"effector_mass": 0.2}}).si_model.inertia
    for rod, bare, cw in zip(ine.proximal, plain.proximal, ine.counterweights, strict=True):
        assert rod.mass == pytest.approx(bare.mass + cw.mass)
        assert rod.first_moment == pytest.approx(bare.first_moment - cw.mass * 0.03)
    # the paper's units too (masses over the effector's, lengths over L)
    paper = scenario_from_dict({**DOC, "output": {"units": "paper"}}).inertia
    assert paper.counterweights[0].mass == pytest.approx(0.3 / 0.2)
    assert paper.counterweights[0].distance == pytest.approx(30.0 / 87.0)


def test_a_model_file_gives_the_same_model_back():
    sc = scenario_from_dict(DOC)
    ine = sc.si_model.inertia
    text = model_toml(sc.robot_mm, "+-", "up", ine, coulomb_speed_deg_s=0.01,
                      gravity_mm_s2=(0.0, -9810.0))
    assert "counterweight_mass = [0.3, 0.2]" in text and "counterweight_distance = [30.0, 30.0]" in text
    back = scenario_from_dict(tomllib.loads(text)).si_model.inertia
    assert back.counterweights == ine.counterweights
    for a, b in zip(back.proximal, ine.proximal, strict=True):
        assert (a.mass, a.com, a.inertia) == pytest.approx((b.mass, b.com, b.inertia), rel=1e-12)


@pytest.mark.slow
def test_torques_command_uses_them(tmp_path):
    cfg = tmp_path / "cw.toml"
    cfg.write_text('[inertia]\neffector_mass = 0.2\ncounterweight_mass = [0.3, 0.2]\n'
                   'counterweight_distance = 30.0\ncounterweight_inertia = [10.0, 0.0]\n'
                   '[gravity]\nvector = [0.0, -9810.0]\n[output]\nunits = "si"\n')
    out = tmp_path / "t.csv"
    assert main(["torques", str(cfg), "--out", str(out)]) == 0
    head = out.read_text().splitlines()[0].split(",")
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    col = {k: i for i, k in enumerate(head)}
    q = data[:, [col["phi_rad"], col["psi_rad"]]]
    dq = data[:, [col["dphi_rad_s"], col["dpsi_rad_s"]]]
    ddq = data[:, [col["ddphi_rad_s2"], col["ddpsi_rad_s2"]]]
    sc = scenario_from_dict(DOC)
    tau = inverse_dynamics(Model(sc.si_model.robot, sc.si_model.inertia), q, dq, ddq)
    got = data[:, [col["tau1_Nm"], col["tau2_Nm"]]]
    assert np.abs(got - tau).max() < 1e-9 * np.abs(tau).max()
    bare = inverse_dynamics(Model(sc.si_model.robot, sc.si_model.inertia.with_(
        proximal=sc.si_model.inertia.bare_proximal)), q, dq, ddq)
    assert np.abs(got - bare).max() > 0.1 * np.abs(tau).max()  # they are not left out


@pytest.mark.parametrize("inertia, message", [
    ({"counterweight_mass": 0.3}, r"\[inertia\].counterweight_mass needs "
                                  r"\[inertia\].counterweight_distance"),
    ({"counterweight_mass": 0.3, "counterweight_distance": -5.0},
     r"\[inertia\].counterweight_distance must be at least 0"),
    ({"counterweight_inertia": 3.0, "counterweight_distance": 5.0},
     "a counterweight of no mass has no inertia"),
    ({"counterweight_mass": [0.1, 0.2, 0.3], "counterweight_distance": 5.0},
     r"\[inertia\].counterweight_mass must be a number or a pair"),
])
def test_bad_counterweights_exit_2(tmp_path, capsys, inertia, message):
    import re

    from ..robustness.harness import toml_text

    cfg = tmp_path / "bad.toml"
    cfg.write_text(toml_text({"inertia": inertia}))
    assert main(["torques", str(cfg), "--out", str(tmp_path / "t.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and re.search(message, err), err
