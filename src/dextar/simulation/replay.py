"""The forward re-simulation of a planned motion in windows anchored to the plan.

An open-loop re-simulation of a whole motion under its own torques drifts however right the
torques are: the five-bar under given torques is unstable (gravity, the velocity products),
so rounding grows without bound and a long or fast motion ends far from its plan, or at a
singularity. In windows anchored to the plan the drift measures the torques instead: each
window starts at the planned state ``(q, qdot)`` and integrates the forward dynamics under the
planned torques to its end, where the angles are compared with the plan's. The windows are
short against the motion's own time scale (see :func:`replay_edges`), so what grows in them
is the torques' error, not the instability.

The windows are integrated side by side, as one system of ``4 K`` states (the dynamics
evaluated for every window at once), by an integrator that handles the stiffness of dry
friction near rest (LSODA with a banded Jacobian: each window's four states are coupled
only to each other).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..dynamics.exact import Model, accelerations
from ..errors import DextarError

integrate = lazy_module("scipy.integrate")

#: ``plan(t (n,)) -> (q, dq, tau)``, each (n, 2): the planned angles, rates and torques at
#: any times of the motion.
PlanFunction = Callable[[Array], tuple[Array, Array, Array]]


@dataclass(frozen=True)
class Replay:
    """The forward re-simulation in windows (run units).

    Attributes
    ----------
    edges : ndarray, shape (K + 1,)
        The windows' bounds in time, from 0 to the motion's duration.
    drift : ndarray, shape (K,)
        Per window, the largest angle error ``|q_sim - q_plan|`` (rad) at its end; ``inf``
        where the re-simulation left the robot's domain (a parallel singularity, rods that
        cannot meet) before the end.
    scale : ndarray, shape (K,)
        Per window, ``a_peak w^2 / 2``: how far an acceleration error equal to the
        motion's peak joint acceleration ``a_peak`` moves an angle over the window's length
        ``w`` (rad); ``drift / scale`` is the torques' error as a fraction of the peak
        acceleration.
    stopped : tuple of (int, float, str)
        The windows whose re-simulation stopped early: index, time reached, why.
    nfev : int
        Evaluations of the dynamics (each for every window at once).
    """

    edges: Array
    drift: Array
    scale: Array
    stopped: tuple[tuple[int, float, str], ...]
    nfev: int

    @property
    def ratio(self) -> Array:
        """``drift / scale`` per window: the re-simulated accelerations' error as a fraction
        of the peak joint acceleration."""
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(self.drift > 0, self.drift / self.scale, 0.0)
        return np.asarray(r)


#: The most windows a re-simulation integrates side by side.
MOST_WINDOWS = 10_000
#: The most evaluations of the dynamics a re-simulation may take (each for every window at
#: once; the right torques take 70-600: ``benchmarks/bench_checks.py``), and of the
#: dynamics of the windows added up.
BUDGET = 20_000
WINDOW_BUDGET = 20_000_000


class ReplayBudgetError(DextarError):
    """A re-simulation that would take more than its budget (:data:`MOST_WINDOWS`,
    :data:`BUDGET`)."""


def replay_edges(duration: float, rate: float, breakpoints: Array, *, least: int = 20,
                 most: int = MOST_WINDOWS) -> Array:
    """Window bounds over ``[0, duration]``: every breakpoint of the law (where the
    acceleration, so the torque, jumps) is a bound, and each piece between them is cut into
    windows at most ``1 / rate`` long (``rate`` the motion's fastest growth rate, 1 per time
    unit: an error grows by at most ``e`` over a window), at least ``least`` windows in all.

    Raises
    ------
    ReplayBudgetError
        More than ``most`` windows would be needed.
    """
    cuts = np.unique(np.concatenate([[0.0], np.asarray(breakpoints, float), [duration]]))
    cuts = cuts[(cuts >= 0.0) & (cuts <= duration)]
    length = np.diff(cuts)
    keep = length > 1e-12 * duration
    if not keep.all():  # breakpoints closer than rounding: one bound
        cuts = np.concatenate([cuts[:1], cuts[1:][keep]])
        cuts[-1] = duration
        length = np.diff(cuts)
    per_time = max(rate, least / duration)
    with np.errstate(over="ignore", invalid="ignore"):
        need = np.ceil(length * per_time - 1e-9)
    total = float(np.sum(np.maximum(need, 1)))
    if not total <= most:
        raise ReplayBudgetError(
            f"the motion is too fast to re-simulate: windows short against its growth rate "
            f"({rate:.3g} per time unit, the joints' speed and gravity's) would number "
            f"{total:.3g}, more than {most}")
    n = np.maximum(1, need).astype(int)
    parts = [np.linspace(a, b, k + 1)[:-1] for a, b, k in zip(cuts[:-1], cuts[1:], n,
                                                               strict=True)]
    return np.concatenate([*parts, [duration]])


def replay(model: Model, plan: PlanFunction, edges: Array, peak_acceleration: float, *,
           rtol: float = 1e-9, give_up: float = np.inf) -> Replay:
    """Re-simulate a planned motion in the windows ``edges`` (see the module's docstring).

    Parameters
    ----------
    model : Model
        The robot the torques were planned for.
    plan : callable
        ``plan(t) -> (q, dq, tau)`` at any times of the motion (vectorised).
    edges : ndarray, shape (K + 1,)
        Window bounds (:func:`replay_edges`).
    peak_acceleration : float
        The motion's peak joint acceleration (the drift's scale).
    rtol : float
        The integrator's relative tolerance (absolute: ``rtol`` times the window's scale).
    give_up : float
        A window whose drift passes ``give_up`` times its scale is decided: it stops there,
        its drift the one it reached (so that torques far off do not make the integrator
        crawl through the motions they cause).

    Raises
    ------
    ReplayBudgetError
        Past :data:`BUDGET` evaluations.
    """

    edges = np.asarray(edges, float)
    start, width = edges[:-1], np.diff(edges)
    k = len(width)
    q0, dq0, _ = plan(start)
    q1, _, _ = plan(edges[1:])
    a_ref = peak_acceleration if peak_acceleration > 0 else 1.0
    scale = 0.5 * a_ref * width**2
    alive = np.ones(k, bool)
    stopped: dict[int, tuple[float, str]] = {}
    reached: dict[int, float] = {}  # the drift of a window given up
    nfev = 0
    # each window's time runs over [0, 1] (t = start + sigma * width), its state is the
    # angles' change since its start (so that the tolerance is relative to the window's own
    # motion) and the rates
    y0 = np.concatenate([np.zeros_like(q0), dq0], axis=1).reshape(-1)
    atol = 1e-2 * rtol * np.stack([scale, scale, scale / width, scale / width], axis=1)

    def rhs(sigma: float, y: Array) -> Array:
        nonlocal nfev
        nfev += 1
        if nfev > BUDGET or nfev * k > WINDOW_BUDGET:
            raise ReplayBudgetError(
                f"the re-simulation did not finish within {nfev} evaluations of the "
                f"dynamics of its {k} windows")
        Y = y.reshape(k, 4)
        t = start + sigma * width
        out = np.zeros((k, 4))
        live = alive & np.isfinite(Y).all(axis=1)
        for n in np.flatnonzero(alive & ~live).tolist():
            _stop(n, float(t[n]), "the re-simulated state is not finite")
        idx = np.flatnonzero(live)
        if idx.size:
            q = q0[idx] + Y[idx, :2]
            q_plan, _, tau = plan(t[idx])
            dev = np.abs(_wrap(q - q_plan)).max(axis=1)
            for j in np.flatnonzero(dev > give_up * scale[idx]).tolist():
                w = int(idx[j])
                _stop(w, float(t[w]), f"it drifted {dev[j]:.3g} rad, past {give_up:g} of "
                      "a_peak w^2 / 2")
                reached[w] = float(dev[j])
            keep = alive[idx]
            idx, q, tau = idx[keep], q[keep], tau[keep]
        if idx.size:
            acc, bad = _accelerations(model, q, Y[idx, 2:], tau)
            for j, why in bad.items():
                _stop(int(idx[j]), float(t[idx[j]]), why)
            good = np.array([j not in bad for j in range(idx.size)], bool)
            sel = idx[good]
            out[sel, :2] = Y[sel, 2:]
            out[sel, 2:] = acc[good]
        return (out * width[:, None]).reshape(-1)

    def _stop(i: int, t: float, why: str) -> None:
        alive[i] = False
        stopped.setdefault(i, (t, why))

    # LSODA: Adams while the windows are smooth, BDF where dry friction near rest makes them
    # stiff; the Jacobian is banded (each window's four states, in a row)
    sol = integrate.solve_ivp(rhs, (0.0, 1.0), y0, method="LSODA", rtol=rtol,
                    atol=np.maximum(atol, 1e-300).reshape(-1), lband=3, uband=3,
                    t_eval=[1.0])
    if sol.status != 0 or sol.y.shape[1] == 0:
        y_end = np.full((k, 4), np.nan)
        for n in np.flatnonzero(alive).tolist():
            _stop(n, float(start[n]), f"the integrator failed: {sol.message}")
    else:
        y_end = sol.y[:, -1].reshape(k, 4)
    err = np.abs(_wrap(q0 + y_end[:, :2] - q1)).max(axis=1)
    drift = np.where(alive & np.isfinite(err), err, np.inf)
    for w, d in reached.items():
        drift[w] = d
    return Replay(edges, drift, scale,
                  tuple((i, t, why) for i, (t, why) in sorted(stopped.items())), nfev)


def _wrap(d: Array) -> Array:
    """Angle differences in ``(-pi, pi]``."""
    return np.asarray((d + math.pi) % (2 * math.pi) - math.pi)


def _accelerations(model: Model, q: Array, dq: Array, tau: Array
                   ) -> tuple[Array, dict[int, str]]:
    """``M(q)^-1 (tau - h(q, dq))`` for states (n, 2), and the states (index: why) where the
    dynamics are not defined (a parallel singularity within the model's tolerance, rods that
    cannot meet)."""
    try:
        return accelerations(model, q, dq, tau), {}
    except DextarError:
        pass
    acc = np.zeros_like(q)
    bad: dict[int, str] = {}
    for i in range(len(q)):  # rare: the windows that left the domain, one by one
        try:
            acc[i] = accelerations(model, q[i:i + 1], dq[i:i + 1], tau[i:i + 1])[0]
        except DextarError as exc:
            bad[i] = str(exc).replace(" at sample 0", "")
    return acc, bad


