"""A run's analysis: the trajectory, exact torques, the paper's model beside them, the energy
comparisons of the paper's Figs. 6 and 7, and the validation residuals (power balance and
forward re-simulation). It takes explicit :class:`RunInputs`, never a config."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

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
from ..dynamics.forward import forward_dynamics, torques_from_samples
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
from ..errors import NumericalError
from ..geometry import FiveBar
from ..kinematics.checker import DEFAULT_TOLERANCES, Tolerances
from ..laws import Law
from ..paths import Path
from ..trajectory import Trajectory, sample_trajectory
from ..units import Units


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


def power_balance_times(law: Law, interior: int = 201) -> tuple[Array, float]:
    """Times for the power balance and the finite-difference step ``h``: ``interior`` times
    (at most), each at least ``5 h`` from the ends and from every breakpoint of the law (where
    its acceleration jumps and the energy is not smooth)."""
    T = law.duration
    cuts = np.concatenate([[0.0], law.breakpoints(), [T]])
    gap = float(np.diff(cuts).min())
    h = min(1e-3 * T, 0.05 * gap)
    if len(cuts) - 1 > interior:  # one time in the middle of each of the longest pieces
        keep = np.sort(np.argsort(-np.diff(cuts))[:interior])
        return 0.5 * (cuts[keep] + cuts[keep + 1]), h
    per = max(1, interior // (len(cuts) - 1))
    t = [np.linspace(a + 5 * h, b - 5 * h, per) for a, b in zip(cuts[:-1], cuts[1:], strict=True)]
    return np.concatenate(t), h


def power_balance_residual(an: Analysis, *, interior: int = 201) -> float:
    """``max |tau . qdot - dT/dt| / max |tau . qdot|`` (dimensionless) on up to ``interior``
    times, with ``dT/dt`` from an 8th-order central difference of the exact energy along the
    law and the torques of the inertial model (gravity and friction off: they are not part of
    ``dT/dt``). Times keep clear of the law's breakpoints, where the energy is not smooth."""
    sc, law = an.inputs, an.law
    t, h = power_balance_times(law, interior)
    model = Model(sc.robot, sc.inertia.frictionless(), an.trajectory.assembly)
    rate = np.zeros_like(t)
    for k, c in enumerate(_FD8):
        if c:
            tr = sample_trajectory(sc.robot, sc.path, law, mode=sc.mode, times=t + (k - 4) * h)
            rate += c * kinetic_energy(model, tr.q, tr.dq)
    rate /= h
    tr = sample_trajectory(sc.robot, sc.path, law, mode=sc.mode, times=t)
    power = np.sum(inverse_dynamics(model, tr.q, tr.dq, tr.ddq) * tr.dq, axis=-1)
    return float(np.abs(power - rate).max() / np.abs(power).max())


def torque_limit_ratio(an: Analysis) -> float | None:
    """Largest ``|tau_i| / limit_i`` over the written samples for a law planned under torque
    limits (None for other laws)."""
    limit = getattr(an.law, "torque_limit", None)
    if limit is None:
        return None
    return float((np.abs(an.tau) / np.asarray(limit)).max())


def forward_error(an: Analysis) -> dict[str, Any]:
    """Re-simulate the motion under the sampled exact torques (cubic-spline interpolated)
    and compare with the trajectory."""
    tr = an.trajectory
    res = forward_dynamics(an.model, torques_from_samples(tr.t, an.tau), tr.q[0], tr.dq[0],
                           tr.t)
    span = np.ptp(tr.q, axis=0)
    span = np.where(span > 0, span, 1.0)
    return {"final_error_relative_to_range": float((np.abs(res.q[-1] - tr.q[-1]) / span).max()),
            "max_error_relative_to_range": float((np.abs(res.q - tr.q).max(axis=0) / span).max()),
            "max_error_rad": float(np.abs(res.q - tr.q).max()),
            "rhs_evaluations": int(res.nfev), "status": res.status, "message": res.message}
