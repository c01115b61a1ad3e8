"""The time-optimal solver's passes against linear programmes solved by scipy, on random
stages, among them stages that need a least speed (the branch where rest is not reachable
next is otherwise rare: no example or test path has it); the compiled passes against the
Python ones."""

import numpy as np
import pytest
from scipy.optimize import linprog

import dextar as dx
from dextar.errors import InfeasibleError, ParameterError
from dextar.laws import time_optimal
from dextar.laws.time_optimal import _controllable, _fastest, _passes, _stages

from ..compiled import skip_without_a_compiler

ROBOT_M = dx.DEXTAR_MM.scaled(1e-3)


def _random_stages(rng, n, floors, top=0.3):
    """Rows ``Gu u + Gx x <= h`` (n, m): two torque-like pairs ``|a u + b x + c| <= T``, x >= 0
    and a cap on x; ``floors`` stages also x >= a least squared speed."""
    a = rng.uniform(0.5, 2.0, (n, 2)) * rng.choice([-1, 1], (n, 2))
    b = rng.uniform(-1.0, 1.0, (n, 2))
    c = rng.uniform(-0.2, 0.2, (n, 2))
    T = np.ones((n, 2))
    xmin = np.zeros(n)
    xmin[floors] = rng.uniform(0.05, top, len(floors))
    # and a steep upper row u <= 20 - 40 x before and at the floors: going faster costs
    # acceleration, so reaching a least speed next caps this point's speed (x <= m lo + q)
    steep = np.zeros(n)
    steep[floors[0] - 4:floors[-1] + 1] = 1.0
    Gu = np.concatenate([a, -a, np.zeros((n, 3)), steep[:, None]], axis=1)
    Gx = np.concatenate([b, -b, -np.ones((n, 1)), np.ones((n, 1)), -np.ones((n, 1)),
                         40 * steep[:, None]], axis=1)
    h = np.concatenate([T - c, T + c, np.zeros((n, 1)), np.full((n, 1), 5.0), -xmin[:, None],
                        np.where(steep > 0, 20.0, 1.0)[:, None]], axis=1)
    ds = rng.uniform(0.01, 0.05, n)
    return Gu, Gx, h, ds


def _lp(obj_x, obj_u, Gu, Gx, h, ds, lo, hi, x=None):
    """Optimum of ``obj_x x + obj_u u`` over the stage's rows and ``lo <= x + 2 ds u <= hi``
    (``x`` fixed when given); None when infeasible."""
    A = np.column_stack([Gx, Gu])
    rows = [A, [[1.0, 2 * ds]], [[-1.0, -2 * ds]]]
    rhs = [h, [hi], [-lo]]
    bounds = [(0, None) if x is None else (x, x), (None, None)]
    r = linprog([obj_x, obj_u], A_ub=np.vstack(rows), b_ub=np.concatenate(rhs), bounds=bounds,
                method="highs")
    return r.x if r.status == 0 else None


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(8))
def test_passes_agree_with_linear_programmes_also_where_a_least_speed_is_needed(seed):
    rng = np.random.default_rng(seed)
    n = 30
    # even seeds: least speeds the motion can meet; odd: some that it cannot (no motion)
    Gu, Gx, h, ds = _random_stages(rng, n, np.arange(12, 18), top=0.3 if seed % 2 == 0 else 4.0)
    st = _stages(Gu, Gx, h, ds)

    def unreachable(k):
        return InfeasibleError(f"stage {k}")

    try:
        K_lo, K_hi = _controllable(st, unreachable)
    except InfeasibleError:
        K_lo = None
    # the reference: the controllable sets stage by stage, backward from rest at the end
    ref_lo, ref_hi, feasible = [0.0] * (n + 1), [0.0] * (n + 1), True
    for k in range(n - 1, -1, -1):
        top = _lp(-1.0, 0.0, Gu[k], Gx[k], h[k], ds[k], ref_lo[k + 1], ref_hi[k + 1])
        low = _lp(1.0, 0.0, Gu[k], Gx[k], h[k], ds[k], ref_lo[k + 1], ref_hi[k + 1])
        if top is None:
            feasible = False
            break
        ref_hi[k], ref_lo[k] = top[0], low[0]
    feasible = feasible and ref_lo[0] <= 1e-9
    assert feasible == (seed % 2 == 0)  # both kinds of case occur
    assert (K_lo is not None) == feasible
    if not feasible:
        return
    assert np.allclose(K_hi, ref_hi, rtol=1e-9, atol=1e-12)
    assert np.allclose(K_lo, ref_lo, rtol=1e-9, atol=1e-12)
    assert max(K_lo[12:19]) > 0.01  # some stages cannot be left at rest: the lo > 0 branch ran
    # forward: the largest acceleration at each point that keeps the next one controllable
    x = _fastest(st, K_lo, K_hi, unreachable)
    for k in range(n):
        best = _lp(0.0, -1.0, Gu[k], Gx[k], h[k], ds[k], K_lo[k + 1], K_hi[k + 1], x=x[k])
        assert best is not None
        assert x[k + 1] == pytest.approx(x[k] + 2 * ds[k] * best[1], rel=1e-9, abs=1e-12) \
            or k == n - 1
    assert x[0] == x[-1] == 0.0


def _speeds(Gu, Gx, h, ds):
    """The squared speeds, or the stage at which no motion passes."""
    try:
        return _passes(Gu, Gx, h, ds, lambda k: InfeasibleError(f"stage {k}"))
    except (InfeasibleError, ParameterError) as e:
        return f"{type(e).__name__}: {e}"


@pytest.mark.skipif(time_optimal._compiled is None,
                    reason="the compiled passes were not built (no C compiler at install)")
def test_compiled_and_python_passes_give_the_same_speeds_to_the_last_bit(monkeypatch):
    """Random stages (least speeds met and not met, so the backward pass's and the forward
    pass's failures occur) and the rows of a real path with gravity, friction and a
    torque-speed envelope: the same squared speeds bit for bit, or the same failing
    stage."""
    import dextar.dynamics as dyn
    from dextar.laws.constraints import motor_constraints
    from dextar.motors import MotorLimits
    from dextar.paths import Arc

    cases = []
    for seed in range(60):
        rng = np.random.default_rng(seed)
        n = int(rng.integers(15, 80))
        lo = int(rng.integers(5, n - 6))
        cases.append(_random_stages(rng, n, np.arange(lo, lo + 5),
                                    top=float(rng.choice([0.3, 1.0, 4.0]))))
    inertia = dyn.Inertia.uniform(ROBOT_M, proximal_mass=0.03, distal_mass=0.02,
                                  effector_mass=0.1, gravity=(0.0, -9.81),
                                  viscous=(0.01, 0.01), coulomb=(0.02, 0.02))
    robot = dyn.Model(ROBOT_M, inertia)
    along = dyn.RobotAlongPath(robot, Arc(0.12, 0.0, np.pi))
    co = along.coefficients(np.linspace(0.0, along.length, 301))
    cons = motor_constraints(MotorLimits((0.6, 0.6), max_speed=(9.0, 9.0),
                                         knee_speed=(3.0, 3.0)))
    x0 = np.full(301, 0.5)
    cases.append((*time_optimal._rows(co, np.diff(co.s), cons, x0), np.diff(co.s)))
    # rows no motion meets (h = -inf) and rows that are not numbers, from a constraint of
    # one's own: the same error either way (the Python elimination's padding met a -inf
    # with a NaN of its own, the compiled one none)
    for value in (-np.inf, np.nan, np.inf):
        rng = np.random.default_rng(7)
        Gu, Gx, h, ds = _random_stages(rng, 30, np.arange(12, 17))
        h = h.copy()
        h[9, 2] = value
        cases.append((Gu, Gx, h, ds))
    outcomes = set()
    for Gu, Gx, h, ds in cases:
        monkeypatch.setattr(time_optimal, "USE_COMPILED", True)
        compiled = _speeds(Gu, Gx, h, ds)
        monkeypatch.setattr(time_optimal, "USE_COMPILED", False)
        python = _speeds(Gu, Gx, h, ds)
        assert type(compiled) is type(python)
        if isinstance(python, str):
            assert compiled == python
            outcomes.add(python.split(":")[0])
        else:
            assert np.array_equal(compiled.view(np.int64), python.view(np.int64))  # bits
            outcomes.add("speeds")
    assert outcomes == {"InfeasibleError", "ParameterError", "speeds"}  # each kind occurs


def test_the_compiled_passes_are_built_where_a_compiler_is():
    """pip builds them where a C compiler is (as on CI): a failed build would otherwise pass
    unseen, every test then running the Python passes."""
    skip_without_a_compiler()
    assert time_optimal._compiled is not None, (
        "dextar.laws._reach was not built: reinstall (pip install -e .) and read the "
        "compiler's output")
    assert time_optimal._compiled.VERSION == time_optimal.REACH_VERSION
    assert time_optimal.USE_COMPILED
    from dextar.laws import optimal  # (the same module's chebval, the same version)

    assert optimal.REACH_VERSION == time_optimal.REACH_VERSION and optimal.USE_COMPILED


def test_an_old_build_of_the_compiled_passes_is_not_used():
    """A build of another interface version (an edit of _reach.c whose build failed leaves
    the old one in place) is set aside at import: the Python passes run."""
    from types import SimpleNamespace

    from dextar._compiled import usable

    version = time_optimal.REACH_VERSION
    assert not usable(SimpleNamespace(VERSION=version + 1), version)
    assert usable(SimpleNamespace(VERSION=version), version)
    if time_optimal._compiled is not None:
        assert usable(time_optimal._compiled, version)


@pytest.mark.parametrize("terms", [1, 2, 3, 1029])
def test_the_compiled_chebyshev_series_is_numpys(terms, monkeypatch):
    """The optimal law's series at many points (a forward re-simulation's windows: the
    compiled Clenshaw recurrence, chebval of _reach.c) is numpy's chebval: the same
    additions and products in the same order (no fused multiply-add), so the same values
    to the last bit on any IEEE machine (NaN and inf where numpy's are), on series of 1 to
    1029 terms at 353 points in and beyond [-1, 1]; with ``USE_COMPILED`` off, numpy's."""
    from types import SimpleNamespace

    from numpy.polynomial import chebyshev

    from dextar.laws import optimal

    if optimal._compiled is None:
        pytest.skip("the compiled part is not built here")
    rng = np.random.default_rng(terms)
    c = rng.normal(size=terms) / np.arange(1, terms + 1) ** 2
    x = np.concatenate([rng.uniform(-1.2, 1.2, 351), [np.nan, np.inf]])
    real, calls = optimal._compiled, []

    def spy(*args):
        calls.append(len(args[0]))
        return real.chebval(*args)

    monkeypatch.setattr(optimal, "_compiled", SimpleNamespace(chebval=spy))
    monkeypatch.setattr(optimal, "MATRIX_LIMIT", 0)  # (Clenshaw's at any size)
    with np.errstate(invalid="ignore", over="ignore"):
        want = chebyshev.chebval(x, c)
        got = optimal._chebval(x, c)
        assert calls == [len(x)]
        np.testing.assert_array_equal(got, want)
        monkeypatch.setattr(optimal, "USE_COMPILED", False)
        np.testing.assert_array_equal(optimal._chebval(x, c), want)
    assert calls == [len(x)]  # (numpy's: the compiled part not called)
    with pytest.raises(ValueError, match="chebval"):
        real.chebval(x, c, np.empty(3))
