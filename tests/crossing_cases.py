"""The crossings of the parallel singularity curve the tests plan (issue 31): a line across
the DexTAR's curve and one across an unequal robot's, both in working mode "+-" from assembly
mode "up" to "down", with a vertical robot's gravity and the pick-and-place's masses (SI).
The cases' model, crossings and path dynamics are computed once and shared (all frozen)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache, cached_property

import numpy as np

import dextar as dx
from dextar.dynamics import Inertia, Model
from dextar.dynamics.crossing import RobotAcrossPath
from dextar.geometry import FiveBar
from dextar.laws.time_optimal import TimeOptimalLaw, solve_time_optimal_law
from dextar.motors import MotorLimits
from dextar.paths import Line
from dextar.trajectory import Crossing, find_crossings


@dataclass(frozen=True)
class Case:
    name: str
    robot: FiveBar
    inertia: Inertia
    start: tuple[float, float]
    end: tuple[float, float]
    peak: float = 0.5

    @property
    def path(self) -> Line:
        return Line(self.start, self.end)

    @cached_property
    def model(self) -> Model:
        return Model(self.robot, self.inertia, "up", tol=0.0)

    @cached_property
    def crossings(self) -> tuple[Crossing, ...]:
        return find_crossings(self.robot, self.path, mode="+-")

    @cached_property
    def dynamics(self) -> RobotAcrossPath:
        return RobotAcrossPath(self.model, self.path, "+-", self.crossings)

    @property
    def motors(self) -> MotorLimits:
        return MotorLimits((self.peak, self.peak))


def _inertia(robot: FiveBar) -> Inertia:
    return Inertia.uniform(robot, proximal_mass=0.03, distal_mass=0.02, effector_mass=0.08,
                           payload=0.05, gravity=(0.0, -9.81), coulomb=(0.02, 0.02),
                           viscous=(0.01, 0.01), coulomb_speed=np.radians(0.01))


DEXTAR = dx.DEXTAR_MM.scaled(1e-3)
UNEQUAL = FiveBar(0.070, 0.080, 0.095, 0.085, 0.060)
CASES = {
    "dextar": Case("dextar", DEXTAR, _inertia(DEXTAR), (-0.015, 0.075), (0.010, 0.020)),
    "unequal": Case("unequal", UNEQUAL, _inertia(UNEQUAL), (-0.020, 0.080), (0.0, 0.020)),
}


@cache
def planned(name: str, grid: int = 400) -> TimeOptimalLaw:
    """The time-optimal law across case ``name`` (cached: the tests share it)."""
    case = CASES[name]
    return solve_time_optimal_law(case.dynamics, motors=case.motors, grid=grid)
