"""The synthetic calibration scenario of the tests: the DexTAR, a "real" robot off by the
issue's bounds, a laser-tracker-like instrument anywhere, 17-bit encoders."""

import math

import numpy as np
import pytest

from dextar import DEXTAR_MM, FiveBar
from dextar.calibration import KinematicModel, select_poses
from dextar.calibration.poses import candidates

#: one count of a 17-bit encoder (rad); recorded readings are off by up to one count
COUNT = 2 * np.pi / 2**17
NOMINAL = KinematicModel(DEXTAR_MM.scaled(1e-3))
MODES = ("++", "+-", "-+", "--")


def true_robot(rng: np.random.Generator) -> KinematicModel:
    """Lengths off by 0.5 mm and offsets by 0.5 deg, each sign random (the issue's bounds,
    at the bound: "before" is then always far above the noise); the instrument frame
    shifted by up to 0.5 m and turned by any angle."""
    s = rng.choice([-1.0, 1.0], 7)
    r = NOMINAL.robot
    lengths = np.array([r.l1, r.l2, r.L1, r.L2, r.d]) + 0.5e-3 * s[:5]
    return KinematicModel(FiveBar(*lengths), math.radians(0.5) * s[5],
                          math.radians(0.5) * s[6], float(rng.uniform(-0.5, 0.5)),
                          float(rng.uniform(-0.5, 0.5)), float(rng.uniform(-np.pi, np.pi)))


@pytest.fixture(scope="session")
def four_modes():
    """60 D-optimal poses in all four working modes."""
    return select_poses(NOMINAL, 60)


@pytest.fixture(scope="session")
def one_mode():
    """60 D-optimal poses of the working mode +- only."""
    return select_poses(NOMINAL, 60, modes=("+-",))


@pytest.fixture(scope="session")
def held_out():
    """Readings of 40 poses drawn at random from the candidates of all four modes (not
    optimised: the workspace as a user meets it)."""
    _, cand = candidates(NOMINAL, MODES, 1, margin=0.2, closure_slack=4e-3, resolution=61,
                         rng=np.random.default_rng(0))
    pick = np.random.default_rng(9).choice(len(cand.q), 40, replace=False)
    return cand.q[pick] - NOMINAL.offsets
