"""The jerk-limited law's compiled rows and knot monitor (``laws/smooth/_rows.c``) against the
numpy code they replace where they were built: the same rows in the same order (values,
intervals, normalisations, gradients and their sizes) on the blended chain, with a jerk
limit and with a torque-rate limit, friction and a speed cap; the same knots; bad sizes an
error, not a crash."""

from dataclasses import replace

import numpy as np
import pytest

from dextar.laws.constraints import motor_constraints
from dextar.laws.smooth import mesh, rows, solve, start
from dextar.motors import MotorLimits

from ..compiled import skip_without_a_compiler

# (the chain's fixtures, shared)
from .test_smooth_parts import chain, setup  # noqa: F401

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
    the last bit on another machine; on this one they are the same bits)."""
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
    intervals at a time (blocks that start past the first knot)."""
    needs_build()
    model, _, J, Tk, _ = setup
    for mo in motions(model, J, Tk):
        for gradients in (True, False):
            a, b = both(monkeypatch, model, mo, gradients)
            assert len(a.F) > 10 * model.mesh.M and (len(a.C) > 0) == gradients
            assert_same(a, b)
    monkeypatch.setattr(rows, "CHUNK", 7)
    a, b = both(monkeypatch, model, motions(model, J, Tk)[1])
    assert len(a.kinds) > 4 * 3  # several blocks
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


def test_the_compiled_rows_refuse_inconsistent_sizes(setup):  # noqa: F811
    """Arrays of the wrong sizes are a ValueError (never a read past an array's end)."""
    needs_build()
    assert rows._compiled is not None
    model, _, J, Tk, tab = setup
    mo = mesh.motion(model.mesh, J, Tk, model.length)
    z = np.zeros(4)
    out = np.zeros(10), np.zeros(10), np.zeros((10, 5))
    k, sizes = np.zeros(10, np.int32), np.zeros((10, 5), np.float32)
    with pytest.raises(ValueError, match="inconsistent"):
        rows._compiled.block(tab.s, np.zeros((len(tab.s), 5)), tab.lo, tab.hi,
                             model.mesh.h, mo.J, mo.Tk, mo.sigma, mo.w, mo.alpha, z[:1], z[:2],
                             z[:4], *out, k, sizes, 1, 1, 0, model.mesh.M, 1e-300, 1.0, -1.0,
                             True)
    with pytest.raises(TypeError, match="int32"):
        rows._compiled.block(tab.s, np.zeros((len(tab.s), 5)), tab.lo, tab.hi,
                             model.mesh.h, mo.J, mo.Tk, mo.sigma, mo.w, mo.alpha, z[:1], z[:2],
                             np.zeros(5), *out, np.zeros(10), sizes, 1, 1, 0, 1, 1e-300, 1.0,
                             -1.0, True)
    with pytest.raises(ValueError, match="inconsistent"):
        rows._compiled.monitor(tab.s, tab.lo, tab.hi, z, z, z[:3], z[:1], z[:2], 0.1, z)
