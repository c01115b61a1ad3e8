import numpy as np
import pytest

import dextar as dx
from dextar.dynamics import Model, exact, paper_inertia
from dextar.laws import solve_optimal_law
from dextar.paths import Arc
from dextar.trajectory import sample_trajectory

ROBOT = dx.DEXTAR_MM.scaled(1 / 87)
SEMI = Arc(120 / 87, 0.0, np.pi)


@pytest.fixture(scope="session")
def law():
    return solve_optimal_law(SEMI, eta=0.1)


@pytest.fixture(scope="session")
def paper_traj(law):
    return sample_trajectory(ROBOT, SEMI, law, samples=1001)


@pytest.fixture(scope="session")
def paper_model():
    return Model(ROBOT, paper_inertia(ROBOT))


def random_joint_motion(rng, t):
    """A smooth joint trajectory near the paper's configuration, with exact derivatives."""
    q0 = np.radians([60.5, 119.5])
    amp = rng.uniform(0.05, 0.3, (3, 2))
    freq = rng.uniform(0.5, 3.0, (3, 2))
    ph = rng.uniform(0, 2 * np.pi, (3, 2))
    arg = 2 * np.pi * freq[None] * t[:, None, None] + ph[None]
    q = q0 + np.sum(amp * np.sin(arg), axis=1)
    dq = np.sum(amp * 2 * np.pi * freq * np.cos(arg), axis=1)
    ddq = -np.sum(amp * (2 * np.pi * freq) ** 2 * np.sin(arg), axis=1)
    return q, dq, ddq


@pytest.fixture(params=["compiled", "numpy"])
def kernel(request, monkeypatch):
    """A test taking it runs with the compiled kernel and with the numpy one."""
    if request.param == "compiled":
        if exact._compiled is None:
            pytest.skip("the compiled kernel was not built (no C compiler at install)")
        monkeypatch.setattr(exact, "USE_COMPILED", True)
    else:
        monkeypatch.setattr(exact, "USE_COMPILED", False)
    return request.param
