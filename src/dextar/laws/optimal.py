"""The paper's optimal law of motion along any smooth path (SPEC section 3).

It minimises ``Phi = (m/2) Int |rdot|^2 dt + (eta m^2/2) Int |rddot|^2 dt`` with rest at both
ends. With arc length ``s`` and curvature ``kappa(s)``, ``|rddot|^2 = sddot^2 + kappa^2 sdot^4``
and the Euler-Lagrange equation is

    s'''' = (gamma^2 + 6 kappa^2 sdot^2) sddot + 3 kappa kappa' sdot^4,  gamma^2 = 1/(eta m),

with ``s(0) = 0, sdot(0) = 0, s(T) = S, sdot(T) = 0``; on a circle it is the paper's (15).

It is solved in dimensionless form, ``s = S sigma(tau)``, ``t = T tau``:

    sigma'''' = (G^2 + 6 K^2 sigma'^2) sigma'' + 3 K K_sigma sigma'^4,

``G^2 = T^2 / (eta m)``, ``K = kappa S``, ``K_sigma = kappa' S^2``.

Method: Chebyshev spectral collocation in integral form. The unknowns are the values of
``u = sigma''''`` at ``N + 1`` Chebyshev points and two constants; ``sigma`` and its first
three derivatives are exact repeated integrals of the Chebyshev interpolant of ``u`` (so the
rest conditions at ``tau = 0`` hold exactly and the matrices stay well conditioned, unlike
differentiation matrices). Newton's method with an exact Jacobian solves the collocation
equations from the closed-form solution of the straight line; ``N`` doubles until the
Chebyshev coefficients have decayed and the residual between the nodes is below tolerance.
When Newton fails, the solver continues in ``G`` from an easy problem, reusing each solution
as the next guess.

Varying curvature: one such element per piece on which the curvature is smooth (a spline
between its knots, a G2 chain between its joints, an analytic curve in one piece), ``sigma``
C3 across the elements' edges, which follow the times at which the law crosses the pieces'
ends; ``K`` and its derivatives come from a Chebyshev fit of each piece in arc length. Newton
is damped there and, when it fails from the line's law, continues in the curvature's scale.
A path whose curvature is not smooth on known pieces (or jumps across one) goes to scipy's
``solve_bvp`` with mesh refinement and continuation in the curvature.

Every loop is bounded by a count (Newton iterations, continuation solves, nodes), never by
the clock, so a result does not depend on the machine's speed. Failure raises
:class:`ConvergenceError`: never a silent wrong answer.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import lru_cache, partial
from typing import Any, NamedTuple

import numpy as np
from numpy.polynomial import chebyshev as cheb

from .._arrays import Array
from .._compiled import usable
from .._lazy import lazy_module
from ..errors import ConvergenceError, ParameterError
from ..params import Param
from ..paths import Path
from ..units import Units
from .base import Law, _positive, law_cost
from .registry import LawType, register_law
from .time_optimal import REACH_VERSION  # (_reach.c's interface: one number for its callers)

try:  # Clenshaw's recurrence compiled (chebval of _reach.c), built where a C compiler is
    from . import _reach as _compiled
except ImportError:  # pragma: no cover - installed without a C compiler: numpy's chebval
    _compiled = None  # type: ignore[assignment]  # the module or None, as USE_COMPILED says

if not usable(_compiled, REACH_VERSION):
    _compiled = None  # type: ignore[assignment]  # an old build: numpy's chebval instead

#: Whether a series at many points is evaluated compiled (where it was built): False gives
#: numpy's chebval (the same values to the last bit; the tests compare the two).
USE_COMPILED = _compiled is not None

integrate = lazy_module("scipy.integrate")
interpolate = lazy_module("scipy.interpolate")


def line_solution(G: float, tau: Array) -> Array:
    """Closed-form optimal law on a straight line, ``sigma'''' = G^2 sigma''``, rest to rest.

    ``sigma = 1/2 + b (tau - 1/2) + e sinh(G (tau - 1/2))`` with
    ``e = 1 / (2 sinh(G/2) - G cosh(G/2))`` and ``b = -e G cosh(G/2)``, written so that it
    neither overflows for large ``G`` nor cancels for small ``G`` (then the minimum-acceleration
    cubic ``3 tau^2 - 2 tau^3`` plus its first correction).

    Returns the rows ``sigma, sigma', sigma'', sigma'''``, shape (4, n).
    """
    x = np.asarray(tau, dtype=float) - 0.5
    if G < 1e-2:
        # series in G^2: sigma = cubic + G^2 * quintic correction (to O(G^4))
        u = x + 0.5
        c0 = np.stack([3 * u**2 - 2 * u**3, 6 * u - 6 * u**2, 6 - 12 * u, -12 + 0 * u])
        # correction solves w'''' = G^2 * cubic'' with w, w' = 0 at both ends
        c1 = np.stack([
            (u**2 * (1 - u) ** 2 * (1 - 2 * u)) / 20,
            (u * (1 - u) * (1 - 5 * u + 5 * u**2)) / 10,
            (1 - 12 * u + 30 * u**2 - 20 * u**3) / 10,
            (-12 + 60 * u - 60 * u**2) / 10,
        ])
        return c0 + G * G * c1
    # e sinh(G x) = [exp(G(x - 1/2)) - exp(-G(x + 1/2))] / (1 + exp(-G)) / (2 tanh(G/2) - G)
    den = 2.0 * math.tanh(0.5 * G) - G
    ep = np.exp(G * (x - 0.5))
    em = np.exp(-G * (x + 0.5))
    scale = 1.0 / ((1.0 + math.exp(-G)) * den)
    sh, ch = (ep - em) * scale, (ep + em) * scale  # e sinh(Gx), e cosh(Gx)
    b = -G / den  # = -e G cosh(G/2)
    return np.stack([0.5 + b * x + sh, b + G * ch, G * G * sh, G**3 * ch])


#: ``sigma(tau, k)``: the k-th derivative of the normalised law at normalised times.
SigmaFn = Callable[[Array, int], Array]

#: ``K, K_sigma, K_sigma_sigma`` of the dimensionless curvature at ``sigma`` on one element.
CurvatureFn = Callable[[Array], tuple[Array, Array, Array]]

#: Bounds of the solvers, in iterations rather than seconds so that a result never depends on
#: the machine's speed: Newton iterations per solve, solves of a continuation (in ``G`` on
#: constant curvature, in the curvature's scale on other paths) and re-placements of the
#: elements' edges on the curvature's breaks.
MAX_NEWTON = 40
MAX_CONTINUATION_SOLVES = 60
MAX_EDGE_UPDATES = 8

# Chebyshev coefficients (in x = 2 xi - 1) of xi^m, m = 0..3: the Taylor part of an element
_XI = tuple(cheb.poly2cheb(np.polynomial.polynomial.polypow([0.5, 0.5], m)) for m in range(4))


@dataclass(frozen=True)
class _Ops:
    """Chebyshev collocation operators for ``N + 1`` Lobatto points on ``xi`` in [0, 1]."""

    x: Array  # nodes in [-1, 1], x_0 = 1 (xi = 1, the element's right end)
    tau: Array  # the nodes in [0, 1]
    to_coef: Array  # values -> Chebyshev coefficients
    Q: tuple[Array, ...]  # k-fold integration from xi = 0 in coefficient space, k = 1..4
    M: tuple[Array, ...]  # the same from node values to node values
    between: Array  # Chebyshev polynomials 0..N+4 at 4 N points between the nodes
    gauss: tuple[Array, Array]  # the same at 2 N + 8 Gauss-Legendre points, and the weights


@lru_cache(maxsize=16)
def _lobatto(N: int) -> tuple[Array, Array]:
    """The ``N + 1`` Chebyshev-Lobatto points in [-1, 1] (``x_0 = 1``) and the matrix from
    values there to Chebyshev coefficients."""
    j = np.arange(N + 1)
    x = np.cos(np.pi * j / N)
    gamma = np.ones(N + 1)
    gamma[[0, N]] = 2.0
    return x, (2.0 / N) * np.cos(np.pi * np.outer(j, j) / N) / np.outer(gamma, gamma)


@lru_cache(maxsize=16)
def _ops(N: int) -> _Ops:
    x, to_coef = _lobatto(N)
    eye = np.eye(N + 1)
    Q = tuple(cheb.chebint(eye, m=k, lbnd=-1, scl=0.5, axis=0) for k in range(1, 5))
    M = tuple(cheb.chebvander(x, N + k) @ Q[k - 1] @ to_coef for k in range(1, 5))
    m = 4 * N
    between = cheb.chebvander(np.cos(np.pi * (np.arange(m) + 0.5) / m), N + 4)
    xg, wg = np.polynomial.legendre.leggauss(2 * N + 8)
    return _Ops(x, 0.5 * (x + 1.0), to_coef, Q, M, between, (cheb.chebvander(xg, N + 4), wg))


class _Mesh:
    """Elements ``[edges[e], edges[e + 1]]`` of ``[0, 1]``, each with ``N + 1`` Lobatto nodes.

    The unknowns ``z`` are ``u = sigma''''`` at every node and the two constants ``c2, c3``
    of ``sigma = c2 tau^2 + c3 tau^3 + (4-fold integral of u)`` on the first element; each next
    element starts from the values of ``sigma`` to ``sigma'''`` where the previous one ends (so
    ``sigma`` is C3 and the rest at ``tau = 0`` holds exactly). ``E[j] @ z`` is ``sigma^(j)``
    at the nodes (j = 0..3), ``ends[j] @ z`` at ``tau = 1`` and ``lefts[e][j] @ z`` at the
    start of element ``e``."""

    def __init__(self, edges: Array, N: int) -> None:
        ops = _ops(N)
        self.ops, self.N, self.edges = ops, N, np.asarray(edges, dtype=float)
        self.h = np.diff(self.edges)
        n = N + 1
        self.nu = len(self.h) * n
        nz = self.nu + 2
        E = np.zeros((4, self.nu, nz))
        C = np.zeros((4, nz))
        C[2, nz - 2], C[3, nz - 1] = 2.0, 6.0
        self.lefts: list[Array] = []
        for e, h in enumerate(self.h):
            rows = slice(e * n, (e + 1) * n)
            d = h * ops.tau
            self.lefts.append(C)
            for j in range(4):
                taylor = np.zeros((n, 4))
                for k in range(j, 4):
                    taylor[:, k] = d ** (k - j) / math.factorial(k - j)
                E[j, rows] = taylor @ C
                E[j, rows, rows] += h ** (4 - j) * ops.M[3 - j]
            C = E[:, e * n, :].copy()  # node 0 is the element's right end
        self.E, self.ends = E, C

    def nodes(self) -> Array:
        """The nodes in [0, 1], element after element, shape (nu,)."""
        return np.concatenate([a + h * self.ops.tau for a, h in zip(self.edges, self.h,
                                                                     strict=False)])

    def coefficients(self, z: Array) -> list[tuple[Array, ...]]:
        """Per element, the Chebyshev coefficients (in the element's x) of ``sigma^(k)``,
        k = 0..4."""
        ops, n = self.ops, self.N + 1
        out = []
        for e, h in enumerate(self.h):
            a = ops.to_coef @ z[e * n:(e + 1) * n]
            c = self.lefts[e] @ z
            coefs = []
            for j in range(4):
                series = h ** (4 - j) * (ops.Q[3 - j] @ a)
                for m in range(4 - j):
                    series[:m + 1] += c[j + m] * h**m / math.factorial(m) * _XI[m]
                coefs.append(series)
            coefs.append(a)
            out.append(tuple(coefs))
        return out


def _chebyshev_matrix(x: Array, degree: int) -> Array:
    """``T_k(x)``, k = 0..degree, shape (x.size, degree + 1): ``Re z^k`` with
    ``z = x + i sqrt(1 - x^2)`` by one cumulative product (Clenshaw's and chebvander's loops
    over k cost ~1 us a degree, and ``cos(k arccos x)`` twice as much), and
    ``sign(x)^k cosh(k arccosh |x|)`` outside [-1, 1] (a Newton iterate a little beyond its
    piece)."""
    x = np.asarray(x, dtype=float).reshape(-1)
    k = np.arange(degree + 1)
    inside = np.clip(x, -1.0, 1.0)
    powers = np.empty((x.size, degree + 1), dtype=complex)
    powers[:, 0] = 1.0
    powers[:, 1:] = (inside + 1j * np.sqrt(1.0 - inside * inside))[:, None]
    np.cumprod(powers, axis=1, out=powers)
    T: Array = np.ascontiguousarray(powers.real)
    out = np.abs(x) > 1.0
    if out.any():  # T_k(x) = sign(x)^k cosh(k arccosh |x|)
        xo = x[out]
        T[out] = np.where(xo[:, None] < 0, (-1.0) ** k, 1.0) * np.cosh(
            np.arccosh(np.abs(xo))[:, None] * k)
    return T


#: :func:`_chebval`'s matrix of the terms up to this many values (points times terms),
#: Clenshaw's recurrence beyond.
MATRIX_LIMIT = 40_000


def _chebval(x: Array, c: Array) -> Array:
    """The Chebyshev series ``c`` at ``x``: through :func:`_chebyshev_matrix` for a few
    points, Clenshaw's recurrence for many (compiled where built: numpy's loop over the terms
    costs ~3 us a term)."""
    x = np.asarray(x, dtype=float)
    if x.size * c.size > MATRIX_LIMIT:
        if (USE_COMPILED and _compiled is not None and c.ndim == 1 and c.size
                and c.dtype == np.float64):
            out = np.empty(x.shape)
            _compiled.chebval(np.ascontiguousarray(x), np.ascontiguousarray(c), out)
            return out
        return np.asarray(cheb.chebval(x, c))
    values: Array = _chebyshev_matrix(x, c.size - 1) @ c
    return values.reshape(x.shape)


@lru_cache(maxsize=16)
def _unit_mesh(N: int) -> _Mesh:
    """One element on [0, 1] (constant curvature), built once per ``N``."""
    return _Mesh(np.array([0.0, 1.0]), N)


def _piecewise(edges: Array, coefs: list[tuple[Array, ...]]) -> SigmaFn:
    """``sigma(tau, k)`` from per-element Chebyshev coefficients."""
    if len(coefs) == 1:
        c0 = coefs[0]

        def one(tau: Array, k: int) -> Array:
            return _chebval(2.0 * np.asarray(tau, dtype=float) - 1.0, c0[k])

        return one

    def many(tau: Array, k: int) -> Array:
        t = np.asarray(tau, dtype=float)
        e = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, len(coefs) - 1)
        out = np.empty(t.shape)
        for i, c in enumerate(coefs):
            sel = e == i
            if sel.any():
                x = 2.0 * (t[sel] - edges[i]) / (edges[i + 1] - edges[i]) - 1.0
                out[sel] = _chebval(x, c[k])
        return out

    return many


@dataclass
class _Spectral:
    """A spectral solution: the law, its residual, nodes per element, the integrals
    ``Int sigma'^2`` and ``Int sigma''^2 + K^2 sigma'^4`` over ``tau`` in [0, 1] (once
    converged), the mesh and the unknowns."""

    sigma: SigmaFn
    residual: float
    nodes: int
    velocity2: float
    acceleration2: float
    mesh: _Mesh
    z: Array


class _Collocation:
    """Newton's method on the integral-form Chebyshev collocation equations, on one element
    (constant curvature) or on one element per smooth piece of the curvature."""

    def __init__(self, curvature: list[CurvatureFn], tol: float, tail: float = 1e-12,
                 every: CurvatureFn | None = None) -> None:
        self.curv, self.tol, self.tail, self.every = curvature, tol, tail, every
        self.iterations = 0
        self.scale = 1.0  # continuation in the curvature: K -> scale K
        self.damped = False  # halve Newton's steps that do not reduce the residual

    def _rhs(self, G2: float, K: Array, Ks: Array, Kss: Array, s1: Array, s2: Array,
             jac: bool) -> Any:
        lam = self.scale
        if lam != 1.0:
            K, Ks, Kss = lam * K, lam * Ks, lam * Kss
        s1sq = s1 * s1
        KK = K * K
        KKs = K * Ks
        F2 = G2 + 6.0 * KK * s1sq
        F = F2 * s2 + 3.0 * KKs * s1sq * s1sq
        if not jac:
            return F
        F1 = 12.0 * KK * s1 * s2 + 12.0 * KKs * s1sq * s1
        F0 = 12.0 * KKs * s1sq * s2 + 3.0 * (Ks * Ks + K * Kss) * s1sq * s1sq
        return F, F0, F1, F2

    def rhs(self, G2: float, mesh: _Mesh, s: Array, s1: Array, s2: Array) -> Any:
        """``F(sigma, sigma', sigma'')`` at the nodes and its partial derivatives."""
        if len(self.curv) == 1:
            K, Ks, Kss = self.curv[0](s)
        elif self.every is not None:  # the elements' nodes at once, (elements, N + 1)
            K, Ks, Kss = (k.reshape(-1) for k in self.every(s.reshape(len(self.curv), -1)))
        else:
            K, Ks, Kss = (np.empty_like(s) for _ in range(3))
            n = mesh.N + 1
            for e, fn in enumerate(self.curv):
                sl = slice(e * n, (e + 1) * n)
                K[sl], Ks[sl], Kss[sl] = fn(s[sl])
        return self._rhs(G2, K, Ks, Kss, s1, s2, True)

    def newton(self, G2: float, mesh: _Mesh, z: Array, max_iter: int = MAX_NEWTON
               ) -> Array | None:
        """Solve the collocation equations from ``z`` in at most ``max_iter`` iterations;
        None when Newton fails."""
        E0, E1, E2 = mesh.E[0], mesh.E[1], mesh.E[2]
        nu = mesh.nu
        J = np.empty((nu + 2, nu + 2))
        J[nu], J[nu + 1] = mesh.ends[0], mesh.ends[1]
        R = np.empty(nu + 2)
        diag = np.arange(nu)
        best = np.inf

        def residual(z: Array) -> tuple[Array, Any, float]:
            d = self.rhs(G2, mesh, E0 @ z, E1 @ z, E2 @ z)
            R[:nu] = z[:nu] - d[0]
            R[nu], R[nu + 1] = mesh.ends[0] @ z - 1.0, mesh.ends[1] @ z
            norm = np.abs(R[:nu]).max() / (1.0 + np.abs(d[0]).max()) + np.abs(R[nu:]).max()
            return R, d, float(norm)

        R, derivs, norm = residual(z)
        for _ in range(max_iter):
            self.iterations += 1
            F, F0, F1, F2 = derivs
            if not np.isfinite(R).all():
                return None
            Jn = J[:nu]
            np.multiply(-F0[:, None], E0, out=Jn)
            Jn -= F1[:, None] * E1
            Jn -= F2[:, None] * E2
            Jn[diag, diag] += 1.0
            try:
                dz = np.linalg.solve(J, -R)
            except np.linalg.LinAlgError:
                return None
            if norm > 10 * best:  # diverging
                return None
            best = min(best, norm)
            step = 1.0
            znew = z + dz
            R, derivs, new = residual(znew)
            # damped: halve the step while it does not decrease the residual (far from it)
            while self.damped and not new < norm and new > 1e-8 and step > 1.0 / 64:
                step *= 0.5
                znew = z + step * dz
                R, derivs, new = residual(znew)
            z, norm = znew, new
            if np.abs(step * dz[:nu]).max() <= (1e-14 * (1.0 + np.abs(z[:nu]).max())
                                                * (mesh.N + 1)):
                return z
        # accept if the last residual is tiny even without a clean step criterion
        return z if best < 1e-12 else None

    def check(self, G2: float, mesh: _Mesh, coefs: list[tuple[Array, ...]]
              ) -> tuple[float, float]:
        """Largest ODE residual between the nodes (relative to ``1 + max |u|``) and the
        largest relative size of the last Chebyshev coefficients of ``u`` of an element."""
        V = mesh.ops.between
        worst, top, tail = 0.0, 0.0, 0.0
        for e, c in enumerate(coefs):
            s, s1, s2, u = (V[:, :c[k].size] @ c[k] for k in (0, 1, 2, 4))
            K, Ks, Kss = self.curv[e](s)
            F = self._rhs(G2, K, Ks, Kss, s1, s2, False)
            worst = max(worst, float(np.abs(u - F).max()))
            top = max(top, float(np.abs(u).max()))
            a = c[4]
            tail = max(tail, float(np.abs(a[-4:]).max() / max(np.abs(a).max(), 1e-300)))
        return worst / (1.0 + top), tail

    def cost(self, mesh: _Mesh, coefs: list[tuple[Array, ...]]) -> tuple[float, float]:
        """``Int sigma'^2`` and ``Int sigma''^2 + K^2 sigma'^4`` over [0, 1] (Gauss-Legendre
        on each element, exact for constant curvature)."""
        V, wg = mesh.ops.gauss
        v2 = a2 = 0.0
        for e, c in enumerate(coefs):
            s, s1, s2 = (V[:, :c[k].size] @ c[k] for k in range(3))
            K = self.curv[e](s)[0]
            half = 0.5 * mesh.h[e]
            v2 += half * float(wg @ (s1 * s1))
            a2 += half * float(wg @ (s2 * s2 + K * K * s1**4))
        return v2, a2

    def solve(self, G: float, edges: Array, N: int, guess: _Spectral | None, max_nodes: int,
              *, refine: bool = True, retry: bool = True, max_iter: int = MAX_NEWTON
              ) -> _Spectral | None:
        """Solve at ``G`` on elements with ``edges``, from ``N`` nodes per element, doubling
        ``N`` up to ``max_nodes`` until the residual and the coefficients' tail are small
        (``refine``; else the first Newton solution at ``N`` is returned unchecked). When
        Newton fails, try again with more nodes only if ``retry``. None on failure."""
        G2 = G * G
        while True:
            mesh = _unit_mesh(N) if len(edges) == 2 and edges[1] == 1.0 else _Mesh(edges, N)
            tau = mesh.nodes()
            if guess is None:
                g = line_solution(G, tau)
                g0 = line_solution(G, np.zeros(1))
                z = np.concatenate([G2 * g[2], [0.5 * g0[2, 0], g0[3, 0] / 6.0]])
            else:
                zero = np.zeros(1)
                z = np.concatenate([guess.sigma(tau, 4), [0.5 * guess.sigma(zero, 2)[0],
                                                          guess.sigma(zero, 3)[0] / 6.0]])
            zz = self.newton(G2, mesh, z, max_iter)
            if zz is None and not retry:
                return None
            if zz is not None:
                coefs = mesh.coefficients(zz)
                sol = _Spectral(_piecewise(mesh.edges, coefs), np.inf, N + 1, 0.0, 0.0, mesh,
                                zz)
                if not refine:
                    return sol
                sol.residual, tail = self.check(G2, mesh, coefs)
                if sol.residual <= self.tol and tail <= self.tail:
                    sol.velocity2, sol.acceleration2 = self.cost(mesh, coefs)
                    return sol
                guess = sol
            if 2 * N > max_nodes:
                return None
            N *= 2


@dataclass(frozen=True)
class OptimalLaw(Law):
    """The solved optimal law; evaluate it like any :class:`Law`.

    Attributes
    ----------
    eta, mass : float
        The weight of the inertia term and the moving mass.
    kinetic, inertial : float
        The functional's two parts, ``(m/2) Int |rdot|^2`` and ``(eta m^2/2) Int |rddot|^2``.
    residual : float
        Largest residual of the ODE between the collocation nodes, relative to
        ``1 + max |s''''|`` (dimensionless).
    nodes, iterations : int
        Number of Chebyshev nodes and of Newton iterations (over all attempts).
    """

    distance: float
    duration: float
    eta: float
    mass: float
    sigma: Callable[[Array, int], Array] = field(repr=False)  # (tau, k) -> sigma^(k)
    kinetic: float = 0.0
    inertial: float = 0.0
    residual: float = 0.0
    nodes: int = 0
    iterations: int = 0
    message: str = ""
    status: int = 0
    name: str = field(default="optimal", init=False)

    @property
    def cost(self) -> float:
        """The functional ``Phi``, kinetic plus inertial part."""
        return self.kinetic + self.inertial

    def cost_report(self) -> dict[str, float]:
        """The functional it minimises: total, kinetic and inertial parts."""
        return {"total": self.cost, "kinetic": self.kinetic, "inertial": self.inertial}

    def report(self, units: Units) -> dict[str, Any]:
        """``eta`` (run units), the ODE residual and the collocation nodes."""
        return {"eta": self.eta, "ode_residual": self.residual, "nodes": self.nodes}

    def cost_parts(self, path: Path, mass: float, eta: float) -> tuple[float, float]:
        """The functional's two parts (stored when ``mass`` and ``eta`` are the law's own)."""
        if mass == self.mass and eta == self.eta:
            return self.kinetic, self.inertial
        return law_cost(self, path, mass, eta)

    def _sigma(self, t: Array, k: int) -> Array:
        return self.sigma(t / self.duration, k)

    def _evaluate(self, t: Array) -> Array:
        S, T = self.distance, self.duration
        return np.stack([S / T**k * self._sigma(t, k) for k in range(4)])

    def fourth_derivative(self, t: object) -> Array:
        """``s''''(t)`` of the computed law (for checking the ODE)."""
        t = np.asarray(t, dtype=float)
        return self.distance / self.duration**4 * self._sigma(t, 4)


class _Solution(NamedTuple):
    """What a solver hands back: the law (None when it failed), its residual, nodes,
    Newton iterations or solves, the method's words and, for the spectral solvers, the
    integrals ``Int sigma'^2`` and ``Int sigma''^2 + K^2 sigma'^4`` (else None)."""

    sigma: SigmaFn | None
    residual: float
    nodes: int
    iterations: int
    method: str
    integrals: tuple[float, float] | None = None


def _said(T: float, eta: float, m: float, S: float, units: Units | None) -> dict[str, str]:
    """The law's figures in words, in the user's units (s, s^2/kg, kg, mm) when the run's
    are known, else as they are."""
    if units is None:
        return {"eta": f"eta = {eta:g}", "duration": f"duration {T:g}", "mass": f"mass {m:g}",
                "length": f"{S:.6g}"}
    return {"eta": f"eta = {eta * units.time_s**2 / units.mass_kg:g} s^2/kg",
            "duration": f"duration {T * units.time_s:g} s",
            "mass": f"mass {m * units.mass_kg:g} kg", "length": f"{S * units.length_mm:.6g} mm"}


def solve_optimal_law(path: Path, *, duration: float = 1.0, eta: float = 0.1, mass: float = 1.0,
                      tol: float = 1e-10, max_nodes: int = 1024,
                      units: Units | None = None) -> OptimalLaw:
    """Solve the paper's optimal law of motion along ``path``.

    Parameters
    ----------
    path : Path
        Any regular path with curvature (C3 or smoother).
    duration : float
        Motion time ``T``.
    eta : float
        Weight of the mean-square inertia forces (time^2 / mass).
    mass : float
        Moving mass ``m``.
    tol : float
        Target for the ODE residual between the nodes, relative to ``1 + max |s''''|``.
    max_nodes : int
        Largest number of Chebyshev nodes tried (per element).
    units : Units, optional
        The run's units, so that an error speaks the user's (s, kg, s^2/kg, mm).

    Returns
    -------
    OptimalLaw

    Raises
    ------
    ConvergenceError
        When neither the direct solve nor a continuation converges within its bounds
        (:data:`MAX_NEWTON`, :data:`MAX_CONTINUATION_SOLVES`, ``max_nodes``).
    """
    T = _positive("duration", duration)
    eta = _positive("eta", eta)
    m = _positive("mass", mass)
    S = path.length
    G = T / math.sqrt(eta * m)
    said = _said(T, eta, m, S, units)
    if not G <= 1e4:
        raise ParameterError(f"{said['eta']} is too small for {said['duration']} and "
                             f"{said['mass']}: boundary layers of relative width {1 / G:.1e} "
                             f"(need duration / sqrt(eta mass) <= 1e4, here {G:.3g}): a larger "
                             "eta or a shorter duration")
    if path.constant_curvature is not None:
        sol = _solve_spectral(path.constant_curvature * S, G, tol, max_nodes)
    else:
        sol = _solve_pieces(path, S, G, tol, min(max_nodes, 256))
        if sol.sigma is None:  # curvature not smooth on known pieces, or too wild
            sol = _solve_local(path, S, G, max(tol, 1e-8))
    if sol.sigma is None:
        raise ConvergenceError(
            f"optimal law did not converge for {said['eta']}, {said['mass']}, "
            f"{said['duration']} on a path of length {said['length']} (duration / sqrt(eta "
            f"mass) = {G:.4g}) with {sol.method}")
    resid, nodes = sol.residual, sol.nodes
    law = OptimalLaw(distance=S, duration=T, eta=eta, mass=m, sigma=sol.sigma, residual=resid,
                     nodes=nodes, iterations=sol.iterations,
                     message=f"converged ({sol.method}): residual {resid:.1e} with {nodes} "
                             "nodes")
    if sol.integrals is not None:
        v2, a2 = sol.integrals
        kin, inert = 0.5 * m * S * S / T * v2, 0.5 * eta * m * m * S * S / T**3 * a2
    else:
        kin, inert = law_cost(law, path, m, eta, nodes=max(64, 2 * nodes))
    if not (math.isfinite(kin) and math.isfinite(inert)):
        part = "kinetic part, which grows as the mass" if not math.isfinite(kin) else \
            "inertial part, which grows as eta times the mass squared"
        raise ParameterError(f"{said['mass']} and {said['eta']} are too large for a finite "
                             f"cost on a path of length {said['length']}: its {part}, "
                             "overflows (a smaller mass or eta)")
    law = replace(law, kinetic=kin, inertial=inert)
    bc = law.evaluate(np.array([0.0, T]))
    bc_err = max(abs(bc[0, 0]), abs(bc[0, 1] - S), abs(bc[1, 0]) * T, abs(bc[1, 1]) * T) / S
    if bc_err > 1e-8:
        raise ConvergenceError(f"optimal law violates its boundary conditions by {bc_err:.1e}")
    return law


def _first_nodes(G: float, max_nodes: int) -> int:
    """Enough nodes to see the boundary layers (width 1 / G)."""
    return int(min(max_nodes, 2 ** math.ceil(math.log2(max(32.0, 6.0 * math.sqrt(G))))))


def _spectral_solution(sol: _Spectral, iterations: int, method: str) -> _Solution:
    return _Solution(sol.sigma, sol.residual, sol.nodes * len(sol.mesh.h), iterations, method,
                     (sol.velocity2, sol.acceleration2))


def _solve_spectral(Kc: float, G: float, tol: float, max_nodes: int) -> _Solution:
    """Constant curvature ``K = kappa S``: Chebyshev collocation on one element (spectral
    accuracy, about a millisecond), by continuation in ``G`` when the direct solve fails."""

    def curvature(s: Array) -> tuple[Array, Array, Array]:
        z = np.zeros_like(s)
        return np.full_like(s, Kc), z, z

    solver = _Collocation([curvature], tol)
    edges = np.array([0.0, 1.0])
    N = _first_nodes(G, max_nodes)
    state = solver.solve(G, edges, N, None, max_nodes)
    if state is None:  # continuation in G from an easy problem
        for Gv in np.geomspace(min(3.0, G), G, 10):
            state = solver.solve(float(Gv), edges, N, state, max_nodes)
            if state is None:
                break
    if state is None:
        return _Solution(None, np.inf, 0, solver.iterations,
                         f"Chebyshev collocation, up to {max_nodes} nodes, direct and by "
                         "continuation in eta")
    return _spectral_solution(state, solver.iterations, "Chebyshev collocation")


def _breaks(path: Path, S: float) -> Array:
    """Where the curvature may lose smoothness, in normalised arc length (with 0 and 1): a
    B-spline path's interior knots, a composite path's joints."""
    p: list[float] = []
    spl = getattr(path, "_spl", None)  # Spline: its B-spline's knots
    knots = getattr(spl, "t", None)
    if knots is not None:
        p = [float(v) for v in np.unique(knots) if path.p0 < v < path.p1]
        s = path.arc_length(np.array(p)) / S if p else np.empty(0)
    else:
        starts = getattr(path, "starts", None)  # Composite: arc length at its joints
        s = np.asarray(starts, dtype=float)[1:-1] / S if starts is not None else np.empty(0)
    return np.concatenate([[0.0], np.sort(s[(s > 1e-9) & (s < 1 - 1e-9)]), [1.0]])


def _curvature_pieces(path: Path, S: float, breaks: Array
                      ) -> tuple[list[CurvatureFn], CurvatureFn] | None:
    """On each piece between the breaks, ``K = kappa S`` as a function of the normalised arc
    length, by Chebyshev interpolation until its coefficients have decayed to 1e-13 (and its
    derivatives by differentiating the series); None when some piece's curvature is not
    smooth enough for that within 513 points, or not continuous across a break. Returns the function of each piece and the
    function of all of them at once (on ``sigma`` of shape (pieces, n))."""
    pieces = list(zip(breaks[:-1], breaks[1:], strict=True))
    series: list[tuple[float, float, Array]] = []
    for a, b in pieces:
        for deg in (64, 128, 256, 512):
            x, to_coef = _lobatto(deg)
            sig = a + 0.5 * (b - a) * (x + 1.0)
            K = path.curvature(path.parameter_at(np.clip(sig, 0.0, 1.0) * S))[0] * S
            coef = to_coef @ K
            if np.abs(coef[-3:]).max() <= 1e-13 * max(1.0, float(np.abs(K).max())):
                series.append((float(a), float(b), coef))
                break
        else:
            return None
    # the elements join with sigma C3, right only where the curvature is continuous (a jump
    # in K puts a jump in sigma''': solve_bvp's smoothed curvature takes those paths)
    ends = [(float(cheb.chebval(-1.0, c)), float(cheb.chebval(1.0, c))) for _, _, c in series]
    scale_K = max(1.0, max(abs(v) for pair in ends for v in pair))
    if any(abs(ends[e][1] - ends[e + 1][0]) > 1e-9 * scale_K for e in range(len(ends) - 1)):
        return None
    size = max(coef.size for _, _, coef in series)
    C = np.zeros((len(series), size, 3))  # K, K_sigma, K_sigma_sigma of each piece
    for e, (a, b, coef) in enumerate(series):
        scale = 2.0 / (b - a)
        d1 = cheb.chebder(coef) * scale
        C[e, :coef.size, 0], C[e, :coef.size - 1, 1] = coef, d1
        C[e, :coef.size - 2, 2] = cheb.chebder(d1) * scale
    mid = np.array([[a + b] for a, b, _ in series])
    width = np.array([[b - a] for a, b, _ in series])

    def on(e: int | slice, s: Array) -> tuple[Array, Array, Array]:
        # a little beyond the piece while the edges settle, never far
        x = np.clip((2.0 * s - mid[e]) / width[e], -1.1, 1.1)
        T = _chebyshev_matrix(x, size - 1).reshape(x.shape + (size,))
        K = T @ C[e]
        return K[..., 0], K[..., 1], K[..., 2]

    fns: list[CurvatureFn] = [partial(on, e) for e in range(len(series))]
    return fns, partial(on, slice(None))


def _edges_at(sigma: SigmaFn, breaks: Array, edges: Array) -> Array:
    """The times where the law crosses the breaks (Newton from the current ``edges``)."""
    t = edges[1:-1].copy()
    target = breaks[1:-1]
    for _ in range(20):
        step = (sigma(t, 0) - target) / np.maximum(sigma(t, 1), 1e-300)
        t = np.clip(t - step, 0.0, 1.0)
        if np.abs(step).max(initial=0.0) <= 1e-13:  # quadratic: the next step is ~1e-26
            break
    return np.concatenate([[0.0], t, [1.0]])


def _solve_pieces(path: Path, S: float, G: float, tol: float, max_nodes: int) -> _Solution:
    """Varying curvature, smooth on pieces (a spline between its knots, an analytic path in
    one piece): one Chebyshev element per piece, whose edges follow the times at which the
    law crosses the pieces' ends. The full curvature is reached on a coarse mesh, directly or
    by continuation in its scale (from the straight line, whose solution is exact); there the
    edges settle, then the nodes double until the residual is below ``tol``."""
    method = "Chebyshev collocation on the curvature's smooth pieces"
    breaks = _breaks(path, S)
    fits = _curvature_pieces(path, S, breaks)
    if fits is None:
        return _Solution(None, np.inf, 0, 0, method + " (curvature not smooth on them)")
    # the residual is the criterion here; the coefficients' tail only guards it
    solver = _Collocation(fits[0], tol, tail=max(1e-12, tol), every=fits[1])
    solver.damped = True

    def line(tau: Array, k: int) -> Array:
        return np.asarray(line_solution(G, tau)[k])

    edges = _edges_at(line, breaks, breaks.copy())
    N = _first_nodes(G, max_nodes)
    state = _continued(solver, G, edges, N, max_nodes)
    refine = False  # coarse while the edges move, then refined
    for _ in range(2 * MAX_EDGE_UPDATES):
        if state is None:
            break
        new = _edges_at(state.sigma, breaks, edges)
        moved = float(np.abs(new - edges).max())
        # an edge off its break by d changes the curvature its element sees by about
        # jump(K''') d^3 / 6 on a spline (C2 curvature), jump(K') d^2 / 2 on a G2 chain
        N = state.nodes - 1
        if not refine and moved <= 1e-8:  # the edges have settled: is the coarse law enough?
            refine = True
            coefs = state.mesh.coefficients(state.z)
            state.residual, tail = solver.check(G * G, state.mesh, coefs)
            if state.residual <= solver.tol and tail <= solver.tail:
                state.velocity2, state.acceleration2 = solver.cost(state.mesh, coefs)
            elif 2 * N <= max_nodes:
                N *= 2  # it does not resolve the law: refine from twice the nodes
                state.residual = np.inf
            else:
                break
        if refine and moved <= 1e-8 and state.residual <= solver.tol:
            return _Solution(state.sigma, state.residual, state.nodes * len(state.mesh.h),
                             solver.iterations, f"{method}, {len(breaks) - 1} of them",
                             (state.velocity2, state.acceleration2))
        edges = new
        state = solver.solve(G, edges, N, state, max_nodes, refine=refine, retry=False)
    return _Solution(None, np.inf, 0, solver.iterations, method)


def _continued(solver: _Collocation, G: float, edges: Array, N: int, max_nodes: int
               ) -> _Spectral | None:
    """A Newton solution at the full curvature on ``N`` nodes per element, from the line's
    law or, when that fails, by continuation in the curvature's scale from 0 with adaptive
    steps (at most MAX_CONTINUATION_SOLVES solves)."""
    # from the line's law Newton converges in a few iterations or not at all
    sol = solver.solve(G, edges, N, None, max_nodes, refine=False, retry=False, max_iter=12)
    if sol is not None:
        return sol
    lam, step, state = 0.0, 0.25, None
    for _ in range(MAX_CONTINUATION_SOLVES):
        target = min(1.0, lam + step)
        solver.scale = target
        trial = solver.solve(G, edges, N, state, max_nodes, refine=False, retry=False)
        solver.scale = 1.0
        if trial is None:
            step *= 0.5
            if step < 1.0 / 256:
                return None
            continue
        if target == 1.0:
            return trial
        lam, step, state = target, min(1.0, 2.0 * step), trial
    return None


def _solve_local(path: Path, S: float, G: float, tol: float) -> _Solution:
    """Varying curvature that is not smooth on known pieces: collocation with local mesh
    refinement (scipy's solve_bvp), by continuation in the curvature (``kappa -> lam kappa``,
    ``lam`` from 0, the straight line whose solution is exact, to 1) with adaptive steps, at
    most MAX_CONTINUATION_SOLVES solves."""

    # curvature along the normalised arc length, tabulated once at 4097 nodes and interpolated
    # by a quintic spline (smooth, so the mesh refinement does not chase interpolation kinks)
    grid = np.linspace(0.0, 1.0, 4097)
    K_of = interpolate.make_interp_spline(grid, path.curvature(path.parameter_at(grid * S))[0] * S, k=5)
    Ks_of = K_of.derivative()

    def curvature(sig: Array) -> tuple[Array, Array]:
        sig = np.clip(sig, 0.0, 1.0)
        return K_of(sig), Ks_of(sig)

    G2 = G * G

    def make(lam: float) -> Callable[[Array, Array], Array]:
        def fun(_tau: Array, y: Array) -> Array:
            K, Ks = curvature(y[0])
            K, Ks = lam * K, lam * Ks
            y1sq = y[1] * y[1]
            return np.vstack([y[1], y[2], y[3], (G2 + 6 * K * K * y1sq) * y[2]
                              + 3 * K * Ks * y1sq * y1sq])
        return fun

    def bc(ya: Array, yb: Array) -> Array:
        return np.array([ya[0], ya[1], yb[0] - 1.0, yb[1]])

    mesh = np.linspace(0.0, 1.0, 61)
    if G > 20:
        layer = np.geomspace(0.05, 12.0, 24) / G
        layer = layer[layer < 0.5]
        mesh = np.unique(np.concatenate([mesh, layer, 1.0 - layer]))
    res: Any = None
    guess = line_solution(G, mesh)
    lam, step, solves = 0.0, 1.0, 0
    while lam < 1.0:
        target = min(1.0, lam + step)
        trial = integrate.solve_bvp(make(target), bc, mesh, guess, tol=tol if target == 1.0 else 1e-5,
                          max_nodes=50_000)
        solves += 1
        if trial.success:
            res, lam = trial, target
            mesh, guess = trial.x, trial.y
            step = min(1.0, 2 * step)
        else:
            step *= 0.5
            if step < 1.0 / 256 or solves >= MAX_CONTINUATION_SOLVES:
                return _Solution(None, np.inf, 0, solves, (
                    "collocation with mesh refinement and continuation in curvature (stopped "
                    f"at {lam:.3g} of the curvature after {solves} solves: {trial.message})"))
    sol = res.sol

    def sigma(tau: Array, k: int) -> Array:
        flat = np.asarray(tau, dtype=float).reshape(-1)
        vals = sol(flat, 1)[3] if k == 4 else sol(flat)[k]
        return np.asarray(vals).reshape(np.shape(tau))

    return _Solution(sigma, float(np.max(res.rms_residuals)), int(res.x.size), solves,
                     "collocation with mesh refinement (solve_bvp)")


def _register() -> None:
    register_law(LawType(
        "optimal",
        {"duration": Param("number", "s", 1.0, "motion time", positive=True),
         "eta": Param("number", "s^2/kg", 0.1, "weight of the mean-square inertia forces",
                      positive=True)},
        lambda r: solve_optimal_law(r.path, duration=r.params["duration"], eta=r.params["eta"],
                                    units=r.units,
                                    mass=r.mass),
        "the paper's optimal law: minimise (m/2) Int |rdot|^2 + (eta m^2/2) Int |rddot|^2"))


_register()
