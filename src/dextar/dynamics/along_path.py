"""The exact closed-chain dynamics along a path, for laws planned under motor limits.

:class:`RobotAlongPath` implements :class:`dextar.laws.constraints.PathDynamics`: the
coefficients ``a = M q'``, ``b = M q'' + c(q, q')``, ``g`` of the path dynamics on a grid of
arc lengths (from the joint path ``q(s)`` of the inverse kinematics), and the torque and speed
ratios of a law through the exact model with gravity and friction.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from .._arrays import Array
from ..geometry import assembly_mode_name
from ..kinematics import assembly_mode, direct_kinematics, inverse_kinematics
from ..laws import Law, UniformLaw
from ..laws.constraints import JointSamples, PathCoefficients
from ..laws.time_optimal import TimeOptimalLaw, solve_time_optimal_law
from ..motors import MotorLimits
from ..paths import Path
from ..trajectory import JointLine, path_motion, sample_trajectory
from ..units import Units
from .exact import Model, inverse_dynamics, path_dynamics, task_inverse_dynamics


@dataclass(frozen=True)
class RobotAlongPath:
    """A robot model following ``path`` in working mode ``mode``.

    ``units`` only serves the words of an error (points in mm, times in s). ``checked``:
    run the geometry checker on the coefficients' grid (False when the path was checked
    already, e.g. by :func:`dextar.trajectory.check_path`).
    """

    model: Model
    path: Path
    mode: str = "+-"
    units: Units | None = None
    checked: bool = True

    @property
    def length(self) -> float:
        """The path's arc length."""
        return float(self.path.length)

    def coefficients(self, s: Array) -> PathCoefficients:
        """The path dynamics at the arc lengths ``s`` (N + 1,), from 0 to the length."""
        S = self.path.length
        # a unit-speed law makes t = s, qdot = q', qddot = q''
        jp = sample_trajectory(self.model.robot, self.path, UniformLaw(S, S), mode=self.mode,
                               times=np.asarray(s, float), units=self.units,
                               checked=self.checked, at_arc_length=True)
        ine = self.model.inertia
        a, b, g = path_dynamics(self._model(jp.assembly), jp.q, jp.dq, jp.ddq)
        return PathCoefficients(jp.t, jp.P, a, b, g, jp.dq, np.array(ine.coulomb, float),
                                np.array(ine.viscous, float), jp.ddq, ine.coulomb_speed)

    def _model(self, assembly: str) -> Model:
        """The model in the assembly mode the path's poses are in (its own tolerance)."""
        return self.model if assembly == self.model.assembly else replace(self.model,
                                                                          assembly=assembly)

    def samples(self, law: Law, times: Array) -> JointSamples:
        """``law`` at ``times`` through the exact model (the path was checked by
        :meth:`coefficients`; the angles are not unwrapped: the model needs only their sines
        and cosines)."""
        t = np.asarray(times, float)
        P, dP, ddP = path_motion(self.path, law, t)[6:]
        dq, ddq, tau = task_inverse_dynamics(self._model(self._assembly), self.mode, P, dP,
                                             ddP)
        return JointSamples(tau, dq, ddq, t)

    @cached_property
    def _assembly(self) -> str:
        """The assembly mode of the path's poses, named by its start's (a checked path
        crosses no parallel singularity: every pose of it is in the same one)."""
        robot = self.model.robot
        P = self.path.position(np.array([self.path.p0]))
        return assembly_mode_name(int(assembly_mode(robot, inverse_kinematics(robot, P,
                                                                              self.mode),
                                                    P)[0]))


def time_optimal_law(model: Model, path: Path, *,
                     torque_limit: tuple[float, float] | None = None,
                     speed_limit: tuple[float, float] | None = None,
                     motors: MotorLimits | None = None, mode: str = "+-",
                     grid: int | Array = 400,
                     tol: float = 1e-3, units: Units | None = None) -> TimeOptimalLaw:
    """The fastest rest-to-rest law along ``path`` for ``model`` within the motors' torque
    (and speed) limits; see :func:`dextar.laws.time_optimal.solve_time_optimal_law`."""
    return solve_time_optimal_law(RobotAlongPath(model, path, mode, units),
                                  torque_limit=torque_limit, speed_limit=speed_limit,
                                  motors=motors, grid=grid, tol=tol, units=units)


@dataclass(frozen=True)
class RobotAlongJointLine:
    """A robot model following a straight line in joint space (a joint move): ``q' = u``
    constant, ``q'' = 0``; implements :class:`~dextar.laws.constraints.PathDynamics`."""

    model: Model
    line: JointLine
    units: Units | None = None

    @property
    def length(self) -> float:
        """The joint-space line's length."""
        return float(self.line.length)

    def coefficients(self, s: Array) -> PathCoefficients:
        """The path dynamics at the joint-space lengths ``s`` (N + 1,)."""
        s = np.asarray(s, float)
        q = self.line.at(s)
        u = np.broadcast_to(self.line.direction, q.shape).copy()
        robot, ine = self.model.robot, self.model.inertia
        a, b, g = path_dynamics(self._free, q, u, np.zeros_like(u))
        P = direct_kinematics(robot, q, self.model.assembly)
        return PathCoefficients(s, P, a, b, g, u, np.array(ine.coulomb, float),
                                np.array(ine.viscous, float), np.zeros_like(u),
                                ine.coulomb_speed)

    def samples(self, law: Law, times: Array) -> JointSamples:
        """``law`` at ``times`` through the exact model."""
        s, ds, dds, _ = law.evaluate(times)
        u = self.line.direction
        q, dq, ddq = self.line.at(s), ds[:, None] * u, dds[:, None] * u
        return JointSamples(inverse_dynamics(self._free, q, dq, ddq), dq, ddq,
                            np.asarray(times, float))

    @property
    def _free(self) -> Model:
        """The model without a singularity tolerance: a joint line may pass serial
        singularities, and its parallel-singularity check is the trajectory's."""
        return replace(self.model, tol=0.0)
