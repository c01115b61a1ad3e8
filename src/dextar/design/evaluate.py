"""One design evaluated on the task: the program planned on that robot, its metrics, or the
reason it fails.

Everything a worker needs travels in a :class:`Task` (picklable, SI), so a design's row
depends only on the task and the design's lengths: the same on any worker, in any chunk.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..dynamics import Inertia, Model, RobotAlongPath, Rod, inverse_dynamics
from ..errors import DextarError
from ..geometry import FiveBar
from ..kinematics import jacobian, workspace_map
from ..kinematics.checker import Tolerances, pose_distances
from ..kinematics.workspace import inverse_condition
from ..laws import Law, LawRequest, law_type
from ..motors import MotorLimits
from ..paths import Path
from ..program import Move, ProgramRequest, ProgramResult, sizing
from ..trajectory import check_path, sample_trajectory
from ..units import SI
from .space import LENGTHS, METRICS

ndimage = lazy_module("scipy.ndimage")

#: Grid of the workspace map behind ``workspace_area_mm2`` (points per side).
AREA_RESOLUTION = 61
#: Setpoint rate of the plans a sweep makes (the sizing integrates over them).
SWEEP_RATE_HZ = 500.0


@dataclass(frozen=True)
class Task:
    """What a design is evaluated on (SI unless named).

    Attributes
    ----------
    moves : tuple of Move
    start : (float, float)
        The start point (m).
    working_mode, assembly : str
    motors : MotorLimits, optional
    rms_limit : (float, float), optional
    template : Inertia
        Effector, payload, rotors, friction and gravity, and the rods of ``robot``.
    mass_per_length : (float, float), optional
        kg/m of the proximal and distal rods (uniform rods); None: each rod of the template
        keeps its linear density and its shape on another length (see :func:`inertia_of`).
    grid : int
        Time-optimal grid of each move.
    tolerances : Tolerances
    path : Path, optional
        A ``dextar run`` task: one path (SI) instead of moves.
    law : Law, optional
        Its law when it does not depend on the robot (computed once for the sweep).
    law_type : str, optional
        Its law's name when it does (``time-optimal``: planned on each design).
    law_values : mapping, optional
        That law's keys (SI).
    samples : int
        Samples along a run task's path.
    robot : FiveBar, optional
        The task's own robot (m), whose rods the template holds.
    """

    moves: tuple[Move, ...]
    start: tuple[float, float]
    working_mode: str
    assembly: str
    motors: MotorLimits | None
    rms_limit: tuple[float, float] | None
    template: Inertia
    mass_per_length: tuple[float, float] | None
    grid: int
    tolerances: Tolerances
    path: Path | None = None
    law: Law | None = None
    law_type: str | None = None
    law_values: Mapping[str, Any] | None = None
    samples: int = 201
    robot: FiveBar | None = None

    @property
    def kind(self) -> str:
        """``"program"`` or ``"run"`` (one path and law)."""
        return "program" if self.path is None else "run"


def footprint_mm(lengths: Sequence[float]) -> float:
    """``max(l1 + L1, l2 + L2) + d / 2`` (mm): the half-width a robot sweeps from its middle."""
    l1, l2, L1, L2, d = (float(v) for v in lengths)
    return max(l1 + L1, l2 + L2) + 0.5 * d


def inertia_of(task: Task, robot: FiveBar) -> Inertia:
    """The task's inertia on ``robot`` (m): uniform rods of ``mass_per_length`` when given;
    otherwise each rod of the task's robot scaled to its new length ``L' = k L`` keeping its
    linear density and shape: mass ``k m``, centre of mass at the same fraction of the rod
    (``k c``), inertia about the centre ``k^3 I`` (it scales as ``m L^2``). The effector, the
    payload and the rotors stay as given."""
    if task.mass_per_length is not None:
        mp, md = task.mass_per_length
        return task.template.with_(
            proximal=(Rod.uniform(mp * robot.l1, robot.l1),
                      Rod.uniform(mp * robot.l2, robot.l2)),
            distal=(Rod.uniform(md * robot.L1, robot.L1), Rod.uniform(md * robot.L2, robot.L2)))
    if task.robot is None:
        return task.template
    old = task.robot

    def scaled(rod: Rod, k: float) -> Rod:
        return Rod(rod.mass * k, rod.com * k, rod.inertia * k**3)

    p, d = task.template.proximal, task.template.distal
    return task.template.with_(
        proximal=(scaled(p[0], robot.l1 / old.l1), scaled(p[1], robot.l2 / old.l2)),
        distal=(scaled(d[0], robot.L1 / old.L1), scaled(d[1], robot.L2 / old.L2)))


def usable_area_mm2(robot_mm: FiveBar, mode: str, start_mm: Sequence[float],
                    tol: float) -> float:
    """Area (mm^2) of the region of working mode ``mode`` around the task's start that the
    end-effector reaches without meeting a parallel singularity (within ``tol``): the
    connected cells of the workspace map holding the start, on a grid of
    :data:`AREA_RESOLUTION` points per side."""
    ws = workspace_map(robot_mm, mode, resolution=AREA_RESOLUTION)
    free = ws.reachable & (np.abs(ws.type2) > tol)
    x, y = ws.x, ws.y
    i = int(np.argmin(np.abs(y - start_mm[1])))
    j = int(np.argmin(np.abs(x - start_mm[0])))

    labels, _ = ndimage.label(free)
    lab = labels[i, j]
    if lab == 0:  # the start's cell is on the boundary of the grid's region: its neighbours
        near = labels[max(i - 1, 0):i + 2, max(j - 1, 0):j + 2]
        lab = int(near.max())
        if lab == 0:
            return 0.0
    return float((labels == lab).sum() * (x[1] - x[0]) * (y[1] - y[0]))


def _unplanned_row(lengths: Sequence[float], reason: str) -> dict[str, Any]:
    """A design's row before (or without) its plan: its lengths, not feasible, ``reason``, its
    footprint and no other metric."""
    row: dict[str, Any] = {k: float(v) for k, v in zip(LENGTHS, lengths, strict=True)}
    row.update({"feasible": False, "reason": reason, **dict.fromkeys(METRICS)})
    row["footprint_mm"] = footprint_mm(lengths)
    return row


def evaluate_design(task: Task, lengths: Sequence[float]) -> dict[str, Any]:
    """The row of one design ``(l1, l2, L1, L2, d)`` (mm): its lengths, ``feasible``,
    ``reason`` (empty when feasible) and the metrics of :data:`~dextar.design.space.METRICS`
    (None where the plan failed before they exist)."""
    row = _unplanned_row(lengths, "")
    try:
        robot_mm = FiveBar(*(float(v) for v in lengths))
    except DextarError as exc:
        row["reason"] = f"geometry: {exc}"
        return row
    robot = robot_mm.scaled(1e-3)
    try:
        res = _plan(task, robot)
    except DextarError as exc:
        row["reason"] = str(exc)
        return row
    size = sizing(res)
    mA, mD = size.motors
    d = pose_distances(robot, res.q, res.P)
    J = jacobian(robot, res.q, res.P, tol=0.0)
    dex = inverse_condition(J[:, 0, 0], J[:, 0, 1], J[:, 1, 0], J[:, 1, 1])
    row.update({
        "cycle_time_s": res.cycle_time_s,
        "min_type1_distance": float(d.type1.min()), "min_type2_distance": float(d.type2.min()),
        "gci": float(np.mean(dex)),
        "peak_torque_A_Nm": mA.peak_torque_Nm, "peak_torque_D_Nm": mD.peak_torque_Nm,
        "rms_torque_A_Nm": mA.rms_torque_Nm, "rms_torque_D_Nm": mD.rms_torque_Nm,
        "workspace_area_mm2": usable_area_mm2(robot_mm, task.working_mode,
                                              [1e3 * v for v in task.start],
                                              task.tolerances.type2)})
    if size.violations:
        v = size.violations[0]
        where = f" at t = {v.t_s:.4g} s in move {v.move}" if v.t_s is not None else ""
        row["reason"] = (f"motors exceeded: motor {v.motor} {v.quantity} "
                         f"{v.value:.4g} above {v.limit:.4g}{where}")
        return row
    for k in METRICS:
        if not math.isfinite(float(row[k])):
            row["reason"] = f"{k} is not finite"
            return row
    row["feasible"] = True
    return row


def _plan(task: Task, robot: FiveBar) -> ProgramResult:
    """The task on ``robot`` (m): its program planned, or its path sampled under its law (a
    one-move result with the same fields)."""
    inertia = inertia_of(task, robot)
    if task.path is None:
        return ProgramRequest(robot, inertia, task.moves, task.start, task.working_mode,
                              task.assembly, task.motors, task.rms_limit, SWEEP_RATE_HZ,
                              task.grid, task.tolerances).plan()
    model = Model(robot, inertia, task.assembly, tol=task.tolerances.type2)
    law = task.law
    if law is None:  # a law planned on the robot (time-optimal)
        assert task.law_type is not None
        check_path(robot, task.path, mode=task.working_mode, tolerances=task.tolerances,
                   units=SI)
        dyn = RobotAlongPath(model, task.path, task.working_mode, SI)
        law = law_type(task.law_type).build(LawRequest(
            task.path, task.law_values or {}, inertia.point_mass, dyn, SI, task.motors))
    tr = sample_trajectory(robot, task.path, law, mode=task.working_mode,
                           samples=task.samples, tolerances=task.tolerances, units=SI)
    tau = inverse_dynamics(model, tr.q, tr.dq, tr.ddq, t=tr.t)
    return ProgramResult([], float(law.duration), tr.t, np.zeros(len(tr.t), int), tr.P, tr.q,
                         tr.dq, tr.ddq, tau, task.motors, task.rms_limit)


def evaluate_chunk(task: Task, designs: Array, first: int) -> list[dict[str, Any]]:
    """Rows of the designs (m, 5) numbered from ``first`` (the unit of work of a sweep). A
    design whose evaluation raises an unexpected error is a row with that error as its
    reason: the sweep never stops for one design, and the error shows in the file."""
    rows = []
    for k, lengths in enumerate(np.asarray(designs, float)):
        try:
            row = evaluate_design(task, lengths)
        except Exception as exc:  # noqa: BLE001 - kept as the design's reason
            row = _unplanned_row(lengths, f"internal error: {type(exc).__name__}: {exc}")
        rows.append({"design": first + k, **row})
    return rows


def evaluate_path(task: Task, lengths: Sequence[float]) -> Array:
    """The end-effector's path (n, 2) in mm of the task on one design (to draw it)."""
    robot = FiveBar(*(float(v) for v in lengths)).scaled(1e-3)
    return np.asarray(_plan(task, robot).P * 1e3)
