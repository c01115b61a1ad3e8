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
as the next guess. Failure raises :class:`ConvergenceError`: never a silent wrong answer.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.polynomial import chebyshev as cheb
from scipy.integrate import solve_bvp
from scipy.interpolate import make_interp_spline

from .._arrays import Array
from ..errors import ConvergenceError, ParameterError
from ..paths import Path
from ..units import Units
from .base import Law, _positive, law_cost


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


#: Wall-clock budget of the continuation on paths of varying curvature (s): a path whose
#: curvature is so wild that it takes longer gets a ConvergenceError, not a hang.
TIME_BUDGET_S = 20.0


@dataclass(frozen=True)
class _Ops:
    """Chebyshev collocation operators for ``N + 1`` Lobatto points on ``tau`` in [0, 1]."""

    x: Array  # nodes in [-1, 1], x_0 = 1 (tau = 1)
    tau: Array
    to_coef: Array  # values -> Chebyshev coefficients
    Q: tuple[Array, ...]  # k-fold integration from tau = 0 in coefficient space, k = 1..4
    M: tuple[Array, ...]  # the same from node values to node values


@lru_cache(maxsize=16)
def _ops(N: int) -> _Ops:
    j = np.arange(N + 1)
    x = np.cos(np.pi * j / N)
    gamma = np.ones(N + 1)
    gamma[[0, N]] = 2.0
    to_coef = (2.0 / N) * np.cos(np.pi * np.outer(j, j) / N) / np.outer(gamma, gamma)
    eye = np.eye(N + 1)
    Q = tuple(cheb.chebint(eye, m=k, lbnd=-1, scl=0.5, axis=0) for k in range(1, 5))
    M = tuple(cheb.chebvander(x, N + k) @ Q[k - 1] @ to_coef for k in range(1, 5))
    return _Ops(x, 0.5 * (x + 1.0), to_coef, Q, M)


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


def solve_optimal_law(path: Path, *, duration: float = 1.0, eta: float = 0.1, mass: float = 1.0,
                      tol: float = 1e-10, max_nodes: int = 1024) -> OptimalLaw:
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
        Largest number of Chebyshev nodes tried.

    Returns
    -------
    OptimalLaw

    Raises
    ------
    ConvergenceError
        When neither the direct solve nor continuation in ``eta`` converges.
    """
    T = _positive("duration", duration)
    eta = _positive("eta", eta)
    m = _positive("mass", mass)
    S = path.length
    G = T / math.sqrt(eta * m)
    if G > 1e4:
        raise ParameterError(f"eta = {eta:g} is too small for duration {T:g} and mass {m:g}: "
                             f"boundary layers of relative width {1 / G:.1e} (need "
                             f"T / sqrt(eta m) <= 1e4)")
    if path.constant_curvature is not None:
        sigma, resid, nodes, iters, method = _solve_spectral(path, S, G, tol, max_nodes)
    else:
        sigma, resid, nodes, iters, method = _solve_local(path, S, G, max(tol, 1e-8))
    if sigma is None:
        raise ConvergenceError(
            f"optimal law did not converge for eta = {eta:g}, mass = {m:g}, duration {T:g} on "
            f"a path of length {S:.6g} (G = T/sqrt(eta m) = {G:.4g}) with {method}")
    law = OptimalLaw(distance=S, duration=T, eta=eta, mass=m, sigma=sigma, residual=resid,
                     nodes=nodes, iterations=iters,
                     message=f"converged ({method}): residual {resid:.1e} with {nodes} nodes")
    kin, inert = law_cost(law, path, m, eta, nodes=max(64, 2 * nodes))
    law = replace(law, kinetic=kin, inertial=inert)
    bc = law.evaluate(np.array([0.0, T]))
    bc_err = max(abs(bc[0, 0]), abs(bc[0, 1] - S), abs(bc[1, 0]) * T, abs(bc[1, 1]) * T) / S
    if bc_err > 1e-8:
        raise ConvergenceError(f"optimal law violates its boundary conditions by {bc_err:.1e}")
    return law


def _solve_spectral(path: Path, S: float, G: float, tol: float, max_nodes: int
                    ) -> tuple[SigmaFn | None, float, int, int, str]:
    """Constant curvature: Chebyshev collocation (spectral accuracy, milliseconds)."""
    solver = _Collocation(path, S, tol)
    # start with enough nodes to see the boundary layers (width 1/G)
    N = int(min(max_nodes, 2 ** math.ceil(math.log2(max(32.0, 6.0 * math.sqrt(G))))))
    state = solver.solve(G, N, None, max_nodes)
    if state is None:  # continuation in G from an easy problem
        for Gv in np.geomspace(min(3.0, G), G, 10):
            state = solver.solve(float(Gv), N, state, max_nodes)
            if state is None:
                break
    method = f"Chebyshev collocation, up to {max_nodes} nodes, direct and by continuation in eta"
    if state is None:
        return None, np.inf, 0, solver.iterations, method
    coef, resid, N = state

    def sigma(tau: Array, k: int) -> Array:
        return np.asarray(cheb.chebval(2.0 * tau - 1.0, coef[k]))

    return sigma, resid, N + 1, solver.iterations, "Chebyshev collocation"


def _solve_local(path: Path, S: float, G: float, tol: float
                 ) -> tuple[SigmaFn | None, float, int, int, str]:
    """Varying curvature: collocation with local mesh refinement (scipy's solve_bvp), by
    continuation in the curvature (``kappa -> lam kappa``, ``lam`` from 0, the straight line
    whose solution is exact, to 1) with adaptive steps."""
    # curvature along the normalised arc length, tabulated once at 4097 nodes and interpolated
    # by a quintic spline (smooth, so the mesh refinement does not chase interpolation kinks)
    grid = np.linspace(0.0, 1.0, 4097)
    K_of = make_interp_spline(grid, path.curvature(path.parameter_at(grid * S))[0] * S, k=5)
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
    started = time.perf_counter()
    while lam < 1.0:
        if time.perf_counter() - started > TIME_BUDGET_S:
            return None, np.inf, 0, solves, (
                f"collocation with mesh refinement and continuation in curvature (stopped at "
                f"{lam:.3g} of the curvature after {TIME_BUDGET_S:g} s)")
        target = min(1.0, lam + step)
        trial = solve_bvp(make(target), bc, mesh, guess, tol=tol if target == 1.0 else 1e-5,
                          max_nodes=50_000)
        solves += 1
        if trial.success:
            res, lam = trial, target
            mesh, guess = trial.x, trial.y
            step = min(1.0, 2 * step)
        else:
            step *= 0.5
            if step < 1.0 / 256 or solves > 60:
                return None, np.inf, 0, solves, ("collocation with mesh refinement and "
                                                 f"continuation in curvature (stopped at "
                                                 f"{lam:.3g} of the curvature: {trial.message})")
    sol = res.sol

    def sigma(tau: Array, k: int) -> Array:
        flat = np.asarray(tau, dtype=float).reshape(-1)
        vals = sol(flat, 1)[3] if k == 4 else sol(flat)[k]
        return np.asarray(vals).reshape(np.shape(tau))

    return (sigma, float(np.max(res.rms_residuals)), int(res.x.size), solves,
            "collocation with mesh refinement (solve_bvp)")


class _Collocation:
    """Newton's method on the integral-form Chebyshev collocation equations."""

    def __init__(self, path: Path, S: float, tol: float) -> None:
        self.path, self.S, self.tol = path, S, tol
        kc = path.constant_curvature
        self.Kc = None if kc is None else kc * S
        self.iterations = 0

    def curvature(self, sig: Array) -> tuple[Array, Array, Array]:
        """``K, K_sigma, K_sigma_sigma`` at ``sigma`` (clipped to the path)."""
        if self.Kc is not None:
            z = np.zeros_like(sig)
            return np.full_like(sig, self.Kc), z, z

        def k_and_dk(sg: Array) -> tuple[Array, Array]:
            p = self.path.parameter_at(np.clip(sg, 0.0, 1.0) * self.S)
            k, dk = self.path.curvature(p)
            return k * self.S, dk * self.S**2

        K, Ks = k_and_dk(sig)
        h = 1e-5
        Kss = (k_and_dk(sig + h)[1] - k_and_dk(sig - h)[1]) / (2 * h)
        return K, Ks, Kss

    def rhs(self, G2: float, s: Array, s1: Array, s2: Array, jac: bool = False) -> Any:
        K, Ks, Kss = self.curvature(s)
        s1sq = s1 * s1
        F = (G2 + 6.0 * K * K * s1sq) * s2 + 3.0 * K * Ks * s1sq * s1sq
        if not jac:
            return F
        F2 = G2 + 6.0 * K * K * s1sq
        F1 = 12.0 * K * K * s1 * s2 + 12.0 * K * Ks * s1sq * s1
        F0 = 12.0 * K * Ks * s1sq * s2 + 3.0 * (Ks * Ks + K * Kss) * s1sq * s1sq
        return F, F0, F1, F2

    def solve(self, G: float, N: int, guess: tuple[Any, ...] | None, max_nodes: int
              ) -> tuple[tuple[Array, ...], float, int] | None:
        """Solve at ``G`` starting with ``N`` nodes; returns (coef, residual, N, u-evaluator)
        or None."""
        G2 = G * G
        while True:
            ops = _ops(N)
            tau = ops.tau
            if guess is None:
                g = line_solution(G, tau)
                g0 = line_solution(G, np.zeros(1))
                u, c2, c3 = G2 * g[2], 0.5 * g0[2, 0], g0[3, 0] / 6.0
            else:
                coef_prev = guess[0]
                u = cheb.chebval(ops.x, coef_prev[4])
                c2 = 0.5 * cheb.chebval(-1.0, coef_prev[2])
                c3 = cheb.chebval(-1.0, coef_prev[3]) / 6.0
            out = self._newton(G2, ops, u, c2, c3)
            if out is not None:
                u, c2, c3 = out
                coef = self._coefficients(ops, u, c2, c3)
                resid, tail = self._residual(G2, coef, N)
                if resid <= self.tol and tail <= 1e-12:
                    return coef, resid, N
                guess = (coef,)
            if 2 * N > max_nodes:
                return None
            N *= 2

    def _newton(self, G2: float, ops: _Ops, u: Array, c2: float, c3: float
                ) -> tuple[Array, float, float] | None:
        M1, M2, M3, M4 = ops.M
        tau = ops.tau
        n = tau.size
        J = np.zeros((n + 2, n + 2))
        eye = np.eye(n)
        scale_prev = np.inf
        for _ in range(40):
            self.iterations += 1
            s = M4 @ u + c2 * tau**2 + c3 * tau**3
            s1 = M3 @ u + 2 * c2 * tau + 3 * c3 * tau**2
            s2 = M2 @ u + 2 * c2 + 6 * c3 * tau
            F, F0, F1, F2 = self.rhs(G2, s, s1, s2, jac=True)
            R = np.concatenate([u - F, [s[0] - 1.0, s1[0]]])
            if not np.isfinite(R).all():
                return None
            J[:n, :n] = eye - F0[:, None] * M4 - F1[:, None] * M3 - F2[:, None] * M2
            J[:n, n] = -(F0 * tau**2 + F1 * 2 * tau + F2 * 2)
            J[:n, n + 1] = -(F0 * tau**3 + F1 * 3 * tau**2 + F2 * 6 * tau)
            J[n, :n], J[n, n], J[n, n + 1] = M4[0], 1.0, 1.0
            J[n + 1, :n], J[n + 1, n], J[n + 1, n + 1] = M3[0], 2.0, 3.0
            try:
                dz = np.linalg.solve(J, -R)
            except np.linalg.LinAlgError:
                return None
            norm = np.abs(R[:n]).max() / (1.0 + np.abs(F).max()) + np.abs(R[n:]).max()
            if norm > 10 * scale_prev:  # diverging
                return None
            scale_prev = min(scale_prev, norm)
            u = u + dz[:n]
            c2 += dz[n]
            c3 += dz[n + 1]
            if np.abs(dz[:n]).max() <= 1e-14 * (1.0 + np.abs(u).max()) * n:
                return u, c2, c3
        # accept if the last residual is tiny even without a clean step criterion
        return (u, c2, c3) if scale_prev < 1e-12 else None

    @staticmethod
    def _coefficients(ops: _Ops, u: Array, c2: float, c3: float) -> tuple[Array, ...]:
        a = ops.to_coef @ u
        # polynomial part c2 tau^2 + c3 tau^3 in x = 2 tau - 1, and its derivatives in tau
        p = np.polynomial.Polynomial([0.0, 0.0, c2, c3], domain=[0, 1], window=[0, 1])
        coefs = []
        for k in range(4):
            integral = ops.Q[3 - k] @ a  # (4 - k)-fold integral of u
            pk = p.deriv(k) if k else p
            # express pk(tau) with tau = (x + 1)/2 as a Chebyshev series in x
            pc = cheb.Chebyshev.cast(pk, domain=[0, 1], window=[-1, 1]).coef
            n = max(integral.size, pc.size)
            c = np.zeros(n)
            c[: integral.size] += integral
            c[: pc.size] += pc
            coefs.append(c)
        coefs.append(a)
        return tuple(coefs)

    def _residual(self, G2: float, coef: tuple[Array, ...], N: int) -> tuple[float, float]:
        m = 4 * N
        x = np.cos(np.pi * (np.arange(m) + 0.5) / m)
        s, s1, s2, _, u = (cheb.chebval(x, c) for c in coef)
        F = self.rhs(G2, s, s1, s2)
        resid = float(np.abs(u - F).max() / (1.0 + np.abs(u).max()))
        a = coef[4]
        tail = float(np.abs(a[-4:]).max() / max(np.abs(a).max(), 1e-300))
        return resid, tail


def _register() -> None:
    from ..params import Param
    from .registry import LawType, register_law

    register_law(LawType(
        "optimal",
        {"duration": Param("number", "s", 1.0, "motion time", positive=True),
         "eta": Param("number", "s^2/kg", 0.1, "weight of the mean-square inertia forces",
                      positive=True)},
        lambda r: solve_optimal_law(r.path, duration=r.params["duration"], eta=r.params["eta"],
                                    mass=r.mass),
        "the paper's optimal law: minimise (m/2) Int |rdot|^2 + (eta m^2/2) Int |rddot|^2"))


_register()
