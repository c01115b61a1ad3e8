"""Computed-torque control against hand cases and the closed form of its error dynamics."""

import numpy as np
import pytest

import dextar as dx
from dextar.dynamics import Model, paper_inertia
from dextar.laws import MinimumJerkLaw
from dextar.paths import Line
from dextar.simulation import simulate_computed_torque
from dextar.trajectory import sample_trajectory

ROBOT = dx.DEXTAR_MM.scaled(1 / 87)
LINE = Line((-0.5, 1.1), (0.5, 1.3))
MODEL = Model(ROBOT, paper_inertia(ROBOT).with_(gravity=(0.0, -2.0), rotor=(0.01, 0.01)))


@pytest.fixture(scope="session")
def traj():
    return sample_trajectory(ROBOT, LINE, MinimumJerkLaw(LINE.length, 1.0), samples=401)


def test_perfect_model_tracks_exactly(traj):
    res = simulate_computed_torque(traj, MODEL, MODEL, natural_frequency=20.0)
    assert res.success and res.status == 0
    assert np.abs(res.joint_error).max() < 1e-6
    assert res.task_error.max() < 1e-6 and not res.saturated.any()


def test_error_follows_the_closed_form_of_critical_damping(traj):
    """With a perfect model the loop is e'' + 2 zeta w e' + w^2 e = 0 for each joint: from
    e(0) = e0, e'(0) = 0 and zeta = 1, e(t) = e0 (1 + w t) exp(-w t) (e = q_d - q)."""
    w, e0 = 8.0, np.radians([1.0, -0.5])
    res = simulate_computed_torque(traj, MODEL, MODEL, natural_frequency=w, damping=1.0,
                                   initial_error=tuple(-e0), rtol=1e-10)
    closed = e0[None, :] * ((1 + w * res.t) * np.exp(-w * res.t))[:, None]
    assert np.abs(res.joint_error - closed).max() < 1e-6 * np.abs(e0).max() * 10


def test_underdamped_closed_form(traj):
    w, zeta, e0 = 10.0, 0.3, np.radians([0.5, 0.5])
    res = simulate_computed_torque(traj, MODEL, MODEL, natural_frequency=w, damping=zeta,
                                   initial_error=tuple(-e0), rtol=1e-10)
    wd = w * np.sqrt(1 - zeta**2)
    t = res.t
    closed = e0[None, :] * (np.exp(-zeta * w * t) * (np.cos(wd * t) + zeta * w / wd
                                                     * np.sin(wd * t)))[:, None]
    assert np.abs(res.joint_error - closed).max() < 1e-5


@pytest.mark.slow
def test_a_wrong_model_leaves_an_error_and_saturation_clips(traj):
    plant = Model(ROBOT, MODEL.inertia.scaled_masses(1.3))
    res = simulate_computed_torque(traj, MODEL, plant, natural_frequency=20.0)
    assert 1e-5 < np.abs(res.joint_error).max() < 0.05
    free = simulate_computed_torque(traj, MODEL, MODEL, natural_frequency=20.0)
    limit = 0.95 * float(np.abs(free.tau).max())  # just below the peak the motion needs
    tight = simulate_computed_torque(traj, MODEL, MODEL, natural_frequency=20.0,
                                     torque_limit=limit)
    assert 0 < tight.saturated.mean() < 0.5
    assert np.abs(tight.tau).max() <= limit * (1 + 1e-12) and tight.torque_limit == limit


@pytest.mark.parametrize("kw, word", [({"natural_frequency": 0.0}, "natural frequency"),
                                      ({"natural_frequency": 5.0, "damping": -1.0}, "damping"),
                                      ({"natural_frequency": 5.0, "torque_limit": 0.0},
                                       "torque limit")])
def test_bad_settings_named(traj, kw, word):
    with pytest.raises(dx.ParameterError, match=word):
        simulate_computed_torque(traj, MODEL, MODEL, **kw)


def test_a_step_that_does_not_advance_is_a_convergence_error(monkeypatch):
    """An integrator step that leaves the time where it was (it underflowed: the fuzz's
    robot of zero masses and a rotor inertia of 5e-324 against its friction) ends the
    simulation with the integrator's words, not with scipy's ValueError about the dense
    solution's times."""
    from types import SimpleNamespace

    from scipy.integrate import OdeSolution

    from dextar.errors import ConvergenceError
    from dextar.simulation import control

    class Stuck:  # advances once, then stays
        def __init__(self, fun, t0, y0, t_bound, **kw):
            self.t, self.status, self.moves = t0, "running", 1

        def step(self):
            if self.moves:
                self.t += 1e-3
                self.moves -= 1

        def dense_output(self):
            return lambda t: np.zeros(4)

    monkeypatch.setattr(control, "integrate",
                        SimpleNamespace(**{control.SOLVER: Stuck, "OdeSolution": OdeSolution}))
    with pytest.raises(ConvergenceError, match="step became too small"):
        control._integrate(lambda t, y: y, np.array([0.0, 1.0]), np.zeros(4), rtol=1e-6,
                           max_step=0.01)
