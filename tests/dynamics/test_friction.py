"""The one friction model: viscous plus regularised Coulomb, zero at rest, used everywhere."""

import numpy as np
import pytest

from dextar.dynamics import Inertia, Model, inverse_dynamics, paper_inertia
from dextar.dynamics.forward import forward_dynamics
from dextar.dynamics.friction import friction_torque

from .conftest import ROBOT


def test_zero_at_rest_and_rounding_noise_gives_rounding_noise():
    assert friction_torque(0.0, 0.3, 0.5, 1e-3) == 0.0
    noise = np.array([-1e-14, 0.0, 1e-14])
    f = friction_torque(noise, 0.3, 0.5, 1e-3)
    assert np.abs(f).max() < 1e-10  # with sign(dq) this would be +-0.5


def test_shape_of_the_model():
    vs, c, b = 1e-3, 0.5, 0.2
    w = np.linspace(-1.0, 1.0, 2001)
    f = friction_torque(w, b, c, vs)
    np.testing.assert_allclose(f, -friction_torque(-w, b, c, vs), atol=1e-15)  # odd
    assert np.all(np.diff(f) > 0)  # increasing, continuous
    fast = np.abs(w) > 10 * vs
    np.testing.assert_allclose(f[fast], b * w[fast] + c * np.sign(w[fast]), rtol=1e-8)
    assert np.abs(f - b * w).max() <= c  # the Coulomb part is bounded by its value
    assert friction_torque(2.0, b, c, vs) == pytest.approx(b * 2.0 + c)  # floats too


def test_inverse_dynamics_at_rest_is_gravity_only():
    ine = paper_inertia(ROBOT).with_(coulomb=(0.4, 0.6), viscous=(0.1, 0.1), gravity=(0.0, -2.0))
    model = Model(ROBOT, ine)
    q = np.radians([[60.5, 119.5]] * 3)
    dq = np.array([[0.0, 0.0], [1e-14, -1e-14], [-1e-14, 1e-14]])
    tau = inverse_dynamics(model, q, dq, np.zeros_like(q))
    np.testing.assert_allclose(tau, tau[[0, 0, 0]], atol=1e-9)
    np.testing.assert_allclose(ine.friction_torques(dq), 0.0, atol=1e-9)


def test_forward_dynamics_through_a_reversal_is_smooth():
    """A joint pushed back against its motion stops and reverses; the integrator sails
    through the reversal (no chattering) and friction only ever brakes."""
    ine = paper_inertia(ROBOT).with_(coulomb=(0.5, 0.5), coulomb_speed=1e-2)
    model = Model(ROBOT, ine)
    q0 = np.radians([60.5, 119.5])

    def torque(t, q, dq):
        return np.array([-2.0, 0.0])

    t = np.linspace(0.0, 0.3, 301)
    res = forward_dynamics(model, torque, q0, np.array([1.0, 0.0]), t, rtol=1e-8, atol=1e-10)
    assert res.success and res.status == 0
    assert res.dq[0, 0] > 0 and res.dq[-1, 0] < 0  # it reversed
    assert res.nfev < 20000


def test_inertia_refuses_bad_regularisation_speed():
    from dextar.errors import ParameterError

    with pytest.raises(ParameterError, match="Coulomb regularisation speed"):
        Inertia.uniform(ROBOT, proximal_mass=0.1, distal_mass=0.1, coulomb_speed=0.0)
