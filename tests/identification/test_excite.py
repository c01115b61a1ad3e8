"""design_excitation tested for properties it meets with margin, never for which optimum it
finds (it is chaotic to one rounding unit). One design covering the pick-and-place program's
joint region (4 harmonics, 2 starts, to keep the test short); measured over seeds 0-9 of
these settings: condition numbers 5.2-7.4, each motor using 73-80 % of its limits, 85-98 %
of the region's poses covered."""

import numpy as np
import pytest

from dextar.config import load_scenario
from dextar.dynamics import inverse_dynamics
from dextar.dynamics.regressor import regressor
from dextar.identification.coverage import JointRegion
from dextar.identification.excite import (
    MARGIN,
    SAFETY,
    FourierTrajectory,
    _feasibility,
    design_excitation,
)
from dextar.program import plan_program

from ..program.test_program import EXAMPLES


@pytest.fixture(scope="session")
def region(prior):
    """The joint region of the pick-and-place program (time-optimal: its peak speeds are 98 %
    of the motors')."""
    model, mode, motors = prior
    sc = load_scenario(EXAMPLES / "pick_place.toml")
    res = plan_program(model.robot, model.inertia, sc.moves, start=sc.program_start,
                       working_mode=mode, motors=motors, servo_rate_hz=200.0)
    return JointRegion.from_samples(res.q, res.dq)


@pytest.fixture(scope="session")
def designed(prior, base, region):
    model, mode, motors = prior
    return design_excitation(model, mode, harmonics=4, starts=2, duration=10.0, motors=motors,
                             seed=0, base=base, region=region)


def _cond(model, base, tr, t):
    Yb = base.columns(regressor(model, *tr.evaluate(t))).reshape(-1, base.size)
    sv = np.linalg.svd(Yb / np.linalg.norm(Yb, axis=0), compute_uv=False)
    return sv[0] / sv[-1]


@pytest.mark.slow
def test_design_rests_at_the_ends_and_keeps_its_margins_and_motors(prior, designed):
    """Checked here on a grid of its own (7919 samples a period), not the design's."""
    model, mode, motors = prior
    tr = designed.trajectory
    q, dq, ddq = tr.evaluate(np.array([0.0, tr.period, designed.duration]))
    assert np.allclose(q, tr.q0, atol=1e-12)
    assert np.abs(dq).max() < 1e-12 and np.abs(ddq).max() < 1e-9
    t = np.linspace(0.0, tr.period, 7919)
    q, dq, ddq = tr.evaluate(t)
    f = _feasibility(model, q)
    assert f is not None
    assert f[0].min() >= MARGIN * (1 - 1e-3) and f[1].min() >= MARGIN * (1 - 1e-3)
    assert np.all(np.sign(f[2]) == np.sign(f[2][0]))  # one assembly mode throughout
    tau = inverse_dynamics(model, q, dq, ddq)
    assert (np.abs(tau) <= SAFETY * motors.available_torque(dq) * (1 + 1e-3)).all()
    assert (np.abs(dq) <= SAFETY * np.asarray(motors.max_speed) * (1 + 1e-3)).all()
    assert designed.duration == pytest.approx(10.0)


@pytest.mark.slow
def test_design_uses_the_headroom_and_covers_the_region(designed, region):
    """Measured 73-80 % of the limits (bound 60 %; the former design: 4-7 % of the torque,
    30-60 % of the speed) and 85-98 % of the region (bound 70 %)."""
    assert designed.headroom.min() > 0.6, designed.headroom
    assert designed.headroom.max() <= SAFETY * (1 + 1e-3)
    assert designed.region_coverage > 0.7, designed.region_coverage
    # its speeds reach the region's as far as the safe speed allows (0.8 of the motors')
    assert (designed.region_speed_ratio > 0.7).all(), designed.region_speed_ratio
    # the rest pose is one of the region's
    assert region.distance(designed.trajectory.q0[None])[0] < 1e-12
    # every coverage floor met (the task's range, speed and acceleration)
    assert designed.coverage is not None and designed.coverage.met, designed.coverage.missed


@pytest.mark.slow
def test_design_is_well_conditioned_and_beats_random_starts(prior, base, designed):
    """Condition number 5.2-7.4 measured (bound 20). Random feasible motions drawn as the
    optimiser draws its starts (coefficients N(0, 0.3^2)): over 200 of them, 5th percentile
    7.1, median 13.9; the median of 9 falls below 7.4 with odds about 1e-5 (5 of 9 below the
    6 % quantile). Larger random motions (N(0, 1)) reach a median of 6.9: the design's gain
    over them is the headroom and the region at the same conditioning, not the
    conditioning."""
    model = prior[0]
    tr = designed.trajectory
    t = np.linspace(0, tr.period, 400, endpoint=False)
    own = _cond(model, base, tr, t)
    assert own < 20 and designed.condition_number < 20
    rng = np.random.default_rng(0)
    conds = []
    while len(conds) < 9:
        x = 0.3 * rng.normal(size=12)
        cand = FourierTrajectory.from_free(tr.q0, x, 4, tr.base_hz)
        f = _feasibility(model, cand.evaluate(t)[0])
        if f is None or min(f[0].min(), f[1].min()) < MARGIN:
            continue
        conds.append(_cond(model, base, cand, t))
    assert own < np.median(conds), (own, conds)


def test_bad_design_options_are_refused(prior, base):
    from dextar.errors import ParameterError

    model, mode, motors = prior
    with pytest.raises(ParameterError, match="safety factor 1.5 must be in"):
        design_excitation(model, mode, motors=motors, safety=1.5, base=base)
    with pytest.raises(ParameterError, match="joint region needs finite poses"):
        JointRegion(np.zeros((0, 2)), np.ones(2))


def test_coverage_floors_tell_a_small_motion(prior):
    """The stored excitations reach 32-90 % of the free range, 36-99 % of the speed and
    13-33 % of the acceleration references (floors 20 / 20 / 10 %); at a quarter of their
    size, 8-22 %, 9-25 %, 3-8 %: the range or acceleration floor is missed and named, the
    peak speed also against the motors' rated speed. Issue 28's motion (19 deg on motor D,
    0.9 rad/s) was 16 % / 13 % of its robot's range and speed."""
    from dextar.identification.excite import check_coverage, coverage_reference

    from .excitations import EXCITATIONS

    model, _, motors = prior
    tr = EXCITATIONS[0]
    ref = coverage_reference(model, tr.q0, 5, 0.2, motors, None)
    assert np.allclose(ref.rated_speed, motors.max_speed)
    speeds: list[str] = []
    for t in EXCITATIONS.values():
        cov = check_coverage(t, ref, 5.0)
        assert cov.met
        assert np.allclose(cov.rated_fraction, cov.speed / np.asarray(motors.max_speed))
        small = FourierTrajectory(t.q0, 0.25 * t.a, 0.25 * t.b, t.base_hz)
        cov = check_coverage(small, ref, 5.0)
        assert not cov.met and any("of the free range from the rest pose, the other motor "
                                   "at rest (floor 20 %)" in m or "rad/s^2 of the top "
                                   "harmonic" in m for m in cov.missed), cov.missed
        assert not any("allowed" in m for m in cov.missed)
        speeds.extend(m for m in cov.missed if "peak speed" in m)
    assert speeds and all(f"% of its rated {motors.max_speed[0]:.3g} rad/s" in m
                          for m in speeds), speeds
    assert check_coverage(tr, ref, 50.0).missed == ("condition number 50 above 20",)


@pytest.mark.slow
def test_a_design_short_of_its_floors_is_designed_again_and_says_so(prior, base, monkeypatch):
    """A floor no motion meets (1000 % of the range): a second design from new
    deterministic starts, then status 2 naming the floor (advisory: dextar excite exits 0
    with a warning, tests/cli); the same result twice."""
    from dextar.identification import excite

    model, mode, motors = prior
    monkeypatch.setattr(excite, "RANGE_FLOOR", 10.0)
    monkeypatch.setattr(excite, "ATTEMPTS", 2)
    # 2 harmonics, the smallest: no motion of any size meets a 1000 % floor, and the attempts,
    # the status and the determinism checked do not depend on the size (3 took twice the CPU)
    kw = dict(harmonics=2, starts=1, duration=5.0, motors=motors, seed=0, base=base)
    a = design_excitation(model, mode, **kw)
    assert a.attempts == 2 and a.status == 2
    assert "stays below its advisory coverage floors after 2 designs" in a.message
    assert "range" in a.message and "floor 1000 %" in a.message
    b = design_excitation(model, mode, **kw)
    assert np.array_equal(a.trajectory.a, b.trajectory.a)
