"""Our time-optimal law against toppra (a peer, in the test extra) on a line move: toppra gets
the exact joint path and our inverse dynamics through its own JointTorqueConstraint."""

import numpy as np
import pytest

from dextar.config import scenario_from_dict
from dextar.dynamics import inverse_dynamics
from dextar.laws import UniformLaw
from dextar.trajectory import sample_trajectory

ta = pytest.importorskip("toppra")

DOC = {"path": {"type": "line", "start": [-50.0, 100.0], "end": [40.0, 135.0]},
       "inertia": {"effector_mass": 0.1, "payload": 0.05, "proximal_mass": 0.03,
                   "distal_mass": 0.02, "rotor_inertia": 2.0},
       "gravity": {"vector": [0.0, -9810.0]},
       "law": {"type": "time-optimal", "torque_limit": [0.4, 0.5], "grid": 400},
       "output": {"units": "si"}}


def test_line_move_duration_agrees_with_toppra():
    from toppra.constraint import DiscretizationType, JointTorqueConstraint

    sc = scenario_from_dict(DOC)
    law = sc.law()
    assert law.success
    model = sc.model()
    S = sc.path.length

    def joint(s, order):
        s = np.atleast_1d(np.asarray(s, float))
        tr = sample_trajectory(sc.robot, sc.path, UniformLaw(S, S), mode=sc.mode,
                               times=np.clip(s, 0, S))
        return (tr.q, tr.dq, tr.ddq)[order]

    class JointPath(ta.interpolator.AbstractGeometricPath):
        dof = 2
        path_interval = np.array([0.0, S])

        def __call__(self, s, order=0):
            out = joint(s, order)
            return out[0] if np.ndim(s) == 0 else out

    def inv_dyn(q, qd, qdd):
        return inverse_dynamics(model, np.asarray(q)[None], np.asarray(qd)[None],
                                np.asarray(qdd)[None])[0]

    pc = JointTorqueConstraint(inv_dyn, np.array([[-0.4, 0.4], [-0.5, 0.5]]), np.zeros(2),
                               discretization_scheme=DiscretizationType.Interpolation)
    grid = np.linspace(0.0, S, 401)
    inst = ta.algorithm.TOPPRA([pc], JointPath(), gridpoints=grid, solver_wrapper="seidel")
    _, sd, _ = inst.compute_parameterization(0, 0)
    sd = np.asarray(sd)
    duration = float(np.sum(2 * np.diff(grid) / (sd[:-1] + sd[1:])))
    assert law.duration == pytest.approx(duration, rel=1e-3)
