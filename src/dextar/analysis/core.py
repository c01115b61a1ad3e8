"""A run's analysis: the trajectory, exact torques, the paper's model beside them, the energy
comparisons of the paper's Figs. 6 and 7, and the validation residuals (power balance and
forward re-simulation). It takes explicit :class:`RunInputs`, never a config."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._arrays import Array
from ..dynamics import (
    Inertia,
    Model,
    Reactions,
    TorqueResult,
    inverse_dynamics,
    kinetic_energy,
    trajectory_torques,
)
from ..dynamics.exact import task_inverse_dynamics
from ..dynamics.paper import (
    PaperModel,
    base_angle,
    effector_energy_const_beta,
    effector_energy_fd,
    paper_model,
    paper_model_limits,
    torque_error,
    triangle_energies,
)
from ..errors import DextarError, NumericalError
from ..geometry import FiveBar
from ..kinematics import inverse_kinematics
from ..kinematics.checker import DEFAULT_TOLERANCES, Tolerances
from ..laws import Law
from ..paths import Path
from ..simulation.replay import replay, replay_edges
from ..trajectory import Trajectory, path_motion, sample_trajectory
from ..units import Units

if TYPE_CHECKING:
    from ..simulation.replay import Replay


@dataclass(frozen=True)
class RunInputs:
    """What a run's analysis is computed from (built by the config layer).

    Attributes
    ----------
    robot, robot_mm : FiveBar
        The geometry in run units and in mm.
    path : Path
        The path in run units; ``path_spec`` describes it as configured (mm, degrees).
    mode, assembly : str
        Working and assembly modes.
    inertia : Inertia
        Masses, friction and gravity in run units.
    units : Units
        The run's unit system.
    samples : int
        Samples written.
    law_type : str
        The configured law's name; ``law_values`` its config keys (config units).
    beta0_time, fig7_distal_mass_ratio, fig7_lambda : float
        The paper's model settings (``[paper]``).
    """

    robot: FiveBar
    robot_mm: FiveBar
    path: Path
    path_spec: dict[str, Any]
    mode: str
    assembly: str
    inertia: Inertia
    units: Units
    samples: int = 1001
    law_type: str = "optimal"
    law_values: dict[str, Any] = field(default_factory=dict)
    tolerances: Tolerances = DEFAULT_TOLERANCES
    beta0_time: float = 0.5
    fig7_distal_mass_ratio: float = 0.5
    fig7_lambda: float = 0.5
    source: str = ""

    def trajectory(self, law: Law, *, samples: int | None = None,
                   times: Array | None = None) -> Trajectory:
        """``law`` sampled along the path (``samples`` or the run's samples, or ``times``)."""
        return sample_trajectory(self.robot, self.path, law, mode=self.mode,
                                 samples=samples or self.samples, times=times,
                                 tolerances=self.tolerances, units=self.units)

# central differences of order 8 on 9 points, for dT/dt in the power balance
_FD8 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0.0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])


@dataclass(frozen=True)
class PaperComparison:
    """The paper's simplified model beside the exact one, on the same trajectory.

    ``error`` compares the paper's torques with ``reference``, the exact torques without
    what the paper's model leaves out (``leaves_out``: gravity, friction), so that it
    measures the model's simplifications and not what it never claimed to include."""

    model: PaperModel
    beta: Array
    tau: Array
    error: dict[str, float]
    reference: Array
    leaves_out: tuple[str, ...]
    T_exact: Array
    T_fd: Array
    T_approx: Array
    T_S: Array
    T_r: Array
    fig7: dict[str, float]


@dataclass(frozen=True)
class Analysis:
    """A law's trajectory with its exact torques, powers, energy, joint forces and, where it
    applies, the paper's model beside them."""

    inputs: RunInputs
    law: Law
    trajectory: Trajectory
    model: Model
    torques: TorqueResult
    paper: PaperComparison | None

    @property
    def tau(self) -> Array:
        """Exact motor torques, shape (n, 2)."""
        return self.torques.tau

    @property
    def power(self) -> Array:
        """Motor powers ``tau_i qdot_i``, shape (n, 2)."""
        return self.torques.power

    @property
    def energy(self) -> Array:
        """The mechanism's kinetic energy, shape (n,)."""
        return self.torques.kinetic_energy

    @property
    def reactions(self) -> Reactions:
        """Passive-joint forces."""
        return self.torques.reactions

    def reaction_magnitudes(self) -> dict[str, Array]:
        """Magnitudes of the passive-joint forces: at B and C (proximal on distal rod) and
        at P (each distal rod on the end-effector)."""
        r = self.reactions
        return {"force_B": np.linalg.norm(r.B, axis=-1), "force_C": np.linalg.norm(r.C, axis=-1),
                "force_P1": np.linalg.norm(r.P1, axis=-1),
                "force_P2": np.linalg.norm(r.P2, axis=-1)}

    @property
    def units(self) -> Units:
        """The run's unit system."""
        return self.inputs.units


def analyze(inputs: RunInputs, law: Law) -> Analysis:
    """Trajectory and exact torques of ``law`` (with the paper comparison when its model
    applies).

    Raises
    ------
    NumericalError
        When a torque is not finite (parameters that overflow), naming the time.
    """
    tr = inputs.trajectory(law)
    model = Model(inputs.robot, inputs.inertia, tr.assembly, tol=inputs.tolerances.type2)
    torques = trajectory_torques(model, tr.t, tr.q, tr.dq, tr.ddq)
    tau = torques.tau
    if not np.isfinite(tau).all():
        i = int(np.flatnonzero(~np.isfinite(tau).all(axis=1))[0])
        raise NumericalError(f"the torque is not finite at {inputs.units.time_text(tr.t[i])}: "
                             "the parameters overflow double precision")
    applies = paper_model_limits(inputs.robot, inputs.inertia) is None
    paper = _paper(inputs, law, tr, tau) if applies else None
    return Analysis(inputs, law, tr, model, torques, paper)


def _paper(sc: RunInputs, law: Law, tr: Trajectory, tau: Array) -> PaperComparison:
    t0 = sc.beta0_time * law.duration
    mid = sample_trajectory(sc.robot, sc.path, law, mode=sc.mode, times=np.array([t0]))
    beta0 = float(base_angle(sc.robot, mid.q)[0])
    pm = paper_model(sc.robot, sc.inertia, beta0)
    tau_p = pm.torques(tr.q, tr.dq, tr.ddq)
    ine = sc.inertia
    leaves_out = tuple(name for name, present in (("gravity", any(ine.gravity)),
                                                  ("friction", ine.has_friction)) if present)
    if leaves_out:
        # the paper's model is inertial only: compare with the exact inertial torques
        inertial = Model(sc.robot, ine.frictionless(), tr.assembly)
        tau = inverse_dynamics(inertial, tr.q, tr.dq, tr.ddq, t=tr.t)
    m = sc.inertia.point_mass
    T_exact = 0.5 * m * np.sum(tr.dP**2, axis=-1)
    T_fd = effector_energy_fd(sc.robot, m, tr.t, tr.q)
    T_approx = effector_energy_const_beta(sc.robot, m, beta0, tr.q, tr.dq)
    ratio, lam = sc.fig7_distal_mass_ratio, sc.fig7_lambda
    mL = ratio * m
    JL = mL * sc.robot.L1**2 / 2
    T_S, T_r = triangle_energies(sc.robot, mL, JL, lam, tr.q, tr.dq, tr.dP)
    return PaperComparison(pm, base_angle(sc.robot, tr.q), tau_p, torque_error(tau, tau_p),
                           tau, leaves_out, T_exact, T_fd, T_approx, T_S, T_r,
                           {"distal_mass": mL, "JL": JL, "lambda": lam})


def power_balance_times(law: Law, interior: int = 201, rate: float = 0.0
                        ) -> tuple[Array, float]:
    """Times for the power balance and the finite-difference step ``h``: ``interior`` times
    (at most), each at least ``5 h`` from the ends and from every breakpoint of the law (where
    its acceleration jumps and the energy is not smooth). ``h`` is at most ``1e-3`` of the
    duration, a twentieth of the shortest piece and ``0.01 / rate`` (``rate``: the joints'
    largest speed, rad per time unit: the energy changes on that scale; a 20-turn arc in
    1000 steps was 5e-4 off by the differences' own error)."""
    T = law.duration
    cuts = np.concatenate([[0.0], law.breakpoints(), [T]])
    gap = float(np.diff(cuts).min())
    h = min(1e-3 * T, 0.05 * gap, 0.01 / rate if rate > 0 else np.inf)
    if len(cuts) - 1 > interior:  # one time in the middle of each of the longest pieces
        keep = np.sort(np.argsort(-np.diff(cuts))[:interior])
        return 0.5 * (cuts[keep] + cuts[keep + 1]), h
    per = max(1, interior // (len(cuts) - 1))
    t = [np.linspace(a + 5 * h, b - 5 * h, per) for a, b in zip(cuts[:-1], cuts[1:], strict=True)]
    return np.concatenate(t), h


def power_balance_residual(an: Analysis, *, interior: int = 201,
                           torques: Inertia | None = None) -> float:
    """``max |tau . qdot - dT/dt| / max |tau . qdot|`` (dimensionless): the smallest of
    :func:`power_balance_residuals` (see there)."""
    return min(power_balance_residuals(an, interior=interior, torques=torques))


#: Residuals that differ by more than this factor between the differences' steps measure
#: the differences, not the torques (a torque error gives the same residual at every step).
STEP_DEPENDENCE = 4.0


def power_balance_residuals(an: Analysis, *, interior: int = 201,
                            torques: Inertia | None = None) -> tuple[float, float, float]:
    """``max |tau . qdot - dT/dt| / max |tau . qdot|`` (dimensionless) at the differences'
    steps ``h``, ``h / 4`` and ``h / 16``, on up to ``interior``
    times, with ``dT/dt`` from an 8th-order central difference of the exact energy along the
    law and the torques of the inertial model (gravity and friction off: they are not part of
    ``dT/dt``). Times keep clear of the law's breakpoints, where the energy is not smooth.
    ``torques``: the torques of another inertia (a wrong model, to see the check fail)."""
    sc, law = an.inputs, an.law
    t, h = power_balance_times(law, interior, float(np.abs(an.trajectory.dq).max()))
    model = Model(sc.robot, sc.inertia.frictionless(), an.trajectory.assembly)
    torque_model = (model if torques is None else
                    Model(sc.robot, torques.frictionless(), an.trajectory.assembly))
    tr = sample_trajectory(sc.robot, sc.path, law, mode=sc.mode, times=t)
    power = np.sum(inverse_dynamics(torque_model, tr.q, tr.dq, tr.ddq) * tr.dq, axis=-1)
    scale = np.abs(power).max()
    # the differences' own error falls as h^8: of h, h / 4 and h / 16, the smallest residual
    # (a torque error does not depend on h). An optimal law with dry friction over 90 s has a
    # boundary layer of a few tenths of a second at its end: 4.9 at h = 0.09 s, 1.05e-5 at
    # h / 4 (the run said 'the torques do not match'), 5.4e-10 at h / 16, 2e-9 and 8e-9 at
    # h / 64 and h / 256 (rounding)
    out: list[float] = []
    for step in (h, 0.25 * h, 0.0625 * h):
        rate = np.zeros_like(t)
        for k, c in enumerate(_FD8):
            if c:
                tk = sample_trajectory(sc.robot, sc.path, law, mode=sc.mode,
                                       times=t + (k - 4) * step)
                rate += c * kinetic_energy(model, tk.q, tk.dq)
        rate /= step
        out.append(float(np.abs(power - rate).max() / scale))
    return out[0], out[1], out[2]


def torque_limit_ratio(an: Analysis) -> float | None:
    """Largest ``|tau_i| / limit_i`` over the written samples for a law planned under torque
    limits (None for other laws)."""
    limit = getattr(an.law, "torque_limit", None)
    if limit is None:
        return None
    return float((np.abs(an.tau) / np.asarray(limit)).max())


#: The forward re-simulation's threshold on ``drift / (a_peak w^2 / 2)`` per window: the
#: re-simulated accelerations' error as a fraction of the motion's peak joint acceleration.
#: Measured (``python benchmarks/bench_checks.py``): right torques give 6e-11 (the paper's
#: example), 3e-11 (``line_si.toml``), 3e-10 (``time_optimal_si.toml``, 400 windows),
#: 2.5e-10 (a 20-turn arc with dry friction, 107 windows), 6e-10 and 5e-10 (2 s and 60 s
#: lines with dry friction and gravity, 27 and 704 windows), 5e-9 (a trapezoid with
#: gravity), at most 3e-8 over 29 random configs; the torques of a model whose masses are
#: 1 % off give 0.009-0.5, 10 % off 0.09-5, gravity or friction left out 0.02-50 (the ratio
#: is about the torques' relative error). 1e-4 catches a torque error of 0.01 % and leaves
#: three decades above the right torques.
REPLAY_TOL = 1e-4

#: The power balance's threshold (``max |tau.qdot - dT/dt| / max |tau.qdot|``): right torques
#: give 3.5e-13 (the paper's example) to 8.5e-11 (38 configs of ``bench_checks.py``: 8th-order
#: differences of the energy); the torques of masses 1 % off give 1e-2.
POWER_BALANCE_TOL = 1e-6


def replay_windows(an: Analysis) -> Array:
    """The forward re-simulation's windows: the law's breakpoints, each window at most
    ``1 / rate`` long with ``rate = max |qdot| + sqrt(|g| / l)`` (the velocity products' and
    gravity's growth rates, 1 per run time unit), at least 20 of them
    (:func:`dextar.simulation.replay.replay_edges`)."""
    inp, tr = an.inputs, an.trajectory
    g = float(np.hypot(*inp.inertia.gravity))
    rate = float(np.abs(tr.dq).max()) + math.sqrt(g / max(inp.robot.l1, inp.robot.l2))
    return replay_edges(an.law.duration, rate, an.law.breakpoints())


def forward_replay(an: Analysis, model: Model | None = None) -> Replay:
    """Re-simulate the motion in windows anchored to the plan
    (:mod:`dextar.simulation.replay`): each window starts at the planned state and runs the
    forward dynamics of ``an.model`` under the torques of ``model`` (default: the run's own,
    the exact inverse dynamics at any time of the law)."""
    inp, law = an.inputs, an.law
    torque_model = model or an.model

    def plan(t: Array) -> tuple[Array, Array, Array]:
        t = np.clip(t, 0.0, law.duration)
        *_, P, dP, ddP = path_motion(inp.path, law, t)
        q = inverse_kinematics(inp.robot, P, inp.mode)
        dq, _, tau = task_inverse_dynamics(torque_model, inp.mode, P, dP, ddP)
        return q, dq, tau

    peak = float(np.abs(an.trajectory.ddq).max())
    return replay(an.model, plan, replay_windows(an), peak, give_up=1e3 * REPLAY_TOL)


def forward_error(an: Analysis, model: Model | None = None) -> dict[str, Any]:
    """The forward re-simulation in windows anchored to the plan (:func:`forward_replay`) as
    the summary reports it: per window its bounds and drift (rad), the largest drift, its
    ratio to ``a_peak w^2 / 2`` against :data:`REPLAY_TOL`, ``passed``, and the windows
    that stopped early (a singularity met: drift ``null``)."""
    u = an.units
    try:
        r = forward_replay(an, model)
    except DextarError as exc:  # reported, not raised
        return {"passed": False, "message": f"the re-simulation could not run: {exc}",
                "threshold": REPLAY_TOL}
    ratio = r.ratio
    worst = int(np.argmax(np.where(np.isnan(ratio), np.inf, ratio)))
    passed = bool(np.all(ratio <= REPLAY_TOL))
    lo, hi = float(r.edges[worst]), float(r.edges[worst + 1])
    stops = {i: (t, why) for i, t, why in r.stopped}
    if passed:
        message = (f"every window within {REPLAY_TOL:g} of the peak acceleration (worst: "
                   f"window {worst}, {ratio[worst]:.3g})")
    elif worst in stops:
        t, why = stops[worst]
        message = (f"the re-simulation of window {worst} ({u.time_text(lo)} to "
                   f"{u.time_text(hi)}) stopped at {u.time_text(t)}: {why}: the torques do "
                   "not give the motion back")
    else:
        message = (f"window {worst} ({u.time_text(lo)} to {u.time_text(hi)}) drifts "
                   f"{r.drift[worst]:.3g} rad, {ratio[worst]:.3g} of the peak acceleration's "
                   f"a w^2 / 2, above {REPLAY_TOL:g}: the torques do not give the motion back")
    finite = [float(v) if np.isfinite(v) else None for v in r.drift]
    return {"passed": passed, "message": message, "windows": len(r.drift),
            "window_starts": [float(v) for v in r.edges[:-1]], "drift_rad": finite,
            "max_drift_rad": (float(np.max(r.drift)) if np.isfinite(r.drift).all()
                              else None),
            "max_drift_ratio": float(ratio[worst]) if np.isfinite(ratio[worst]) else None,
            "worst_window": worst, "threshold": REPLAY_TOL,
            "peak_acceleration": float(np.abs(an.trajectory.ddq).max()),
            "stopped": [{"window": i, "t": t, "why": why} for i, t, why in r.stopped],
            "rhs_evaluations": r.nfev}
