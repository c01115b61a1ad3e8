"""MuJoCo, an independent engine, follows the planned crossing of the parallel singularity
curve into the other assembly mode: the exported model (its loop closed by an equality
constraint in MuJoCo's own coordinates) driven by the planned torques and the
singularity-robust task-space loop of dextar.simulation.crossing, at 2 kHz with the torques
held between updates."""

from dataclasses import replace

import numpy as np
import pytest

from dextar.dynamics import Model, gravity_torques
from dextar.dynamics.closed_chain import task_state
from dextar.dynamics.crossing import PlannedTorques
from dextar.kinematics import assembly_mode
from dextar.output.mjcf import to_mjcf
from dextar.simulation.crossing import sr_inverse
from dextar.trajectory import path_motion, sample_trajectory

from ..crossing_cases import CASES, planned

mujoco = pytest.importorskip("mujoco")


def drive(case, law, truth, *, feedback=True, hz=30.0, every=5, hold=0.02):
    """Drive MuJoCo's model of ``truth`` along the planned law (then hold the end for
    ``hold`` s); returns the largest and the final distance of its end-effector to the plan
    (m) and the assembly signs it went through."""
    tr = sample_trajectory(case.robot, case.path, law, mode="+-", samples=3,
                           crossings=case.crossings)
    m = mujoco.MjModel.from_xml_string(to_mjcf(truth, start=(tr.q[0], tr.dq[0])))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("start").id)
    mujoco.mj_forward(m, d)
    dt = m.opt.timestep
    n = int(np.ceil((law.duration + hold) / dt))
    ticks = np.arange(0, n + every, every) * dt
    mid = ticks + 0.5 * every * dt
    ff = PlannedTorques(case.dynamics, law)(np.minimum(mid, law.duration))
    ff[mid > law.duration] = gravity_torques(replace(case.model, assembly="down"), tr.q[-1])
    Pd, dPd = path_motion(case.path, law, np.minimum(ticks, law.duration))[6:8]
    dPd[ticks > law.duration] = 0.0
    s1, s2 = m.site("tip1").id, m.site("tip2").id
    j1, j2 = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    w = 2 * np.pi * hz
    err, signs = [], set()
    for k in range(n):
        if k % every == 0:
            j = k // every
            P = 0.5 * (d.site_xpos[s1][:2] + d.site_xpos[s2][:2])  # the two tips of the loop
            mujoco.mj_jacSite(m, d, j1, None, s1)
            mujoco.mj_jacSite(m, d, j2, None, s2)
            dP = 0.5 * ((j1 + j2) @ d.qvel)[:2]
            M, _, E, _, _ = task_state(case.model, (1, -1), P, dP)
            tau = ff[j]
            if feedback:
                tau = tau + sr_inverse(E) @ (M @ (w * w * (Pd[j] - P) + 2 * w * (dPd[j] - dP)))
            d.ctrl[:] = tau
            err.append(float(np.linalg.norm(P - Pd[j])))
            signs.add(int(assembly_mode(case.robot, d.qpos[[0, 2]], P)))
        mujoco.mj_step(m, d)
    P = 0.5 * (d.site_xpos[s1][:2] + d.site_xpos[s2][:2])
    end = int(assembly_mode(case.robot, d.qpos[[0, 2]], P))
    return max(err), float(np.linalg.norm(P - np.asarray(case.end))), signs, end


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(CASES))
def test_mujoco_follows_the_crossing_into_the_other_assembly_mode(name):
    """Within 1 mm: 4.4e-6 and 6.6e-6 m measured on the DexTAR and the unequal robot with
    MuJoCo's model of ours; with 20 g of payload MuJoCo has and the controller does not,
    1.5e-4 m (open loop the same torques miss by 3.1 and 3.4 mm: the check can fail)."""
    case, law = CASES[name], planned(name)
    worst, final, signs, end = drive(case, law, case.model)
    assert worst < 1e-3 and final < 1e-3
    assert signs == {1, -1} and end == -1  # through the curve, ending "down"
    heavy = Model(case.robot, case.inertia.with_(payload=case.inertia.payload + 0.02), "up",
                  tol=0.0)
    worst, final, _, end = drive(case, law, heavy)
    assert worst < 1e-3 and end == -1
    worst_open, _, _, _ = drive(case, law, heavy, feedback=False)
    assert worst_open > 1e-3
