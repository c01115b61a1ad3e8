"""The jerk-limited law's compiled interior point (``laws/smooth/_ipm.c``) against the numpy
solver it replaces where it was built (the same programmes, the same answers to their
tolerances, the same laws), and the start's jerks whatever the number of knots."""

import dataclasses
import signal
from types import SimpleNamespace

import numpy as np
import pytest

from dextar._compiled import usable
from dextar.dynamics import RobotAlongPath
from dextar.laws import solve_jerk_limited_law
from dextar.laws.constraints import motor_constraints
from dextar.laws.smooth import banded, mesh, rows, slp, solve, start, table
from dextar.motors import MotorLimits
from dextar.paths import Line

from ..compiled import skip_without_a_compiler
from ..program.test_program import EXAMPLES

# (the chain's fixtures, shared)
from .test_smooth_parts import (  # noqa: F401
    MOTORS,
    as_linprog,
    chain,
    programmes,
    setup,
    started,
)


def both(monkeypatch, lp, x0, **kw):
    """The programme solved by the numpy solver and by the compiled one."""
    monkeypatch.setattr(banded, "USE_COMPILED", False)
    python = banded.solve_staged(lp, x0, **kw)
    monkeypatch.setattr(banded, "USE_COMPILED", True)
    compiled = banded.solve_staged(lp, x0, **kw)
    return python, compiled


def test_the_compiled_interior_point_is_built_where_a_compiler_is():
    """pip builds it where a C compiler is (as on CI): a failed build would otherwise pass
    unseen, every test then running the numpy solver."""
    skip_without_a_compiler()
    assert banded._compiled is not None, (
        "dextar.laws.smooth._ipm was not built: reinstall (pip install -e .) and read the "
        "compiler's output")
    assert banded._compiled.VERSION == banded.IPM_VERSION
    assert banded.USE_COMPILED


def test_an_old_build_of_the_compiled_interior_point_is_not_used():
    """A build of another interface version is set aside (the numpy solver runs)."""
    version = banded.IPM_VERSION
    assert not usable(SimpleNamespace(VERSION=version + 1), version)
    assert usable(SimpleNamespace(VERSION=version), version)


def test_the_compiled_interior_point_solves_as_the_numpy_one(setup, monkeypatch):  # noqa: F811
    """On the blended chain's programmes (two pinned joints): the same status, the same
    objective to 1e-9 (relative; both stop at a duality gap of 1e-6), the same solution to
    1e-6 of its scale, within a couple of iterations of each other; stopped after three
    iterations, both say they have not converged."""
    if banded._compiled is None:
        pytest.skip("the compiled interior point is not built here")
    for lp, x0 in programmes(setup):
        python, compiled = both(monkeypatch, lp, x0)
        assert python.status == compiled.status == 0
        assert abs(python.fun - compiled.fun) <= 1e-9 * (1 + abs(python.fun))
        scale = 1 + np.abs(python.x).max()
        assert np.abs(python.x - compiled.x).max() <= 1e-6 * scale
        assert abs(python.nit - compiled.nit) <= 2
        early = both(monkeypatch, lp, x0, maxiter=3)
        assert [r.status for r in early] == [1, 1]
        assert [r.nit for r in early] == [3, 3]


def test_each_stopping_rule_stops_both_solvers_alike(setup, monkeypatch):  # noqa: F811
    """With the other two tolerances out of play, each rule alone (the primal residuals, the
    dual ones, the gap) stops the compiled solver at the numpy solver's iteration, give or
    take one (their iterates agree to rounding): a rule the compiled passes dropped or
    miscomputed stops it elsewhere."""
    if banded._compiled is None:
        pytest.skip("the compiled interior point is not built here")
    loose = 1e3  # (the gap's rule also ends a solve whose gap is below 1e-6 of its bound)
    for lp, x0 in programmes(setup):
        for least, kw in ((1, dict(dual_tol=loose, gap_tol=loose)),
                          (2, dict(tol=loose, gap_tol=10.0)),
                          (3, dict(tol=loose, dual_tol=loose))):
            python, compiled = both(monkeypatch, lp, x0, **kw)
            assert python.status == compiled.status == 0, kw
            # (the rule had work to do: 3 and 1, 4 and 2, 9 and 6 iterations on the two
            # programmes, 5 and 1, 7 and 3, 9 and 6 before banded.TARGET_FLOOR held the
            # corrector's target at the gap's tolerance; a full primal step meets the
            # equalities and rows to rounding, so the primal rule is met at once after it:
            # the start's slacks of SLACK_FLOOR make the start nearly feasible; a solver
            # without the rule stops at 0)
            assert python.nit >= least and compiled.nit >= least, (kw, python.nit)
            assert abs(python.nit - compiled.nit) <= 1, (kw, python.nit, compiled.nit)


def test_the_compiled_interior_point_meets_the_programme(setup, monkeypatch):  # noqa: F811
    """Its solution is within the rows, the equalities and the bounds; a programme whose
    Newton matrix cannot be factorised (a NaN in a row) is status 2, not a solution."""
    if banded._compiled is None:
        pytest.skip("the compiled interior point is not built here")
    monkeypatch.setattr(banded, "USE_COMPILED", True)
    lp, x0 = programmes(setup)[0]
    res = banded.solve_staged(lp, x0)
    g = as_linprog(lp)
    scale = 1 + np.abs(lp.rb).max()
    assert res.status == 0
    assert (g["A_ub"] @ res.x - lp.rb).max() <= 1e-7 * scale
    assert np.abs(g["A_eq"] @ res.x - g["b_eq"]).max() <= 1e-7 * scale
    assert np.all(res.x >= lp.lo - 1e-9) and np.all(res.x <= lp.hi + 1e-9)
    ra = lp.ra.copy()
    ra[len(ra) // 2, 2] = np.nan
    bad = banded.solve_staged(banded.StagedLP(lp.c, lp.rk, ra, lp.rg, lp.rb, lp.E, lp.e,
                                              lp.lo, lp.hi), x0)
    assert bad.status == 2


@pytest.mark.slow
def test_a_signal_ends_the_compiled_interior_point(line_start, monkeypatch):
    """A signal's handler runs between the compiled iterations: the exception it raised 10 ms
    into a programme of 3000 knots ends the solve in a fraction of the solve's CPU time (not
    when the solve returns)."""
    import time

    if banded._compiled is None:
        pytest.skip("the compiled interior point is not built here")
    monkeypatch.setattr(banded, "USE_COMPILED", True)
    along, tab, cons, st = line_start
    me = start.pinned(start.fractions(st, tab, cons, 3000, solve.KNOT_TOL), st, tab.joints)
    model = rows.RowModel(me, tab, [c for c in cons if c.order == 2],
                          [c for c in cons if c.order == 3], along.length)
    J = start.start_jerks(st, me, along.length)
    Tk = slp.time_scaled(model, J, np.full(me.M, st.T))
    mo = mesh.motion(me, J, Tk, along.length)
    r = model.rows(mo)
    prog = slp.Programme(me, along.length)
    scale, jscale = float(np.abs(mo.alpha).max()), float(np.abs(mo.J).max())
    lp, x0 = prog.build(r, r.F + prog.reach(r, mo, 0.3, scale, jscale) > -1e-9, mo, mo.T,
                        0.3, scale, jscale)
    t0 = time.process_time()
    whole = banded.solve_staged(lp, x0)
    full = time.process_time() - t0
    assert whole.status == 0 and whole.nit >= 10

    class StopError(Exception):
        pass

    def handler(signum, frame):
        raise StopError

    old = signal.signal(signal.SIGALRM, handler)
    try:
        t0 = time.process_time()
        signal.setitimer(signal.ITIMER_REAL, 0.01)
        with pytest.raises(StopError):
            banded.solve_staged(lp, x0)
        stopped = time.process_time() - t0
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert stopped < 0.5 * full, (stopped, full)


@pytest.mark.slow
def test_the_law_is_the_same_with_either_solver(chain, monkeypatch):  # noqa: F811
    """The blended chain's law with the compiled and the numpy interior point: both within
    the limits, the same duration to 1e-3 (the programmes agree to their tolerances, but the
    SLP's path through some forty of them is not the same to the last bit: measured 4e-5
    apart, one of the two settling, the other stopping at its budget)."""
    if banded._compiled is None:
        pytest.skip("the compiled interior point is not built here")
    dyn, path = chain
    pts = np.unique(np.concatenate([np.linspace(0.0, path.length, 201), path.starts]))
    laws = []
    for compiled in (False, True):
        monkeypatch.setattr(banded, "USE_COMPILED", compiled)
        laws.append(solve_jerk_limited_law(dyn, motors=MOTORS, grid=pts))
    assert [law.status for law in laws] == [0, 0]
    assert abs(laws[0].duration - laws[1].duration) <= 1e-3 * laws[0].duration


@pytest.fixture(scope="module")
def line_start():
    """bench_smooth.py's pick-and-place line (examples/pick_place.toml's robot and motors,
    with a joint acceleration and jerk limit): the path table, constraints, filtered start."""
    from dextar.config import load_scenario

    sc = load_scenario(str(EXAMPLES / "pick_place.toml"))
    m = sc.si_motors
    motors = MotorLimits(m.peak_torque, m.max_speed, m.knee_speed, (60.0, 60.0),
                         (3000.0, 3000.0))
    along = RobotAlongPath(sc.si_model, Line((-0.04, 0.11), (0.04, 0.09)), sc.mode)
    cons = motor_constraints(motors)
    second = [c for c in cons if c.order == 2]
    third = [c for c in cons if c.order == 3]
    tab = table.make_table(along, np.linspace(0.0, along.length, 401))
    base = solve._second_order(along, tab, second, None)
    return along, tab, cons, solve._start(along, tab, second, third, base, None)


def test_the_start_jerks_do_not_grow_with_the_knots(line_start):
    """The start's largest jerk on 16000 knots within 1 % of that on 1000 (the start's last
    sample's acceleration, not quite zero, jumped to zero within the last interval: a jerk
    growing as the knots, 61 % over at 16000, and the start 17 % slower)."""
    along, tab, cons, st = line_start
    jmax = []
    for n in (1000, 16000):
        me = start.pinned(start.fractions(st, tab, cons, n, solve.KNOT_TOL), st, tab.joints)
        jmax.append(np.abs(start.start_jerks(st, me, along.length)).max())
    assert jmax[1] <= 1.01 * jmax[0]


def test_a_long_programme_has_a_proximal_term_on_its_jerks(setup, monkeypatch):  # noqa: F811
    """From ``slp.LONG_PROGRAMME`` intervals the programme carries proximal weights on its
    jerks' box (the upper rows, ``PROX h / jb^2``), a shorter one none. Both solvers, and
    the numpy one with the rows' products made in every iteration (a long programme's
    way), then give the convex quadratic programme's solution ``x``, the same to 1e-6 of
    its scale: by HiGHS, no feasible point is better along the objective's gradient at
    ``x`` (first-order optimality, checked independently); it is nearer the start than
    the linear programme's solution (``q``, the quadratic term, under a tenth: the weight
    made 100 times PROX so that ``q`` is far above the tolerances), its linear objective
    ``c x`` no lower; with zero weights each solver gives the linear programme's solution
    to the bit."""
    from scipy.optimize import linprog

    model, me, *_ = setup
    assert programmes(setup)[0][0].rq is None  # (the chain's mesh: tens of intervals)
    monkeypatch.setattr(slp, "LONG_PROGRAMME", 16)
    monkeypatch.setattr(slp, "PROX", 100 * slp.PROX)
    solvers = [(False, banded.KEEP), (False, 0)] + ([(True, banded.KEEP)]
                                                    if banded._compiled is not None else [])
    for lp, x0 in programmes(setup):
        assert lp.rq is not None
        on = np.flatnonzero(lp.rq)
        assert len(on) == len(lp.E) - 2  # (all but the two intervals into the pins)
        general = as_linprog(lp)
        g = general["A_ub"]
        jb = lp.rb[on] - g[on] @ x0  # (the upper rows of the box: its half-width)
        assert np.allclose(lp.rq[on] * jb * jb, slp.PROX * me.h[lp.rk[on]], rtol=1e-9)
        tol = None
        first = None
        for compiled, keep in solvers:
            monkeypatch.setattr(banded, "USE_COMPILED", compiled)
            monkeypatch.setattr(banded, "KEEP", keep)
            linear = banded.solve_staged(dataclasses.replace(lp, rq=None), x0)
            zero = banded.solve_staged(dataclasses.replace(lp, rq=np.zeros(len(lp.rk))), x0)
            assert np.array_equal(linear.x, zero.x)
            tol = 1e-6 * (1 + abs(linear.fun))
            res = banded.solve_staged(lp, x0)
            assert res.status == 0
            first = first or res
            assert np.abs(res.x - first.x).max() <= 1e-6 * (1 + np.abs(first.x).max())
            assert abs(res.nit - first.nit) <= 2
            d, d_lin = g @ (res.x - x0), g @ (linear.x - x0)
            q, q_lin = 0.5 * float(lp.rq @ (d * d)), 0.5 * float(lp.rq @ (d_lin * d_lin))
            slope = lp.c + g.T @ (lp.rq * d)
            best = linprog(**dict(general, c=slope), method="highs")
            assert best.status == 0
            # (measured: 5.5e-9 and 1.7e-8 against about 1.9e-6; 1.6e-3 without the
            # term's gradient in either solver)
            assert float(slope @ res.x) - best.fun <= tol
            assert q_lin > 100 * tol and q <= 0.1 * q_lin  # (measured: 0.03 and 0.005)
            assert res.fun >= linear.fun - tol
