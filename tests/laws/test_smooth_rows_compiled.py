"""The jerk-limited law's compiled rows and knot monitor (``laws/smooth/_rows.c``) against the
numpy code they replace where they were built: the same rows in the same order (values,
intervals, normalisations, gradients and their sizes) on the blended chain, with a jerk
limit and with a torque-rate limit, friction and a speed cap; the same knots; bad sizes an
error, not a crash."""

from dataclasses import replace

import numpy as np
import pytest

from dextar.laws.constraints import PointRows, Tangent, motor_constraints, point_rows
from dextar.laws.smooth import mesh, rows, solve, start
from dextar.motors import MotorLimits

from ..compiled import skip_without_a_compiler

# (the chain's fixtures, shared)
from .test_smooth_parts import chain, setup, started  # noqa: F401

#: A torque-rate limit with a speed limit (a speed cap on the rows) and friction on the
#: table (the torque rate's friction slope), beside the chain's jerk limit.
RATE = MotorLimits((1.5, 1.5), max_speed=(6.0, 6.0), max_torque_rate=(40.0, 40.0),
                   max_acceleration=(400.0, 400.0))


def needs_build():
    if rows._compiled is None:
        pytest.skip("the compiled rows are not built here")


def test_the_compiled_rows_are_built_where_a_compiler_is():
    """pip builds them where a C compiler is (as on CI): a failed build would otherwise pass
    unseen, every test then building the rows with numpy."""
    skip_without_a_compiler()
    assert rows._compiled is not None, (
        "dextar.laws.smooth._rows was not built: reinstall (pip install -e .) and read the "
        "compiler's output")
    assert rows._compiled.VERSION == rows.ROWS_VERSION
    assert rows.USE_COMPILED


def both(monkeypatch, model, mo, gradients=True):
    """The rows at ``mo`` built with numpy and compiled."""
    monkeypatch.setattr(rows, "USE_COMPILED", False)
    numpy_rows = model._rows(mo, gradients)
    monkeypatch.setattr(rows, "USE_COMPILED", True)
    return numpy_rows, model._rows(mo, gradients)


def assert_same(a, b):
    """The same rows in the same order: intervals and kinds exactly, values to rounding
    (1e-12 of each array's scale: the C library's pow and cosh may differ from numpy's in
    the last bit; the third-order rows here by up to 3e-13, the rest the same bits)."""
    assert a.kinds == b.kinds
    np.testing.assert_array_equal(a.k, b.k)
    assert a.k.dtype == b.k.dtype and a.sizes.dtype == b.sizes.dtype
    for name in ("F", "norm", "C", "sizes"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape, name
        scale = float(np.abs(x).max(initial=0.0))
        np.testing.assert_allclose(y, x, rtol=1e-12, atol=1e-12 * scale, err_msg=name)


def motions(model, J, Tk):
    """The chain's start motion and one with its jerks and durations changed (the rows at a
    motion the programmes moved to)."""
    me = model.mesh
    rng = np.random.default_rng(7)
    Jn = J + 0.2 * rng.normal(size=J.size) * np.abs(J).max()
    Tn = Tk * (1 + 0.1 * rng.normal(size=len(me.pins) + 1)[me.stretch])
    j = mesh.projected(me, Jn / Tn**3, Tn, model.length)
    return [mesh.motion(me, J, Tk, model.length), mesh.motion(me, j * Tn**3, Tn, model.length)]


def test_the_compiled_rows_are_the_numpy_rows_with_a_jerk_limit(setup, monkeypatch):  # noqa: F811
    """The chain's rows (second order at the knots and middles, w >= 0, the joint jerks at
    every interval's start, middle and end), with and without gradients, and built a few
    intervals at a time (blocks that start past the first knot, the compiled ones written
    into one set of arrays that then owns its rows)."""
    needs_build()
    model, _, J, Tk, _ = setup
    for mo in motions(model, J, Tk):
        for gradients in (True, False):
            a, b = both(monkeypatch, model, mo, gradients)
            assert len(a.F) > 10 * model.mesh.M and (len(a.C) > 0) == gradients
            assert_same(a, b)
    monkeypatch.setattr(rows, "CHUNK", 7)
    for gradients in (True, False):  # (several blocks, written into one set of arrays)
        a, b = both(monkeypatch, model, motions(model, J, Tk)[1], gradients)
        assert len(a.kinds) > 4 * 3 and (len(b.C) > 0) == gradients
        assert_same(a, b)
        assert all(x.base is None for x in (b.F, b.k, b.C, b.norm, b.sizes))  # (their own)
    # every quarter's and middle's row kept (near any use, above any chord), blocks of 7
    # and of all
    monkeypatch.setattr(rows, "QUARTER_NEAR", 10.0)
    monkeypatch.setattr(rows, "QUARTER_BULGE", -10.0)
    monkeypatch.setattr(rows, "MIDDLE_BULGE", -np.inf)
    M = model.mesh.M
    for chunk in (7, 2048):
        monkeypatch.setattr(rows, "CHUNK", chunk)
        a, b = both(monkeypatch, model, motions(model, J, Tk)[1])
        assert sum(n for k, n in a.kinds if k == "second-order") == 4 * (4 * M - 1)
        assert_same(a, b)


def test_the_compiled_rows_are_the_numpy_rows_with_a_torque_rate_limit(setup, monkeypatch):  # noqa: F811
    """With a torque-rate limit (the friction's slope near a reversal, gravity's rate), a
    speed cap and Coulomb and viscous friction on the table."""
    needs_build()
    model, me, J, Tk, tab = setup
    co = replace(tab.co, coulomb=np.array([0.02, 0.03]), viscous=np.array([0.01, 0.02]),
                 coulomb_speed=0.05)
    tab = replace(tab, co=co)
    cons = motor_constraints(RATE)
    rate = rows.RowModel(me, tab, [c for c in cons if c.order == 2],
                         [c for c in cons if c.order == 3], model.length)
    assert rate.root_cap is not None
    for mo in motions(model, J, Tk):
        a, b = both(monkeypatch, rate, mo)
        assert [name for name, _ in a.kinds] == ["second-order", "cap", "w>=0", "third"]
        assert_same(a, b)


@pytest.mark.parametrize("motors", [
    RATE, MotorLimits((1.5, 1.2), max_speed=(6.0, 7.0), knee_speed=(3.0, 2.5),
                      max_jerk=(3000.0, 3000.0), max_acceleration=(400.0, 300.0))],
    ids=["torque-speed-acceleration", "envelope"])
def test_the_compiled_columns_are_the_constraints_rows(setup, motors, monkeypatch):  # noqa: F811
    """The second-order rows' columns at the table's points (the built-in constraints: the
    peak torque with the friction's tangent, the torque-speed envelope with its own, an
    acceleration limit; the speed limit as the cap) are the constraint objects' rows to the
    bit, with Coulomb and viscous friction on the table, at two motions' tangent points."""
    needs_build()
    model, me, J, Tk, tab = setup
    co = replace(tab.co, coulomb=np.array([0.02, 0.03]), viscous=np.array([0.01, 0.02]),
                 coulomb_speed=0.05)
    cons = motor_constraints(motors)
    rm = rows.RowModel(me, replace(tab, co=co), [c for c in cons if c.order == 2],
                       [c for c in cons if c.order == 3], model.length)
    assert rm._spec is not None
    for mo in motions(model, J, Tk):
        x0 = rm.tangent(mo)
        out = []
        for compiled in (False, True):
            monkeypatch.setattr(rows, "USE_COMPILED", compiled)
            out.append(rm._columns(x0))
        (a, ma, pa), (b, mb, pb) = out
        assert ma == mb == 4 * len([c for c in cons if c.order == 2 and c.kind != "speed"])
        assert pa == pb > 0
        np.testing.assert_array_equal(a, b)


def test_a_constraint_of_another_class_keeps_its_own_rows(setup, monkeypatch):  # noqa: F811
    """A constraint the compiled columns do not know (a plugin's, or a subclass of a built-in
    one with rows of its own) has its own rows: the columns are then the objects' rows."""
    from dextar.laws.constraints import TorqueLimit

    class Derated(TorqueLimit):
        def rows(self, tangent):
            r = super().rows(tangent)
            return PointRows(r.pu, r.px, 0.5 * r.ph)

    model, me, J, Tk, tab = setup
    mo = motions(model, J, Tk)[0]
    plain = rows.RowModel(me, tab, [TorqueLimit((1.5, 1.5))], model.third, model.length)
    own = rows.RowModel(me, tab, [Derated((1.5, 1.5))], model.third, model.length)
    assert own._spec is None and (plain._spec is not None or rows._compiled is None)
    x0 = own.tangent(mo)
    a, b = plain._columns(x0)[0], own._columns(x0)[0]
    m = 4
    np.testing.assert_array_equal(b[:, 2 * m:3 * m], 0.5 * a[:, 2 * m:3 * m])


def test_the_compiled_monitor_places_the_numpy_knots(chain, monkeypatch):  # noqa: F811
    """The knots of the chain's start (the monitor of its torques, accelerations, jerks and
    speeds) are those of the numpy monitor."""
    needs_build()
    dyn, path = chain
    from .test_smooth_parts import grid

    tab = solve.make_table(dyn, grid(path))
    for motors in (RATE, replace(RATE, max_jerk=(3000.0, 3000.0), max_torque_rate=None)):
        cons = motor_constraints(motors)
        second = [c for c in cons if c.order == 2]
        base = solve._second_order(dyn, tab, second, None)
        st = solve._start(dyn, tab, second, [c for c in cons if c.order == 3], base, None)
        monkeypatch.setattr(rows, "USE_COMPILED", False)
        f_numpy = start.fractions(st, tab, cons, 32, solve.KNOT_TOL)
        monkeypatch.setattr(rows, "USE_COMPILED", True)
        f_compiled = start.fractions(st, tab, cons, 32, solve.KNOT_TOL)
        assert len(f_numpy) > 33  # denser than the fewest: the monitor placed them
        assert f_compiled.shape == f_numpy.shape
        np.testing.assert_allclose(f_compiled, f_numpy, rtol=0, atol=1e-12)


def test_the_compiled_rows_leave_out_the_rows_without_a_limit(setup, monkeypatch):  # noqa: F811
    """Where a second-order row's limit is not finite (a column ``ph`` of +-inf or NaN at
    some grid points), its rows there are left out, by the compiled rows as by numpy's,
    in a block from the first interval and in one past it."""
    needs_build()
    model, _, J, Tk, _ = setup
    mo = motions(model, J, Tk)[1]
    pr = point_rows(model.second, Tangent(model.table.moving, np.concatenate(
        [model.tangent(mo)[:1], model.tangent(mo), model.tangent(mo)[-1:]])))
    every = PointRows(pr.pu[1:-1], pr.px[1:-1], pr.ph[1:-1])
    ph = pr.ph[1:-1].copy()
    ph[40:60, 1], ph[100:103, 2], ph[150, 0] = np.inf, -np.inf, np.nan
    cols, m, phmax = rows.columns(PointRows(pr.pu[1:-1], pr.px[1:-1], ph), model.root_cap)
    M = model.mesh.M
    for k0, k1 in ((0, M), (5, 17)):
        out = []
        for compiled in (False, True):
            monkeypatch.setattr(rows, "USE_COMPILED", compiled)
            model._grad = True
            out.append(model._block(mo, cols, m, phmax, k0, k1))
        assert_same(*out)
        model._grad = True
        full = model._block(mo, *rows.columns(every, model.root_cap), k0, k1)
        # some were left out (the same block with every limit finite has more)
        assert dict(out[1].kinds)["second-order"] < dict(full.kinds)["second-order"]


@pytest.mark.parametrize("kinds", [[0.0], [1.0], [2.0], [3.0], [0.0, 1.0, 2.0, 3.0]])
def test_the_compiled_monitor_is_the_numpy_monitor(chain, kinds, monkeypatch):  # noqa: F811
    """Each part of the knots' monitor (a joint acceleration, a torque, a joint jerk, a
    speed) and all of them at once, on the chain's start: the same values."""
    needs_build()
    dyn, path = chain
    from .test_smooth_parts import grid

    tab = solve.make_table(dyn, grid(path))
    cons = motor_constraints(RATE)
    second = [c for c in cons if c.order == 2]
    base = solve._second_order(dyn, tab, second, None)
    st = solve._start(dyn, tab, second, [c for c in cons if c.order == 3], base, None)
    lims = [np.array([3.0, 5.0]) * (i + 1) for i in range(len(kinds))]
    dt = float(st.t[1] - st.t[0])
    out = []
    for compiled in (False, True):
        monkeypatch.setattr(rows, "USE_COMPILED", compiled)
        out.append(start._monitor(tab, st.s, st.v, st.a, kinds, lims, dt))
    assert np.abs(out[0]).max() > 0
    np.testing.assert_allclose(out[1], out[0], rtol=1e-12, atol=1e-12 * np.abs(out[0]).max())


@pytest.mark.parametrize("bad", ["fric", "F", "norm", "k", "C", "sizes", "k1", "m"])
def test_the_compiled_rows_refuse_inconsistent_sizes(setup, bad):  # noqa: F811
    """Arrays of the wrong sizes (an output one row short, a block past the mesh, a number
    of columns whose products would overflow) are a ValueError, never a read or a write
    past an array's end; a wrong dtype is a TypeError."""
    needs_build()
    assert rows._compiled is not None
    model, _, J, Tk, tab = setup
    mo = mesh.motion(model.mesh, J, Tk, model.length)
    M, m = model.mesh.M, 4
    kinds, lims, fric = model._third_spec
    # the rows of the whole mesh: the second-order rows at the inner knots, the middles and
    # the quarters (every one near its limit here: all zero), w >= 0 at the first two
    R = (4 * M - 1) * m + (2 * M - 1) + 12 * M * len(kinds)
    short = {name: (R - 1 if bad == name else R) for name in ("F", "norm", "k", "C", "sizes")}
    pcols = np.zeros((len(tab.s), 4 * m))
    pcols[:, 3 * m:] = 1.0  # every limit finite: every row kept
    args = dict(pcols=pcols, fric=fric[:4] if bad == "fric" else fric,
                F=np.zeros(short["F"]), norm=np.zeros(short["norm"]),
                C=np.zeros((short["C"], 5)), k=np.zeros(short["k"], np.int32),
                sizes=np.zeros((short["sizes"], 5), np.float32),
                m=2**62 + 1 if bad == "m" else m, k1=M + 1 if bad == "k1" else M)

    def call(**kw):
        a = {**args, **kw}
        return rows._compiled.block(tab.s, a["pcols"], tab.lo, tab.hi, model.mesh.h, mo.J,
                                    mo.Tk, mo.sigma, mo.w, mo.alpha, kinds, lims, a["fric"],
                                    a["F"], a["norm"], a["C"], a["k"], a["sizes"], a["m"], 0,
                                    0, a["k1"], 1e-300, model.length, -1.0 / model.length,
                                    rows.QUARTER_NEAR, -1.0, -np.inf,
                                    True)  # (every quarter and middle kept)

    with pytest.raises(ValueError, match="inconsistent"):
        call()
    good = {**args, "fric": fric, "m": m, "k1": M, "F": np.zeros(R), "norm": np.zeros(R),
            "C": np.zeros((R, 5)), "k": np.zeros(R, np.int32),
            "sizes": np.zeros((R, 5), np.float32)}
    assert sum(call(**good)) == R  # (the same call with every size right)
    with pytest.raises(TypeError, match="int32"):
        call(**{**good, "k": np.zeros(R)})


def test_the_compiled_monitor_refuses_inconsistent_sizes(setup):  # noqa: F811
    """The monitor's arrays of the wrong sizes are a ValueError."""
    needs_build()
    assert rows._compiled is not None
    tab = setup[4]
    z = np.zeros(4)
    with pytest.raises(ValueError, match="inconsistent"):
        rows._compiled.monitor(tab.s, tab.lo, tab.hi, z, z, z[:3], z[:1], z[:2], 0.1, z)


@pytest.mark.parametrize("bad", ["cols", "pars", "m", "root"])
def test_the_compiled_columns_refuse_inconsistent_sizes(setup, bad):  # noqa: F811
    """The compiled columns' arrays of the wrong sizes are a ValueError (the same call with
    every size right fills the columns)."""
    needs_build()
    assert rows._compiled is not None
    model = setup[0]
    pts, kinds, pars = model._spec
    x0 = model.tangent(mesh.motion(model.mesh, setup[2], setup[3], model.length))
    m, n = 4 * len(kinds), len(x0)
    good = dict(cols=np.empty((n, 4 * m)), pars=pars, m=m, root=np.zeros(0))
    assert rows._compiled.columns(pts, x0, kinds, pars, good["root"], good["cols"], m, 0) > 0
    wrong = {**good, bad: {"cols": np.empty((n, 4 * m - 1)), "pars": pars[:-1], "m": m + 4,
                           "root": np.zeros(n)}[bad]}
    with pytest.raises(ValueError, match="inconsistent"):
        rows._compiled.columns(pts, x0, kinds, wrong["pars"], wrong["root"], wrong["cols"],
                              wrong["m"], 0)
