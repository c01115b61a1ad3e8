"""A robot that no part of dextar's dynamics simulates: MuJoCo runs the exported five-bar
(friction, gravity, payload, rotors, masses unlike the prior's) under a stiff PD loop with the
prior's feedforward, and records what a drive would (angles and applied torques at 1 kHz).

Shared by tests/identification/test_mujoco_identification.py and
benchmarks/bench_identify_mujoco.py (which imports this file by path); mujoco is a test and
benchmark dependency only.

The loop: a PD at the 10 kHz inner rate inside MuJoCo (a ``general`` actuator with an affine
bias ``-kp q - kd qdot``; the control ``ff + kp q_d + kd qdot_d`` is precomputed), so the
whole run is one ``mujoco.rollout`` call in C. The bandwidth (:data:`BANDWIDTH_HZ` on the
joint inertia :data:`JOINT_INERTIA`, critically damped) keeps the robot within 0.01 deg of
the set-points over the excitations, where a 20 Hz loop drifted 10-17 deg and changed
assembly mode. MuJoCo's Euler integrator (not the export's RK4) computes the actuator force
once, at the start of each step, so the torque a step applies is exactly
``ctrl - kp q - kd qdot`` of its first state; the recorded torque is that of the step
starting at the sample. (Under RK4 the bias is re-evaluated at each stage and no single
value is the torque applied: 1.5 % / 3 % of apparent model error on the semicircle, where
Euler at 10 kHz leaves 0.005 % / 0.014 % against the true parameters, 4x faster.)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout

from dextar.dynamics import Model, Rod, inverse_dynamics
from dextar.kinematics import direct_kinematics, elbows
from dextar.kinematics.checker import pose_distances
from dextar.output.mjcf import to_mjcf

#: Position-loop bandwidth (Hz) and the joint inertia (kg m^2) its gains are set for; the
#: robot's mass matrix has 8.5e-4 kg m^2 on its diagonal at the rest pose.
BANDWIDTH_HZ = 100.0
JOINT_INERTIA = 1e-3
#: Drive sample rate (Hz) and inner steps per sample.
RATE = 1000
SUB = 10

Motion = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]


def true_robot(prior: Model) -> Model:
    """The robot MuJoCo simulates: heavier rods, moved centres, rotors, other friction."""
    ine = prior.inertia

    def rod(r: Rod, f: float) -> Rod:
        return Rod(r.mass * f, r.com * 0.9, r.inertia * f)

    return Model(prior.robot, ine.with_(
        proximal=(rod(ine.proximal[0], 1.3), rod(ine.proximal[1], 1.2)),
        distal=(rod(ine.distal[0], 1.25), rod(ine.distal[1], 1.15)),
        effector_mass=ine.effector_mass * 1.1, rotor=(2e-5, 3e-5), viscous=(0.008, 0.012),
        coulomb=(0.025, 0.018)), prior.assembly)


@dataclass(frozen=True)
class Run:
    """A tracked motion sampled at :data:`RATE`.

    Attributes
    ----------
    t, q, tau : ndarray, shapes (n,), (n, 2), (n, 2)
        Times, the robot's angles and the torques applied (SI).
    tracking_error_deg : float
        Largest |q - q_desired| over every inner step.
    assembly_gap_mm : float
        Largest distance between MuJoCo's end-effector and the one of the model's assembly
        mode at the same angles (0 to rounding while the robot stays in that mode).
    type2_sign_changes : int
        Sign changes of the type-2 indicator of MuJoCo's own pose (0: no parallel
        singularity crossed).
    """

    t: np.ndarray
    q: np.ndarray
    tau: np.ndarray
    tracking_error_deg: float
    assembly_gap_mm: float
    type2_sign_changes: int


def _pd_model(true: Model, q0: np.ndarray, dq0: np.ndarray) -> tuple[mujoco.MjModel, float, float]:
    w = 2 * np.pi * BANDWIDTH_HZ
    kp, kd = JOINT_INERTIA * w * w, 2 * JOINT_INERTIA * w
    xml = to_mjcf(true, start=(q0, dq0))
    for name, joint in (("motor_A", "phi"), ("motor_D", "psi")):
        xml = xml.replace(f'<motor name="{name}" joint="{joint}" gear="1"/>',
                          f'<general name="{name}" joint="{joint}" gear="1" '
                          f'biastype="affine" biasprm="0 {-kp:.17g} {-kd:.17g}"/>')
    assert xml.count("<general") == 2
    m = mujoco.MjModel.from_xml_string(xml)
    m.opt.timestep = 1.0 / (RATE * SUB)
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    return m, kp, kd


def track(true: Model, prior: Model, motion: Motion, duration: float) -> Run:
    """Track ``motion`` (times (n,) -> q, dq, ddq, each (n, 2)) for ``duration`` s on
    MuJoCo's robot ``true`` under the PD loop with ``prior``'s feedforward."""
    n = int(round(duration * RATE)) + 1
    tt = np.arange((n - 1) * SUB + 1) / (RATE * SUB)
    qd, dqd, ddqd = motion(tt)
    m, kp, kd = _pd_model(true, qd[0], dqd[0])
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("start").id)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    s0 = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, s0, spec)
    ctrl = inverse_dynamics(prior, qd, dqd, ddqd) + kp * qd + kd * dqd
    states, _ = rollout.rollout(m, d, s0[None], ctrl[None, :-1], initial_warmstart=None)
    states = np.concatenate([s0[None], states[0]])
    # layout of the full physics state: time, qpos (4), qvel (4), ...
    qpos, qvel = states[:, 1:5], states[:, 5:9]
    q, dq = qpos[:, [0, 2]], qvel[:, [0, 2]]
    applied = ctrl[:-1] - kp * q[:-1] - kd * dq[:-1]  # each step's force (Euler)
    err = float(np.degrees(np.abs(q - qd).max()))
    # MuJoCo's own end-effector (the tip of leg 1) against the model's assembly mode
    B, C = elbows(true.robot, q)
    th = qpos[:, 0] + qpos[:, 1]
    P = B + true.robot.L1 * np.stack([np.cos(th), np.sin(th)], -1)
    Pm = direct_kinematics(true.robot, q, true.assembly)
    gap = float(1e3 * np.hypot(*(P - Pm).T).max())
    s = np.sign(pose_distances(true.robot, q, P).type2_signed)
    changes = int((s[1:] != s[:-1]).sum())
    k = np.arange(n) * SUB
    return Run(tt[k], q[k], applied[np.minimum(k, len(applied) - 1)], err, gap, changes)
