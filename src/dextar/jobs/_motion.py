"""The jobs on one configured motion (``[path]`` and ``[law]``): its law sampled (``dextar
plan``), its torques (``dextar torques``), its tracking by a controlled, perturbed plant
(``dextar simulate``) and the robot as a MuJoCo model (``dextar export mjcf``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..analysis import Analysis, analyze
from ..config import Scenario
from ..dynamics import Model
from ..dynamics.paper import paper_model_limits
from ..laws import Law
from ..output.mjcf import to_mjcf
from ..simulation import ControlResult, simulate_computed_torque
from ..trajectory import Trajectory


@dataclass(frozen=True)
class Planned:
    """A law along the path (``dextar plan``), in the scenario's units.

    Attributes
    ----------
    scenario : Scenario
    law : Law
        With its solver's ``status``, ``success`` and ``message``.
    trajectory : Trajectory
        The law sampled along the path (``[output].samples``).
    """

    scenario: Scenario
    law: Law
    trajectory: Trajectory


def plan(sc: Scenario) -> Planned:
    """The configured law along the path, sampled (the path checked for reach and both
    singularity types first)."""
    law = sc.law()
    return Planned(sc, law, sc.trajectory(law))


@dataclass(frozen=True)
class Torques:
    """A law's exact torques (``dextar torques``).

    Attributes
    ----------
    scenario : Scenario
    analysis : Analysis
        The trajectory, exact torques, powers, energy, joint forces and the paper's model
        beside them where it applies.
    paper_model_reason : str or None
        Why the paper's simplified model does not apply (None where it does).
    """

    scenario: Scenario
    analysis: Analysis
    paper_model_reason: str | None


def torques(sc: Scenario) -> Torques:
    """The configured law's exact (and paper-model) torques along the path."""
    an = analyze(sc.inputs(), sc.law())
    why = None if an.paper is not None else paper_model_limits(sc.robot, sc.inertia)
    return Torques(sc, an, why)


@dataclass(frozen=True)
class Simulated:
    """A computed-torque tracking simulation (``dextar simulate``).

    Attributes
    ----------
    scenario : Scenario
    trajectory : Trajectory
        The planned motion.
    result : ControlResult
        The plant's motion, torques, errors and the verdict (``status`` 0: followed within
        the tolerance; 1: it met a singularity; 2: it left the tolerance; 3: incomplete,
        the integration stopped by its step budget).
    control : dict
        The controller's settings in run units (``[control]``), the tolerance the one used
        (``tolerance``, run length unit, and ``tolerance_mm``: the default's value where the
        config gives none).
    """

    scenario: Scenario
    trajectory: Trajectory
    result: ControlResult
    control: dict[str, Any]


def simulate(sc: Scenario) -> Simulated:
    """Track the configured motion with computed torque on the config's model, the plant's
    masses off by ``[control].mass_error`` and carrying ``[control].payload`` unknown to the
    controller."""
    tr = sc.trajectory()
    c = sc.control
    plant = sc.inertia.scaled_masses(1.0 + c["mass_error"])
    plant = plant.with_(payload=plant.payload + c["payload"])
    res = simulate_computed_torque(
        tr, Model(sc.robot, sc.inertia, tr.assembly), Model(sc.robot, plant, tr.assembly),
        natural_frequency=c["natural_frequency"], damping=c["damping"],
        torque_limit=c["torque_limit"], initial_error=c["initial_error"],
        tolerance=c["tolerance"], time_s=sc.units.time_s, length_mm=sc.units.length_mm)
    used = res.tolerance if res.tolerance is not None else c["tolerance"]
    c = {**c, "tolerance": used,
         "tolerance_mm": None if used is None else used * sc.units.length_mm}
    return Simulated(sc, tr, res, c)


def mjcf(sc: Scenario, units: str) -> str:
    """The robot as a MuJoCo model (XML) in the scenario's units, with a keyframe ``start``
    at the motion's first sample; ``units`` names them in the file's first comment."""
    tr = sc.trajectory(samples=2)
    return to_mjcf(sc.model(tr.assembly), start=(tr.q[0], tr.dq[0]), units=units)
