import numpy as np
import pytest

from dextar.dynamics import Model, inverse_dynamics, paper_inertia
from dextar.dynamics.forward import forward_dynamics, torques_from_samples
from dextar.output.mjcf import mujoco_state, to_mjcf
from dextar.trajectory import sample_trajectory

from .conftest import ROBOT, SEMI

mujoco = pytest.importorskip("mujoco")


def test_forward_of_inverse_returns_trajectory(paper_traj, paper_model):
    tr = paper_traj
    tau = inverse_dynamics(paper_model, tr.q, tr.dq, tr.ddq)
    res = forward_dynamics(paper_model, torques_from_samples(tr.t, tau), tr.q[0], tr.dq[0], tr.t)
    span = np.ptp(tr.q, axis=0)
    assert (np.abs(res.q[-1] - tr.q[-1]) / span).max() < 1e-6
    assert (np.abs(res.q - tr.q).max(axis=0) / span).max() < 1e-6


def test_forward_with_exact_torque_function(law):
    model = Model(ROBOT, paper_inertia(ROBOT).with_(gravity=(0.0, -1.0), payload=0.2,
                                                     viscous=(0.05, 0.05)))

    def torque(t, _q, _dq):
        s = sample_trajectory(ROBOT, SEMI, law, times=np.array([t]))
        return inverse_dynamics(model, s.q, s.dq, s.ddq)[0]

    tr = sample_trajectory(ROBOT, SEMI, law, samples=11)
    res = forward_dynamics(model, torque, tr.q[0], tr.dq[0], tr.t)
    assert np.abs(res.q - tr.q).max() < 1e-7


@pytest.mark.parametrize("changes", [
    {},
    {"gravity": (0.0, -3.0)},
    {"gravity": (1.0, -2.0), "payload": 0.4, "rotor": (0.01, 0.02)},
])
def test_mujoco_gives_back_our_accelerations(law, changes):
    model = Model(ROBOT, paper_inertia(ROBOT).with_(**changes))
    tr = sample_trajectory(ROBOT, SEMI, law, samples=41)
    tau = inverse_dynamics(model, tr.q, tr.dq, tr.ddq)
    mm = mujoco.MjModel.from_xml_string(to_mjcf(model))
    data = mujoco.MjData(mm)
    qpos, qvel = mujoco_state(model, tr.q, tr.dq)
    got = np.empty_like(tr.ddq)
    for i in range(len(tr.t)):
        data.qpos[:], data.qvel[:], data.ctrl[:] = qpos[i], qvel[i], tau[i]
        mujoco.mj_forward(mm, data)
        got[i] = data.qacc[[0, 2]]
    rel = np.abs(got - tr.ddq).max() / np.abs(tr.ddq).max()
    assert rel < 1e-3
    # and the loop-closure constraint is active and satisfied by the state we set
    assert data.nefc >= 2 and np.abs(data.efc_pos[:data.nefc]).max() < 1e-10


def test_mujoco_general_robot_and_rods():
    """An asymmetric five-bar with non-uniform rods, gravity and rotors, on random motions."""
    from dextar.dynamics import Inertia, Rod
    from dextar.geometry import FiveBar

    from .conftest import random_joint_motion

    robot = FiveBar(l1=0.8, l2=0.9, L1=1.1, L2=1.0, d=0.6)
    ine = Inertia(proximal=(Rod(0.08, 0.3, 0.004), Rod(0.11, 0.5, 0.006)),
                  distal=(Rod(0.1, 0.6, 0.009), Rod(0.07, 0.35, 0.005)), effector_mass=1.0,
                  payload=0.3, rotor=(0.01, 0.02), gravity=(0.5, -2.0))
    model = Model(robot, ine)
    t = np.linspace(0, 1, 30)
    q, dq, ddq = random_joint_motion(np.random.default_rng(11), t)
    tau = inverse_dynamics(model, q, dq, ddq)
    mm = mujoco.MjModel.from_xml_string(to_mjcf(model))
    data = mujoco.MjData(mm)
    qpos, qvel = mujoco_state(model, q, dq)
    got = np.empty_like(ddq)
    for i in range(len(t)):
        data.qpos[:], data.qvel[:], data.ctrl[:] = qpos[i], qvel[i], tau[i]
        mujoco.mj_forward(mm, data)
        got[i] = data.qacc[[0, 2]]
    assert np.abs(got - ddq).max() / np.abs(ddq).max() < 1e-3


@pytest.mark.slow
def test_mujoco_replays_our_torques_open_loop(tmp_path):
    """The exported model (friction, gravity, payload, rotors; keyframe at the start) driven
    open loop by our torques follows the paper's motion within 1e-3 rad."""
    from dextar.cli import main
    from dextar.config import scenario_from_dict

    doc = {"inertia": {"effector_mass": 1.0, "payload": 0.1, "proximal_mass": 0.08,
                       "distal_mass": 0.1, "rotor_inertia": 50.0},
           "friction": {"viscous": 1e-3, "coulomb": 0.02},
           "gravity": {"vector": [0.0, -9810.0]}, "output": {"units": "si"}}
    cfg = tmp_path / "c.toml"
    cfg.write_text('[inertia]\neffector_mass = 1.0\npayload = 0.1\nproximal_mass = 0.08\n'
                   'distal_mass = 0.1\nrotor_inertia = 50.0\n[friction]\nviscous = 1e-3\n'
                   'coulomb = 0.02\n[gravity]\nvector = [0.0, -9810.0]\n[output]\nunits = "si"\n')
    xml = tmp_path / "m.xml"
    assert main(["export", "mjcf", str(cfg), "--out", str(xml)]) == 0
    text = xml.read_text()
    assert 'frictionloss="0.02"' in text and 'damping="0.001"' in text and '<key name="start"' in text
    sc = scenario_from_dict(doc)
    law = sc.law()
    m = mujoco.MjModel.from_xml_path(str(xml))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("start").id)
    mujoco.mj_forward(m, d)
    assert np.abs(d.efc_pos[d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY]).max() < 1e-12
    dt = m.opt.timestep
    n = int(round(law.duration / dt))
    mid = sample_trajectory(sc.robot, sc.path, law, mode=sc.mode, times=(np.arange(n) + 0.5) * dt)
    tau = inverse_dynamics(sc.model(mid.assembly), mid.q, mid.dq, mid.ddq)
    got = np.empty((n, 2))
    for k in range(n):  # the torque of the middle of each step, held over the step
        d.ctrl[:] = tau[k]
        mujoco.mj_step(m, d)
        got[k] = d.qpos[[0, 2]]
    ref = sample_trajectory(sc.robot, sc.path, law, mode=sc.mode,
                            times=np.minimum((np.arange(n) + 1) * dt, law.duration))
    assert np.abs(got - ref.q).max() < 1e-3
    # without the exported friction the replay goes visibly wrong: friction matters
    m.dof_frictionloss[:] = 0.0
    mujoco.mj_resetDataKeyframe(m, d, m.key("start").id)
    for k in range(n):
        d.ctrl[:] = tau[k]
        mujoco.mj_step(m, d)
    assert np.abs(d.qpos[[0, 2]] - ref.q[-1]).max() > 1e-2
