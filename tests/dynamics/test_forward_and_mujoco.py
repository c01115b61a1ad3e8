import numpy as np
import pytest

from dextar.dynamics import Model, inverse_dynamics, paper_inertia
from dextar.dynamics.forward import forward_dynamics, torques_from_samples
from dextar.export.mjcf import mujoco_state, to_mjcf
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
    # and the constraint is satisfied by the state we set
    assert np.abs(data.efc_pos).max() < 1e-10 if data.nefc else True


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
