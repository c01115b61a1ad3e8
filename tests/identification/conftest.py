import numpy as np
import pytest

from dextar.config import load_scenario
from dextar.dynamics import inverse_dynamics
from dextar.identification.base import base_parameters
from dextar.identification.data import MotionData

from ..program.test_program import EXAMPLES
from .excitations import EXCITATIONS

#: 17-bit encoder: one count in rad
COUNT = 2 * np.pi / 2**17


@pytest.fixture(scope="session")
def prior():
    """The pick-and-place robot (SI), its working mode and motors."""
    sc = load_scenario(EXAMPLES / "pick_place.toml")
    return sc.si_model, sc.mode, sc.si_motors


@pytest.fixture(scope="session")
def excitation():
    """A stored exciting trajectory (tests/identification/excitations.py)."""
    return EXCITATIONS[0]


@pytest.fixture(scope="session")
def base(prior):
    return base_parameters(prior[0])


def synthetic(model, trajectory, seconds, *, seed, noise=0.005, rate=1000.0):
    """Our exact model along the exciting trajectory: Gaussian noise (N m) on the torques,
    angles quantised to a 17-bit encoder."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(round(seconds * rate)) + 1) / rate
    q, dq, ddq = trajectory.evaluate(t)
    tau = inverse_dynamics(model, q, dq, ddq)
    return MotionData(t, np.round(q / COUNT) * COUNT, tau + rng.normal(scale=noise,
                                                                      size=tau.shape))


@pytest.fixture(scope="session")
def issue28():
    """Issue 28's robot (SI) and its working mode (tests/identification/excitations.py)."""
    from dextar.config.scenario import scenario_from_dict

    from .excitations import ISSUE28_CONFIG

    sc = scenario_from_dict(ISSUE28_CONFIG)
    return sc.si_model, sc.mode
