import numpy as np
import pytest

from dextar.errors import ParameterError
from dextar.paths import Arc, Expression, ExpressionPath, Line, Spline


def fd(f, p, h=1e-5):
    return (f(p + h) - f(p - h)) / (2 * h)


PATHS = [
    Arc(1.38, 0.0, np.pi),
    Arc(0.5, -1.0, 2.0, center=(0.1, 1.2)),
    Line((0.0, 1.0), (0.6, 1.4)),
    Spline(((0.0, 1.0), (0.3, 1.2), (0.6, 1.0), (1.0, 1.3), (1.2, 1.1))),
    ExpressionPath("0.3*cos(p) + 0.05*p**2", "1.2 + 0.2*sin(2*p)", 0.0, 3.0),
]


@pytest.mark.parametrize("path", PATHS, ids=lambda p: type(p).__name__)
def test_derivatives_against_finite_differences(path):
    p = np.linspace(path.p0 + 0.01 * (path.p1 - path.p0), path.p1 - 0.01 * (path.p1 - path.p0), 37)
    r, r1, r2, r3 = path.derivatives(p)
    for lower, upper in ((0, r1), (1, r2), (2, r3)):
        np.testing.assert_allclose(fd(lambda x, k=lower: path.derivatives(x)[k], p), upper,
                                   atol=1e-6 * (1 + np.abs(upper).max()))
    # curvature derivative along the arc
    kappa, dkappa = path.curvature(p)
    dk_fd = fd(lambda x: path.curvature(x)[0], p) / path.speed(p)
    np.testing.assert_allclose(dkappa, dk_fd, atol=1e-5 * (1 + np.abs(dkappa).max()))


@pytest.mark.parametrize("path", PATHS, ids=lambda p: type(p).__name__)
def test_arc_length_and_inverse(path):
    p = np.linspace(path.p0, path.p1, 101)
    s = path.arc_length(p)
    # against a brute-force polyline length
    dense = path.position(np.linspace(path.p0, path.p1, 200001))
    poly = np.sum(np.linalg.norm(np.diff(dense, axis=0), axis=1))
    assert path.length == pytest.approx(poly, rel=1e-8)
    assert s[0] == pytest.approx(0.0, abs=1e-14) and s[-1] == pytest.approx(path.length, rel=1e-12)
    np.testing.assert_allclose(path.parameter_at(s), p, atol=1e-10 * (path.p1 - path.p0))


def test_closed_forms():
    a = Arc(2.0, 0.0, np.pi)
    assert a.length == pytest.approx(2 * np.pi)
    np.testing.assert_allclose(a.curvature(np.array([0.3, 2.0]))[0], 0.5)
    e = ExpressionPath("2*cos(p)", "2*sin(p)", 0.0, np.pi)
    assert e.length == pytest.approx(2 * np.pi, rel=1e-12)
    np.testing.assert_allclose(e.curvature(np.linspace(0, 3, 7))[0], 0.5, rtol=1e-12)


def test_spline_through_waypoints():
    w = ((0.0, 1.0), (0.3, 1.2), (0.6, 1.0))
    s = Spline(w)
    knots = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(np.array(w), axis=0), axis=1))])
    np.testing.assert_allclose(s.position(knots), w, atol=1e-12)


@pytest.mark.parametrize("text, word", [
    ("__import__('os').system('x')", "not allowed"),
    ("p.real", "Attribute"),
    ("open('f')", "not allowed"),
    ("q + 1", "unknown name 'q'"),
    ("1 +", "not valid"),
    ("(lambda: 1)()", "not allowed"),
    ("p if p else 1", "not allowed"),
])
def test_expression_refuses_unsafe(text, word):
    with pytest.raises(ParameterError, match=word.replace("(", r"\(")):
        Expression.parse(text)


def test_expression_not_finite_names_point():
    e = ExpressionPath("log(p)", "p", 0.0, 1.0)
    with pytest.raises(ParameterError, match="not finite at p = 0"):
        e.derivatives(np.array([0.0, 0.5]))


def test_expression_symbolic_derivatives_exact():
    e = Expression.parse("exp(2*p)*sin(p)**2 + p**3/(1+p**2) + atan(p) + sqrt(1+p)")
    x = np.array([0.3, 1.1])
    v = e(x)
    # third derivative against a dense finite difference of the second
    np.testing.assert_allclose(v[3], fd(lambda z: e(z)[2], x, 1e-6), rtol=1e-7)


def test_invalid_paths():
    with pytest.raises(ParameterError):
        Arc(-1.0)
    with pytest.raises(ParameterError):
        Line((0, 0), (0, 0))
    with pytest.raises(ParameterError, match="coincide"):
        Spline(((0, 0), (0, 0), (1, 1)))
    with pytest.raises(ParameterError, match="outside"):
        Arc(1.0).derivatives(np.array([4.0]))


def test_nearly_coincident_spline_waypoints_refused():
    """A waypoint 1e-12 from the next makes a kink of unbounded curvature (the fuzz found an
    optimal law taking minutes on it): refused by name."""
    with pytest.raises(ParameterError, match="waypoints 1 and 2 coincide"):
        Spline(((0.0, 1.0), (0.5, 1.2), (0.5 + 1e-12, 1.2), (1.0, 1.0)))


def test_pieces_that_do_not_meet_are_refused():
    """A composite path (or a chain to blend) whose piece starts away from where the previous
    ends was accepted, the gap crossed in no time (a new user's trial: a 10 mm jump, a law
    "within the limits"): refused, naming the pieces, the points and the gap. Pieces that
    meet to rounding (an arc's end computed from its angle) are accepted."""
    from dextar.paths import Composite, blended

    a, b = Line((-0.04, 0.20), (0.0, 0.24)), Line((0.01, 0.24), (0.04, 0.20))
    with pytest.raises(ParameterError, match=r"pieces 0 and 1 do not meet: piece 0 ends at "
                       r"\(0, 0\.24\), piece 1 starts at \(0\.01, 0\.24\), 0\.01 apart"):
        Composite((a, b))
    with pytest.raises(ParameterError, match="pieces 0 and 1 do not meet"):
        blended((a, b), (0.005,))
    # 1.8e-5 of the longer piece's length apart: refused too (the tolerance is 2e-6 of it);
    # 1.8e-7 of it: they meet
    with pytest.raises(ParameterError, match=r"do not meet: .* 1e-06 apart \(1\.77e-05 of"):
        Composite((a, Line((1e-6, 0.24), (0.04, 0.20))))
    assert Composite((a, Line((1e-8, 0.24), (0.04, 0.20)))).length > 0.1
    # an arc about a centre ends on its circle, its target 1.6e-7 off it: the next piece,
    # starting at the target, meets it (a program's blended chain with it had been refused)
    from dextar.paths.circles import arc_about

    to = (0.0212132, 0.1412132)
    arc = arc_about(np.array([0.03, 0.12]), np.array([0.0, 0.12]), np.array(to))
    assert Composite((arc, Line(to, (0.0, 0.15)))).length > arc.length
    arc = Arc(0.05, 0.0, np.pi / 3, center=(0.0, 0.2))
    end = tuple(float(v) for v in arc.position(np.array([arc.p1]))[0])
    assert np.hypot(end[0] - 0.025, end[1] - (0.2 + 0.05 * np.sin(np.pi / 3))) < 1e-15
    path = Composite((arc, Line((0.025, 0.2 + 0.05 * np.sin(np.pi / 3)), (0.0, 0.3))))
    assert path.length == pytest.approx(arc.length + np.hypot(0.025, 0.3 - end[1]))
    chain, owner = blended((Line((-0.04, 0.20), (0.0, 0.24)), Line((0.0, 0.24), (0.04, 0.20))),
                           (0.005,))
    assert list(owner) == [0, 0, 1]


def test_a_line_too_short_to_plan_is_refused_by_its_length():
    """NumPy's allclose refused a line under about 1e-5 of its coordinates with "start and
    end must differ" (a new user's trial: they do); the same lines are refused with their
    length and why (a law along a shorter one took tens of seconds), a longer one is a
    line."""
    assert Line((0.0, 0.22), (0.0, 0.22001)).length == pytest.approx(1e-5, rel=1e-9)
    with pytest.raises(ParameterError, match=r"the line is 1e-06 long, under 1e-05 of the "
                       r"size of its coordinates \(0\.22\): too short to plan a motion"):
        Line((0.0, 0.22), (0.0, 0.220001))
    with pytest.raises(ParameterError, match="line start and end must differ"):
        Line((0.0, 0.22), (0.0, 0.22))
