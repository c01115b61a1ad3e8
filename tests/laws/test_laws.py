import math

import numpy as np
import pytest

from dextar.errors import ConvergenceError, ParameterError
from dextar.laws import (
    MinimumJerkLaw,
    TrapezoidalLaw,
    UniformLaw,
    law_cost,
    line_solution,
    solve_optimal_law,
)
from dextar.paths import Arc, ExpressionPath, Line, Spline

SEMI = Arc(120 / 87, 0.0, np.pi)  # the paper's semicircle in units of L = 87 mm


def paper_law(eta=0.1):
    return solve_optimal_law(SEMI, duration=1.0, eta=eta, mass=1.0)


@pytest.mark.parametrize("eta", [pytest.param(1e-5, marks=pytest.mark.slow), 1e-3, 0.1, 10.0,
                                 1e3, 1e5])
def test_semicircle_satisfies_paper_ode_15(eta):
    law = paper_law(eta)
    R = SEMI.radius
    t = np.linspace(0, 1, 2001)
    s, ds, dds, _ = law.evaluate(t)
    p, dp, ddp = s / R, ds / R, dds / R
    p4 = law.fourth_derivative(t) / R
    gamma2 = 1.0 / eta
    rhs = (6 * dp**2 + gamma2) * ddp
    assert np.abs(p4 - rhs).max() / (1 + np.abs(p4).max()) < 1e-8
    # boundary conditions (16)
    assert abs(p[0]) < 1e-8 and abs(p[-1] - np.pi) < 1e-8
    assert abs(dp[0]) < 1e-8 and abs(dp[-1]) < 1e-8


def test_rest_to_rest_symmetry():
    law = paper_law()
    t = np.linspace(0, 1, 501)
    s = law.evaluate(t)[0] / SEMI.radius
    np.testing.assert_allclose(s + s[::-1], np.pi, atol=1e-10)


def test_optimal_cost_below_other_laws():
    eta = 0.1
    law = paper_law(eta)
    S = SEMI.length
    others = [MinimumJerkLaw(S, 1.0), TrapezoidalLaw(S, vmax=2 * S, amax=6 * S, duration=1.0)]
    # and perturbations of the optimum that keep rest at both ends
    t = np.linspace(0, 1, 4001)
    assert law.cost == pytest.approx(law.kinetic + law.inertial)
    for other in others:
        assert sum(law_cost(other, SEMI, 1.0, eta)) > law.cost
    # a perturbation u(t) = t^2 (1 - t)^2 sin(k pi t) added to s raises the cost
    base = law.evaluate(t)
    for eps in (1e-2, -1e-2):
        dbump = eps * (2 * t * (1 - t) ** 2 - 2 * t**2 * (1 - t))
        ddbump = eps * (2 * (1 - t) ** 2 - 8 * t * (1 - t) + 2 * t**2)
        ds, dds = base[1] + dbump, base[2] + ddbump
        k = 1 / SEMI.radius
        J = 0.5 * np.trapezoid(ds**2, t) + 0.5 * eta * np.trapezoid(dds**2 + k**2 * ds**4, t)
        assert J > law.cost


def test_cost_parts_match_paper_definitions():
    law = paper_law()
    t = np.linspace(0, 1, 200001)
    _, ds, dds, _ = law.evaluate(t)
    kin = 0.5 * np.trapezoid(ds**2, t)
    inert = 0.5 * 0.1 * np.trapezoid(dds**2 + ds**4 / SEMI.radius**2, t)
    assert law.kinetic == pytest.approx(kin, rel=1e-8)
    assert law.inertial == pytest.approx(inert, rel=1e-8)


@pytest.mark.parametrize("eta", [1e-4, 0.1, 100.0])
def test_line_matches_closed_form(eta):
    line = Line((0.2, 1.0), (0.8, 1.4))
    T, m = 2.0, 1.5
    law = solve_optimal_law(line, duration=T, eta=eta, mass=m)
    G = T / np.sqrt(eta * m)
    t = np.linspace(0, T, 401)
    S = line.length
    exact = line_solution(G, t / T) * np.array([S, S / T, S / T**2, S / T**3])[:, None]
    got = law.evaluate(t)
    for k in range(3):
        assert np.abs(got[k] - exact[k]).max() <= 1e-8 * (1 + np.abs(exact[k]).max())


def test_line_closed_form_is_the_hyperbolic_formula():
    # independent check of line_solution: sigma'''' = G^2 sigma'' and the end conditions
    G = 4.0
    tau = np.linspace(0, 1, 11)
    y = line_solution(G, tau)
    a = 1 / (2 * np.sinh(G / 2) - G * np.cosh(G / 2))
    direct = 0.5 - a * G * np.cosh(G / 2) * (tau - 0.5) + a * np.sinh(G * (tau - 0.5))
    np.testing.assert_allclose(y[0], direct, atol=1e-14)
    assert y[0][0] == pytest.approx(0, abs=1e-14) and y[0][-1] == pytest.approx(1, abs=1e-14)
    assert abs(y[1][0]) < 1e-13 and abs(y[1][-1]) < 1e-13


@pytest.mark.slow
@pytest.mark.parametrize("path", [
    Spline(((0.0, 1.0), (0.3, 1.2), (0.6, 1.0), (1.0, 1.3))),
    ExpressionPath("0.3*cos(p)", "1.2 + 0.2*sin(2*p)", 0.0, 3.0),
])
def test_general_paths_euler_lagrange(path):
    eta = 0.01
    law = solve_optimal_law(path, eta=eta)
    t = np.linspace(0.01, 0.99, 301)
    s, ds, dds, _ = law.evaluate(t)
    kappa, dkappa = path.curvature(path.parameter_at(s))
    rhs = (1 / eta + 6 * kappa**2 * ds**2) * dds + 3 * kappa * dkappa * ds**4
    s4 = law.fourth_derivative(t)
    assert np.abs(s4 - rhs).max() / (1 + np.abs(rhs).max()) < 1e-4
    assert law.cost < sum(law_cost(MinimumJerkLaw(path.length, 1.0), path, 1.0, eta))


def test_simple_laws():
    S, T = 2.0, 1.5
    t = np.linspace(0, T, 1001)
    for law in (UniformLaw(S, T), MinimumJerkLaw(S, T), TrapezoidalLaw(S, 2.0, 4.0, T)):
        s, ds, dds, ddds = law.evaluate(t)
        assert s[0] == pytest.approx(0, abs=1e-12) and s[-1] == pytest.approx(S, rel=1e-12)
        np.testing.assert_allclose(np.gradient(s, t)[1:-1], ds[1:-1], atol=2e-3 * S / T)
    mj = MinimumJerkLaw(S, T).evaluate(t)
    assert mj[1][0] == mj[1][-1] == 0 and abs(mj[2][0]) < 1e-12
    tz = TrapezoidalLaw(S, vmax=1.0, amax=2.0)
    assert tz.duration == pytest.approx(S / 1.0 + 1.0 / 2.0)
    assert np.abs(tz.evaluate(np.linspace(0, tz.duration, 999))[1]).max() <= 1.0 + 1e-12


@pytest.mark.parametrize("S, a, T", [(1.39, 1.15e19, 1.0), (0.123, 1.0, 1e9), (2.0, 4.0, 1.5),
                                     (1.0, 1.0, 2.0)])
def test_a_trapezoid_of_a_long_duration_moves_at_its_cruise_speed(S, a, T):
    """Found by the long-motion fuzz shape (review 28): a 1e9 s trapezoid over 123 mm had a
    cruise speed of exactly 0 (the cancellation of (a T - sqrt(a^2 T^2 - 4 a S)) / 2): the
    law never moved, and the run's summary divided by its zero energy. The cruise speed is
    the root of v^2 - a T v + a S = 0 (the distance covered in T), to rounding; the law
    arrives."""
    law = TrapezoidalLaw(S, math.inf, a, T)
    v = law.cruise
    assert v > 0 and v * v - a * T * v + a * S == pytest.approx(0.0, abs=1e-12 * a * S)
    assert v * (T - v / a) == pytest.approx(S, rel=1e-12)  # cruise + the two ramps
    s = law.evaluate(np.array([0.0, 0.5 * T, T]))[0]
    assert s[0] == 0.0 and s[1] == pytest.approx(0.5 * S, rel=1e-9) and s[2] == pytest.approx(S)


def test_law_errors():
    with pytest.raises(ParameterError, match="cannot be covered"):
        TrapezoidalLaw(10.0, vmax=100.0, amax=1.0, duration=1.0)
    with pytest.raises(ParameterError, match="eta"):
        solve_optimal_law(SEMI, eta=-1.0)
    with pytest.raises(ParameterError, match="too small"):
        solve_optimal_law(SEMI, eta=1e-12)
    with pytest.raises(ParameterError, match="outside"):
        UniformLaw(1.0, 1.0).evaluate([2.0])


def test_convergence_failure_is_an_error():
    # stiff boundary layers (eta = 1e-5) cannot be resolved with at most 32 nodes: the solver
    # must say so rather than return an under-resolved law
    with pytest.raises(ConvergenceError, match="did not converge for eta = 1e-05"):
        solve_optimal_law(SEMI, eta=1e-5, max_nodes=32)


def test_hard_path_converges_and_satisfies_the_euler_lagrange_equation():
    """Curvature ~ 1/p near the start (a cusp-like path): the solver converges, says so, and
    its law satisfies the Euler-Lagrange equation checked independently of the solver."""
    hard = ExpressionPath("p**3", "p**2", 0.001, 1.0)
    eta = 1e-4
    law = solve_optimal_law(hard, eta=eta)
    assert law.success and "converged" in law.message and law.residual <= 1e-8
    t = np.linspace(0.02, 0.98, 201)
    s, ds, dds, _ = law.evaluate(t)
    kappa, dkappa = hard.curvature(hard.parameter_at(s))
    rhs = (1 / eta + 6 * kappa**2 * ds**2) * dds + 3 * kappa * dkappa * ds**4
    s4 = law.fourth_derivative(t)
    assert np.abs(s4 - rhs).max() / (1 + np.abs(rhs).max()) < 1e-4
    y = law.evaluate(np.array([0.0, 1.0]))
    assert abs(y[0, 0]) < 1e-9 and y[0, 1] == pytest.approx(hard.length, rel=1e-9)
    assert abs(y[1, 0]) < 1e-6 * hard.length and abs(y[1, 1]) < 1e-6 * hard.length


SPLINE = Spline(((0.0, 1.0), (0.3, 1.2), (0.6, 1.0), (1.0, 1.3)))


def euler_lagrange_residual(path, law, n=1001):
    """s'''' against the Euler-Lagrange equation with the path's own curvature at s(t)."""
    t = np.linspace(0.0, law.duration, n)
    s, ds, dds, _ = law.evaluate(t)
    kappa, dkappa = path.curvature(path.parameter_at(s))
    rhs = (1 / (law.eta * law.mass) + 6 * kappa**2 * ds**2) * dds + 3 * kappa * dkappa * ds**4
    s4 = law.fourth_derivative(t)
    return np.abs(s4 - rhs).max() / (1 + np.abs(s4).max())


@pytest.mark.slow
def test_spline_law_by_pieces_is_spectrally_accurate():
    """A spline's law comes from one Chebyshev element per spline piece: the Euler-Lagrange
    residual on 1001 times reaches 5e-12 (bound 1e-9), the law agrees with solve_bvp's at tol
    1e-8 to 2e-11 of its range (bound 1e-7; solve_bvp's own error is ~1e-8 residual), and a
    law read for an eta 1e-4 larger fails the same check (residual 1e-4)."""
    from dextar.laws.optimal import OptimalLaw, _solve_local

    eta = 0.01
    law = solve_optimal_law(SPLINE, eta=eta)
    assert "smooth pieces, 3 of them" in law.message and law.residual <= 1e-10
    assert euler_lagrange_residual(SPLINE, law) < 1e-9
    S = SPLINE.length
    bvp = _solve_local(SPLINE, S, 1 / np.sqrt(eta), 1e-8)
    ref = OptimalLaw(distance=S, duration=1.0, eta=eta, mass=1.0, sigma=bvp.sigma)
    t = np.linspace(0, 1, 501)
    a, b = law.evaluate(t)[:3], ref.evaluate(t)[:3]
    for k in range(3):
        assert np.abs(a[k] - b[k]).max() <= 1e-7 * np.ptp(b[k])
    # the stored cost parts are those of the quadrature on fine panels
    kin, inert = law_cost(law, SPLINE, 1.0, eta, nodes=4000)
    assert law.kinetic == pytest.approx(kin, rel=1e-10)
    assert law.inertial == pytest.approx(inert, rel=1e-10)
    # the check can fail: the same law read as the solution for an eta 1e-4 larger
    off = OptimalLaw(distance=S, duration=1.0, eta=eta * (1 + 1e-4), mass=1.0, sigma=law.sigma)
    assert euler_lagrange_residual(SPLINE, off) > 1e-5


def test_curvature_jump_is_left_to_mesh_refinement():
    """A curvature that jumps between pieces (a line into an arc) puts a jump in s''': the
    spectral elements, which join with s C3, must not take such a path."""
    from dextar.laws.optimal import _breaks, _curvature_pieces
    from dextar.paths.composite import Composite

    jump = Composite((Line((0.0, 0.0), (1.0, 0.0)), Arc(0.5, -np.pi / 2, 0.0, center=(1.0, 0.5))))
    S = jump.length
    breaks = _breaks(jump, S)
    assert breaks.size == 3  # the joint is seen
    assert _curvature_pieces(jump, S, breaks) is None
    assert _curvature_pieces(SPLINE, SPLINE.length, _breaks(SPLINE, SPLINE.length)) is not None


@pytest.mark.slow
@pytest.mark.parametrize("path", [
    SPLINE,  # Chebyshev elements on the spline's pieces
    ExpressionPath("p", "0.1*sqrt(p**2 + 1e-4)**3", -1.0, 1.0),  # solve_bvp (not smooth enough)
])
def test_result_does_not_depend_on_the_clock(monkeypatch, path):
    """The solvers are bounded by iterations, not seconds: with a clock that jumps 1000 s at
    every reading (a machine a million times slower) the law is the same."""
    import time

    law = solve_optimal_law(path, eta=0.01)
    now = [time.perf_counter()]

    def slow() -> float:
        now[0] += 1000.0
        return now[0]

    for name in ("perf_counter", "monotonic", "time", "process_time"):
        monkeypatch.setattr(time, name, slow)
    again = solve_optimal_law(path, eta=0.01)
    assert again.success and again.message == law.message and again.nodes == law.nodes
    t = np.linspace(0, 1, 201)
    np.testing.assert_allclose(again.evaluate(t), law.evaluate(t), rtol=0, atol=1e-12)
    assert again.cost == pytest.approx(law.cost, rel=1e-12)
