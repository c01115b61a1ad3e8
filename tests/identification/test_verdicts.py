"""Identification's verdict from what the model is for (issue 28): the predicted-torque
uncertainty along the task, the residual against what noise explains, physics in the full
sense, and a time column in milliseconds. Synthetic data of our model along the stored
excitations (the pick-and-place robot, 17-bit angles); the MuJoCo cases behind the thresholds
are benchmarks/bench_identify_verdicts.py."""

import dataclasses
import math
import re

import numpy as np
import pytest

from dextar.dynamics import Model
from dextar.dynamics.regressor import regressor, standard_parameters
from dextar.errors import ParameterError
from dextar.identification.excite import FourierTrajectory
from dextar.identification.fit import (
    PHYSICAL_SIGMAS,
    POOR_FIT,
    RESIDUAL_FACTOR,
    UNCERTAINTY_LIMIT,
    identify,
)
from dextar.identification.verdict import check_time_base, recorded_motion
from dextar.program import plan_program

from .conftest import synthetic
from .excitations import EXCITATIONS, ISSUE28


@pytest.fixture(scope="module")
def task(prior):
    """The pick-and-place program (time-optimal, at the motors' limits), planned (SI)."""
    from dextar.config import load_scenario

    from ..program.test_program import EXAMPLES

    model, mode, motors = prior
    sc = load_scenario(EXAMPLES / "pick_place.toml")
    pp = plan_program(model.robot, model.inertia, sc.moves, start=sc.program_start,
                      working_mode=mode, motors=motors, servo_rate_hz=200.0)
    return pp.q, pp.dq, pp.ddq


def _shrunk(tr, f):
    return FourierTrajectory(tr.q0, f * tr.a, f * tr.b, tr.base_hz)


@pytest.mark.slow
def test_a_motion_too_small_for_the_task_is_poorly_determined(prior, base, task):
    """The stored excitation at a quarter of its size, 20 mN m of noise: the program's
    torques predicted within 44-99 % (1 sigma, measured on the three stored excitations),
    far above the limit 2 %: poorly determined, with the reason; along the recorded motion
    0.55-0.84 % (identified for motions like it: the task extrapolates). The same excitation at full size with
    1 mN m of noise: 0.44 / 0.49 % along the task, identified (a parameter covariance
    propagated by Monte Carlo over 12 noise draws matched the reported one to 4-7 %)."""
    model, mode, _ = prior
    d = synthetic(model, _shrunk(EXCITATIONS[0], 0.25), 10.0, seed=3, noise=0.02)
    res = identify(d, model, mode=mode, base=base, reference=task,
                   reference_name="the pick-and-place program")
    assert res.status == 1 and res.status_text == "poorly determined", res.message
    assert res.uncertainty.min() > 10 * UNCERTAINTY_LIMIT, res.uncertainty
    assert "along the pick-and-place program" in res.message and res.reasons
    own = identify(d, model, mode=mode, base=base)
    assert own.success and own.reference.startswith("the recorded motion (")
    assert own.uncertainty.max() < res.uncertainty.min() / 10
    good = identify(synthetic(model, EXCITATIONS[0], 10.0, seed=3, noise=0.001), model,
                    mode=mode, base=base, reference=task)
    assert good.success, good.message
    assert good.uncertainty.max() < UNCERTAINTY_LIMIT / 2, good.uncertainty


def _error_along_recorded(res, model):
    """The identified model's RMS error along the recorded motion against the true model
    (the prior itself: synthetic data), per motor, over the true RMS torque."""
    Y = regressor(model, *recorded_motion(res.conditioned))
    truth = Y @ standard_parameters(model.inertia)
    return (np.sqrt(((Y @ res.theta - truth) ** 2).mean(axis=0))
            / np.sqrt((truth ** 2).mean(axis=0)))


@pytest.mark.slow
def test_realistic_noise_is_identified_along_the_recorded_motion(issue28):
    """Issue 28's robot (1.5 N m motors), 10 s of a stored excitation, 50 mN m of torque
    noise (3 % of the motors' peak: a current sensor's): without --task the predicted torques
    along the recorded motion are uncertain by 0.26-0.33 % (noise seeds 1-4), the model's
    error along it 0.23-0.45 %: identified (limit 2 %, 6x above). The former default
    reference, the excitation's envelope (every visited pose with speeds and accelerations
    drawn up to their peaks), read 3.4-4.3 % on these data at 15 s: "poorly determined",
    exit 1 (on MuJoCo's data 1.0-4.6 %, the review's 3.8 / 3.2 %, where the model predicts an
    unseen line and arc within 0.2-0.7 %). Two seconds of the same motion with 200 mN m of
    noise: 4.7-7.2 % (seeds 1-3), errors 4.0-5.8 %: poorly determined. Over 80 cases of
    MuJoCo's data (benchmarks/bench_identify_verdicts.py) the error along the recorded
    motion was 0.46-1.51 times this 1-sigma figure."""
    model, mode = issue28
    good = identify(synthetic(model, ISSUE28, 10.0, seed=2, noise=0.05), model, mode=mode)
    assert good.success, good.message
    # the verdict's scope named: the poses and speeds of the rows the fit used
    assert re.fullmatch(r"the recorded motion \(motor A 3\d\.\d+ to 99\.\d+ deg, D 11\d\.\d+ "
                        r"to 17\d\.\d+ deg, up to 1\.\d+ / 1\.\d+ rad/s\)", good.reference)
    assert good.uncertainty.max() < UNCERTAINTY_LIMIT / 4, good.uncertainty
    assert _error_along_recorded(good, model).max() < UNCERTAINTY_LIMIT / 4
    bad = identify(synthetic(model, ISSUE28, 2.0, seed=2, noise=0.2), model, mode=mode)
    assert bad.status == 1 and bad.status_text == "poorly determined", bad.message
    assert bad.uncertainty.min() > 1.5 * UNCERTAINTY_LIMIT, bad.uncertainty
    assert "along the recorded motion (motor A" in bad.message
    # the figure tells a model that is wrong along its own motion
    assert _error_along_recorded(bad, model).min() > UNCERTAINTY_LIMIT


@pytest.mark.slow
def test_a_residual_noise_does_not_explain_is_a_poor_fit(prior, base):
    """Gravity tilted by 9.4 deg in the data, vertical in the config (5 mN m of noise): fit
    quality 5.5 / 4.3, 10 / 21, 11 / 6.7 % on the three stored excitations, where the noise
    and filters explain 1.5-3 %: the first is below the former 20 % poor-fit limit and was
    "identified"; now a poor fit (ratio 3.8 against the limit 2). The right config: 1.0 /
    2.4 %, within what is explained, identified; 20 mN m of noise: 4-9 %, explained too."""
    model, mode, _ = prior
    a = math.radians(9.4)
    tilted = Model(model.robot, model.inertia.with_(gravity=(9.81 * math.sin(a),
                                                             -9.81 * math.cos(a))),
                   model.assembly)
    d = synthetic(tilted, EXCITATIONS[0], 10.0, seed=3, noise=0.005)
    res = identify(d, model, mode=mode, base=base)
    assert (res.fit_quality < POOR_FIT).all()  # the former verdict's limit does not see it
    assert (res.fit_quality > 1.5 * RESIDUAL_FACTOR * res.explained_quality).any()
    assert res.status == 3 and "the torques' noise and the filters explain" in res.message
    right = identify(d, tilted, mode=mode)
    assert right.success, right.message
    assert (right.fit_quality < right.explained_quality * RESIDUAL_FACTOR / 1.5).all()
    noisy = identify(synthetic(model, EXCITATIONS[0], 10.0, seed=8, noise=0.02), model,
                     mode=mode, base=base)
    assert noisy.fit_quality.min() > 0.02  # a large residual, explained by the noise
    assert (noisy.fit_quality < RESIDUAL_FACTOR * noisy.explained_quality / 1.5).all()
    assert not any(r.startswith("poor fit") for r in noisy.reasons)


@pytest.mark.slow
def test_a_fit_physics_cannot_explain_is_not_physically_consistent(prior, base):
    """The time stretched 30x (20 ms steps, 30x slower: above the time-base check's 20 Hz):
    the least-squares estimate lies 26-63 standard deviations from any physical set
    (measured on the three stored excitations; the limit 5), where good fits are
    physical (0) or within 2.9 sigma (benchmarks/bench_identify_verdicts.py). Every rod
    the model writes has its centre of mass within its length and J >= m c^2."""
    model, mode, _ = prior
    d = synthetic(model, EXCITATIONS[0], 10.0, seed=3, noise=0.005)
    slow = identify(dataclasses.replace(d, t=30 * d.t), model, mode=mode, base=base)
    assert slow.unphysical_distance > 2 * PHYSICAL_SIGMAS, slow.unphysical_distance
    assert any(r.startswith("not physically consistent") for r in slow.reasons)
    assert slow.status >= 2
    good = identify(d, model, mode=mode, base=base)
    assert good.unphysical_distance < PHYSICAL_SIGMAS / 2 and good.success
    r = model.robot
    for res in (slow, good):
        ine = res.inertia
        for rod, length in zip((*ine.proximal, *ine.distal), (r.l1, r.l2, r.L1, r.L2),
                               strict=True):
            assert rod.mass >= 0 and rod.inertia >= 0
            assert abs(rod.com) <= length * (1 + 1e-9), (rod, length)


def test_time_in_milliseconds_is_named(prior, base):
    """The same data with t_s in milliseconds: a 1 Hz sample rate with joints below 0.003
    rad/s; refused by name with the rates read as milliseconds. In seconds it passes."""
    model, mode, _ = prior
    d = synthetic(model, EXCITATIONS[0], 10.0, seed=3)
    check_time_base(d)
    ms = dataclasses.replace(d, t=1000 * d.t)
    with pytest.raises(ParameterError, match=r"sample rate of 1 Hz.*Is the time in "
                                             r"milliseconds\? Read as milliseconds, the "
                                             r"data run at 1000 Hz"):
        identify(ms, model, mode=mode, base=base)


@pytest.mark.parametrize("factor, said", [
    (1e6, r"sample rate of 0.001 Hz.*Is the time in microseconds\? Read as microseconds, the "
          r"data run at 1000 Hz and 2.\d+ rad/s; if so, divide t_s by 1000000$"),
    (1e4, r"Is the time in milliseconds\? Read as milliseconds, the data run at 100 Hz"),
    # 10 ms steps at 1 kHz: read as milliseconds, 10 kHz (a drive's rate: named, with it)
    (1e2, r"Is the time in milliseconds\? Read as milliseconds, the data run at 10000 Hz"),
    # no power of 1000 brings 1/30 Hz to 100 Hz - 10 kHz: every reading named
    (3e4, r"No power of 1000 brings it to a drive's rate \(as milliseconds, 33.3333 Hz .*; "
          r"as microseconds, 33333.3 Hz .*\): give t_s in seconds$"),
])
def test_the_time_unit_named_brings_the_rate_to_a_drives(prior, factor, said):
    """The unit named is the power of 1000 that brings the rate into 100 Hz - 10 kHz (the
    former message said milliseconds whatever the unit: t * 1e6 "divide t_s by 1000")."""
    model, mode, _ = prior
    d = synthetic(model, EXCITATIONS[0], 10.0, seed=3)
    with pytest.raises(ParameterError, match=said):
        check_time_base(dataclasses.replace(d, t=factor * d.t))
