"""Identification from synthetic data of our exact model: the estimates fall within their
standard deviations, the deviations shrink as 1/sqrt(n), the written config reproduces the
base parameters, and bad data are refused by name."""

import numpy as np
import pytest

from dextar.dynamics import Model
from dextar.dynamics.regressor import standard_parameters
from dextar.errors import ParameterError
from dextar.identification.data import MotionData
from dextar.identification.excite import FourierTrajectory
from dextar.identification.fit import identify, physical_set, realise

from .conftest import synthetic


def test_exciting_trajectory_starts_and_ends_at_rest_within_margins(prior, excitation):
    model, mode, motors = prior
    tr = excitation.trajectory
    q, dq, ddq = tr.evaluate(np.array([0.0, tr.period, excitation.duration]))
    assert np.allclose(q, tr.q0, atol=1e-12)
    assert np.abs(dq).max() < 1e-12 and np.abs(ddq).max() < 1e-9
    assert excitation.min_type1_distance >= 0.15 - 1e-9
    assert excitation.min_type2_distance >= 0.15 - 1e-9
    assert (excitation.peak_speed <= np.asarray(motors.max_speed) * (1 + 1e-6)).all()
    assert excitation.condition_number < 20
    # the rates are the derivative of the angles
    t = np.linspace(0, tr.period, 2001)
    q, dq, ddq = tr.evaluate(t)
    h = 1e-6
    qp, dqp, _ = tr.evaluate(t + h)
    qm, dqm, _ = tr.evaluate(t - h)
    assert np.abs((qp - qm) / (2 * h) - dq).max() < 1e-6
    assert np.abs((dqp - dqm) / (2 * h) - ddq).max() < 1e-5


def test_optimised_trajectory_beats_random_ones(prior, excitation, base):
    """The optimiser's condition number is lower than that of random feasible starts."""
    from dextar.dynamics.regressor import regressor

    model = prior[0]
    rng = np.random.default_rng(0)
    conds = []
    t = np.linspace(0, 5, 400, endpoint=False)
    while len(conds) < 5:
        x = 0.3 * rng.normal(size=16)
        tr = FourierTrajectory.from_free(excitation.trajectory.q0, x, 5, 0.2)
        try:
            Yb = base.columns(regressor(model, *tr.evaluate(t))).reshape(-1, base.size)
        except Exception:
            continue
        sv = np.linalg.svd(Yb / np.linalg.norm(Yb, axis=0), compute_uv=False)
        conds.append(sv[0] / sv[-1])
    assert excitation.condition_number < min(conds)


def test_estimates_within_three_sigma_and_sigma_shrinks_as_root_n(prior, excitation, base):
    model, mode, _ = prior
    true = base.of(standard_parameters(model.inertia))
    short = identify(synthetic(model, excitation, 10.0, seed=1), model, mode=mode, base=base)
    long = identify(synthetic(model, excitation, 40.0, seed=2), model, mode=mode, base=base)
    for res in (short, long):
        assert res.success, res.message
        z = (res.beta - true) / res.std
        assert np.abs(z).max() < 3.0, dict(zip(base.names, z.round(2), strict=True))
    ratio = short.std / long.std  # 4 times the data: half the deviation
    assert np.all((ratio > 1.5) & (ratio < 2.7)), ratio


def test_physical_set_reproduces_the_base_parameters(prior, excitation, base):
    model, mode, _ = prior
    res = identify(synthetic(model, excitation, 10.0, seed=3), model, mode=mode, base=base)
    assert res.consistent
    back = base.of(standard_parameters(res.inertia))
    assert np.allclose(back, res.beta, rtol=1e-9, atol=1e-15)
    for rod in (*res.inertia.proximal, *res.inertia.distal):
        assert rod.mass >= 0 and rod.inertia >= 0


def test_an_unphysical_solution_is_constrained(prior, base):
    """Base parameters no physical set can have (a negative friction) are refused by
    physical_set; realise never writes a negative mass or inertia."""
    model = prior[0]
    theta = standard_parameters(model.inertia)
    beta = base.of(theta)
    bad = beta.copy()
    bad[base.names.index("fv_A")] = -0.01
    _, ok = physical_set(bad, base, theta, model.inertia)
    assert not ok
    _, ok = physical_set(beta, base, theta, model.inertia)
    assert ok
    ine = realise(theta, model.inertia)
    assert np.allclose(base.of(standard_parameters(ine)), beta, rtol=1e-12)


def _data(model, excitation, **changes):
    d = synthetic(model, excitation, 10.0, seed=4)
    fields = {"t": d.t, "q": d.q, "tau": d.tau}
    fields.update(changes)
    return MotionData(**fields)


def test_bad_data_are_refused_by_name(prior, excitation, base):
    model, mode, _ = prior
    d = synthetic(model, excitation, 10.0, seed=4)
    tau = d.tau.copy()
    tau[[5, 9]] = np.nan
    with pytest.raises(ParameterError, match=r"tau1_Nm, tau2_Nm is NaN or infinite at row 7, 11"):
        MotionData(d.t, d.q, tau)
    t = d.t.copy()
    t[100] = t[99]
    with pytest.raises(ParameterError, match="t_s does not increase at row 102"):
        MotionData(t, d.q, d.tau)
    t = d.t.copy()
    t[100:] += 0.0005
    with pytest.raises(ParameterError, match=r"not uniform within 1 %.*row 102"):
        MotionData(t, d.q, d.tau)
    few = MotionData(d.t[:400], d.q[:400], d.tau[:400])
    with pytest.raises(ParameterError, match="fewer than 55"):
        identify(few, model, mode=mode, base=base, cutoff_hz=5.0)
    with pytest.raises(ParameterError, match=r"row 2 \(t = 0 s\) is in working mode \+-, not -\+"):
        identify(d, model, mode="-+", base=base)


def test_data_that_do_not_excite_name_the_combination(prior, excitation, base):
    """Motor D held still: its friction and the parameters only it reveals cannot be
    identified, and the error names them."""
    model, mode, _ = prior
    d = synthetic(model, excitation, 10.0, seed=5)
    q = d.q.copy()
    q[:, 0] = q[0, 0] + 0.3 * (q[:, 0] - q[0, 0])
    q[:, 1] = q[0, 1]
    from dextar.dynamics import inverse_dynamics

    dq = np.gradient(q, d.t, axis=0)
    tau = inverse_dynamics(model, q, dq, np.gradient(dq, d.t, axis=0))
    with pytest.raises(ParameterError, match=r"do not excite base parameter (J_D'|fv_D|fc_D) "
                                             r"\(.*\): it cannot be identified"):
        identify(MotionData(d.t, q, tau), model, mode=mode, base=base)


def test_poor_excitation_is_a_warning(prior, excitation, base):
    """One small sine per motor: the inertia and gravity columns nearly align; the fit is
    made but flagged (status 1, a warning)."""
    model, mode, _ = prior
    t = np.arange(20001) / 1000.0
    q0 = excitation.trajectory.q0
    w = 2 * np.pi * 0.5
    q = q0 + 0.05 * np.stack([np.sin(w * t), np.sin(w * t + 1.0)], -1)
    dq = 0.05 * w * np.stack([np.cos(w * t), np.cos(w * t + 1.0)], -1)
    ddq = -w * w * (q - q0)
    from dextar.dynamics import inverse_dynamics

    tau = inverse_dynamics(model, q, dq, ddq) + np.random.default_rng(0).normal(
        scale=1e-4, size=q.shape)
    res = identify(MotionData(t, q, tau), model, mode=mode, base=base)
    assert res.condition_number > 1e3
    assert res.status == 1 and "condition number" in res.warnings[0]


def test_identified_model_is_a_model(prior, excitation, base):
    model, mode, _ = prior
    res = identify(synthetic(model, excitation, 10.0, seed=6), model, mode=mode, base=base)
    m2 = Model(model.robot, res.inertia, model.assembly)
    assert m2.inertia.effector_mass > 0


def test_collinear_columns_name_the_combination(base):
    from dextar.identification.fit import _rank_check

    A = np.random.default_rng(0).normal(size=(200, base.size))
    A[:, base.names.index("fv_A")] = 3.0 * A[:, 0]
    with pytest.raises(ParameterError, match=r"the combination .*J_A'.*fv_A|the combination "
                                             r".*fv_A.*J_A'"):
        _rank_check(A, base, "data.csv")


def test_values_beyond_any_measurement_are_refused(prior, excitation):
    model, mode, _ = prior
    d = synthetic(model, excitation, 10.0, seed=7)
    tau = d.tau.copy()
    tau[50, 0] = 1e308
    with pytest.raises(ParameterError, match=r"tau1_Nm, tau2_Nm beyond 1e\+09 at row 52"):
        MotionData(d.t, d.q, tau)
