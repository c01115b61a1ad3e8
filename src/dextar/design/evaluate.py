"""One design evaluated on the task: the program planned on that robot, its metrics, or the
reason it fails.

Everything a worker needs travels in a :class:`Task` (picklable, SI), so a design's row
depends only on the task and the design's columns: the same on any worker, in any chunk.

A design is its lengths and, when the sweep varies them, its counterweights and its motor
(:attr:`Task.columns`). With a motor catalogue (:attr:`Task.catalogue`) each design is planned
with catalogue motors on both joints behind a gearbox (:class:`~dextar.motors.Gearmotor`):
their joint-side torque and speed limits (the motor-side speed over the ratio) and their
reflected rotor inertia ``N^2 J_r`` (added to the task's joint-side rotor inertia) enter the
plan, their spin ``N J_r`` the shaking moment. ``motor_choice`` ``"lightest"`` (or
``"cheapest"``) tries the motors from the lightest (cheapest), each with every ratio, and
keeps the first motor with a ratio that fits the task, with its ratio of the shortest cycle
(then of the largest margin to the limits); ``"search"`` plans the motor and ratio the design
names.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..dynamics import Counterweight, Inertia, Model, RobotAlongPath, Rod, inverse_dynamics
from ..dynamics.balancing import shaking_summary_si
from ..errors import (
    AssemblyError,
    DextarError,
    GeometryError,
    InfeasibleError,
    ReachError,
    SingularityError,
)
from ..geometry import FiveBar
from ..kinematics import jacobian, workspace_map
from ..kinematics.checker import Tolerances, pose_distances
from ..kinematics.workspace import inverse_condition
from ..laws import Law, LawRequest, law_type
from ..motors import Catalogue, Gearmotor, MotorLimits
from ..paths import Path
from ..program import Move, ProgramRequest, ProgramResult, Sizing, sizing
from ..trajectory import check_path, sample_trajectory
from ..units import SI
from .space import COUNTERWEIGHTS, LENGTHS, METRICS, MOTOR_COLUMNS, MOTOR_METRICS

ndimage = lazy_module("scipy.ndimage")

#: Grid of the workspace map behind ``workspace_area_mm2`` (points per side).
AREA_RESOLUTION = 61
#: The errors of a plan that do not depend on the motors (a path out of reach, a
#: singularity, a robot that cannot close): a design that meets one with a catalogue motor
#: meets it with every other, so the others are not tried.
GEOMETRIC_ERRORS = (GeometryError, ReachError, AssemblyError, SingularityError)
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
    columns : tuple of str
        What a design holds (:attr:`dextar.design.space.DesignSpace.columns`): the lengths
        (mm), and the counterweights (kg, mm) and the motor's indices when the sweep varies
        them.
    catalogue : Catalogue, optional
        Motors and gear ratios to plan each design with (``motors`` then holds the drives'
        acceleration, jerk and torque-rate limits only; ``rms_limit`` is the motors').
    motor_choice : str
        ``"lightest"``, ``"cheapest"`` or ``"search"`` (see the module doc).
    cycle : str
        A program task's ``[program].cycle``: ``"as-planned"``, or ``"fit-rms"`` (each
        design's cycle the shortest within its motors' RMS ratings).
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
    columns: tuple[str, ...] = LENGTHS
    catalogue: Catalogue | None = None
    motor_choice: str = "lightest"
    cycle: str = "as-planned"

    @property
    def kind(self) -> str:
        """``"program"`` or ``"run"`` (one path and law)."""
        return "program" if self.path is None else "run"


def footprint_mm(lengths: Sequence[float]) -> float:
    """``max(l1 + L1, l2 + L2) + d / 2`` (mm): the half-width a robot sweeps from its middle."""
    l1, l2, L1, L2, d = (float(v) for v in lengths)
    return max(l1 + L1, l2 + L2) + 0.5 * d


def inertia_of(task: Task, robot: FiveBar, design: object = None) -> Inertia:
    """The task's inertia on ``robot`` (m): uniform rods of ``mass_per_length`` when given;
    otherwise each rod of the task's robot scaled to its new length ``L' = k L`` keeping its
    linear density and shape: mass ``k m``, centre of mass at the same fraction of the rod
    (``k c``), inertia about the centre ``k^3 I`` (it scales as ``m L^2``). The effector, the
    payload and the rotors stay as given. The proximal rods carry the task's counterweights
    (which do not scale with the rods), or the design's when ``design`` (its columns, or its
    row) varies them; a row that names a catalogue motor adds its reflected rotor inertia."""
    base = task.template
    x = None if design is None else design_values(task, design)
    cws = base.counterweights if x is None else counterweights_of(task, x)
    if base.has_counterweights:  # the rods scale without their counterweights
        base = base.with_counterweights((Counterweight(), Counterweight()))
    if task.mass_per_length is not None:
        mp, md = task.mass_per_length
        out = base.with_(
            proximal=(Rod.uniform(mp * robot.l1, robot.l1),
                      Rod.uniform(mp * robot.l2, robot.l2)),
            distal=(Rod.uniform(md * robot.L1, robot.L1), Rod.uniform(md * robot.L2, robot.L2)))
    elif task.robot is None:
        out = base
    else:
        old = task.robot

        def scaled(rod: Rod, k: float) -> Rod:
            return Rod(rod.mass * k, rod.com * k, rod.inertia * k**3)

        p, d = base.proximal, base.distal
        out = base.with_(
            proximal=(scaled(p[0], robot.l1 / old.l1), scaled(p[1], robot.l2 / old.l2)),
            distal=(scaled(d[0], robot.L1 / old.L1), scaled(d[1], robot.L2 / old.L2)))
    out = out.with_counterweights(cws)
    if isinstance(design, Mapping) and task.catalogue is not None and design.get("motor"):
        gm = Gearmotor(task.catalogue.motor(str(design["motor"])), float(design["gear_ratio"]))
        out = with_gearmotor(out, gm)
    return out


def design_values(task: Task, design: object) -> dict[str, float]:
    """A design's columns by name: ``design`` is a sequence of :attr:`Task.columns` (or of
    the lengths alone, when the task has no other column) or a mapping holding them (a
    row)."""
    if isinstance(design, Mapping):
        return {k: float(design[k]) for k in task.columns}
    values = [float(v) for v in np.asarray(design, float).reshape(-1)]
    if len(values) != len(task.columns):
        raise ValueError(f"a design of this task holds {len(task.columns)} values "
                         f"({', '.join(task.columns)}), got {len(values)}")
    return dict(zip(task.columns, values, strict=True))


def counterweights_of(task: Task, x: Mapping[str, float]) -> tuple[Counterweight,
                                                                   Counterweight]:
    """The proximal counterweights of a design (SI): its columns when it varies them (each
    counterweight's inertia scaled with its mass from the task's, whose shape it keeps),
    else the task's."""
    base = task.template.counterweights
    if COUNTERWEIGHTS[0] not in x:
        return base
    out = []
    for k in (0, 1):
        m = x[COUNTERWEIGHTS[k]]
        r = 1e-3 * x[COUNTERWEIGHTS[2 + k]]
        b = base[k]
        inertia = b.inertia * m / b.mass if b.mass > 0 else 0.0
        out.append(Counterweight(m, r, inertia if m > 0 else 0.0))
    return out[0], out[1]


def with_gearmotor(inertia: Inertia, gm: Gearmotor) -> Inertia:
    """``inertia`` with the gearmotor's reflected rotor inertia added on both joints."""
    j = gm.reflected_inertia
    return inertia.with_(rotor=(inertia.rotor[0] + j, inertia.rotor[1] + j))


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


def _unplanned_row(task: Task, x: Mapping[str, float], reason: str) -> dict[str, Any]:
    """A design's row before (or without) its plan: its columns, not feasible, ``reason``, no
    motor, its footprint and no other metric."""
    row: dict[str, Any] = dict(x)
    row.update({"feasible": False, "reason": reason, "motor": "", **dict.fromkeys(METRICS)})
    row["footprint_mm"] = footprint_mm([x[k] for k in LENGTHS])
    return row


@dataclass(frozen=True)
class _Attempt:
    """One plan of a design: with which gearmotor (None: the task's motors), the plan, its
    sizing."""

    gearmotor: Gearmotor | None
    result: ProgramResult
    size: Sizing

    @property
    def worst_ratio(self) -> float:
        """The largest ratio of a peak, RMS or speed to its limit (0 without limits)."""
        vals = [v for m in self.size.motors for v in (
            m.peak_torque_ratio, m.rms_torque_ratio, m.peak_speed_ratio) if v is not None]
        return max(vals, default=0.0)


def _candidates(task: Task, x: Mapping[str, float]) -> list[list[Gearmotor | None]]:
    """The gearmotors to try, in groups: the first group with one that fits is kept (one
    group of None: the task's own motors)."""
    cat = task.catalogue
    if cat is None:
        return [[None]]
    if task.motor_choice == "search":
        i, j = int(x[MOTOR_COLUMNS[0]]), int(x[MOTOR_COLUMNS[1]])
        return [[Gearmotor(cat.motors[i], cat.ratios[j])]]
    return [[Gearmotor(m, r) for r in cat.ratios] for m in cat.ordered(task.motor_choice)]


def _attempt(task: Task, robot: FiveBar, inertia: Inertia, gm: Gearmotor | None) -> _Attempt:
    if gm is None:
        res = _plan(task, robot, inertia, task.motors, task.rms_limit)
    else:
        rms = gm.rms_torque
        res = _plan(task, robot, with_gearmotor(inertia, gm), gm.limits(task.motors),
                    (rms, rms))
    return _Attempt(gm, res, sizing(res))


def _choose(task: Task, robot: FiveBar, inertia: Inertia, x: Mapping[str, float]
            ) -> tuple[_Attempt | None, str]:
    """The plan of the design with its motors (see the module doc), and the reason it fails
    (empty when it fits)."""
    last: _Attempt | None = None
    errors: list[str] = []
    for group in _candidates(task, x):
        tried: list[_Attempt] = []
        for gm in group:
            try:
                tried.append(_attempt(task, robot, inertia, gm))
            except GEOMETRIC_ERRORS:  # the same with any motor
                raise
            except DextarError as exc:  # no motion (or cycle) within this gearmotor's limits
                if gm is None:
                    raise
                errors.append(f"{gm.label}: {exc}")
        fits = [a for a in tried if a.size.fits]
        if fits:
            return min(fits, key=lambda a: (a.result.cycle_time_s, a.worst_ratio)), ""
        for a in tried:  # the closest to fitting so far
            if last is None or a.worst_ratio < last.worst_ratio:
                last = a
    if last is None:  # no gearmotor of the catalogue has a motion within its limits
        assert task.catalogue is not None and errors
        if len(errors) == 1:
            raise InfeasibleError(errors[0])
        raise InfeasibleError(f"no motor of {task.catalogue.source} moves the task within "
                              f"its limits at any ratio; the last tried, {errors[-1]}")
    said = last.size.violations[0].text()
    if task.catalogue is None or task.motor_choice == "search":
        return last, f"motors exceeded: {said}"
    assert last.gearmotor is not None
    return last, (f"motors exceeded: no motor of {task.catalogue.source} fits at any ratio; "
                  f"the closest, {last.gearmotor.label}: {said}")


def evaluate_design(task: Task, design: object) -> dict[str, Any]:
    """The row of one design (its columns, :attr:`Task.columns`: the lengths ``(l1, l2,
    L1, L2, d)`` in mm, then any counterweights and motor indices; or a row holding them):
    its columns, ``feasible``, ``reason`` (empty when feasible), ``motor`` (the chosen
    catalogue motor's name, empty without one) and the metrics of
    :data:`~dextar.design.space.METRICS` (None where the plan failed before they exist)."""
    return _evaluate(task, design)[0]


def _evaluate(task: Task, design: object) -> tuple[dict[str, Any], ProgramResult | None]:
    x = design_values(task, design)
    row = _unplanned_row(task, x, "")
    try:
        robot_mm = FiveBar(*(x[k] for k in LENGTHS))
    except DextarError as exc:
        row["reason"] = f"geometry: {exc}"
        return row, None
    robot = robot_mm.scaled(1e-3)
    try:
        inertia = inertia_of(task, robot, x)
        chosen, reason = _choose(task, robot, inertia, x)
    except DextarError as exc:
        row["reason"] = str(exc)
        return row, None
    assert chosen is not None
    res, size, gm = chosen.result, chosen.size, chosen.gearmotor
    mA, mD = size.motors
    d = pose_distances(robot, res.q, res.P)
    J = jacobian(robot, res.q, res.P, tol=0.0)
    dex = inverse_condition(J[:, 0, 0], J[:, 0, 1], J[:, 1, 0], J[:, 1, 1])
    spin = None if gm is None else (inertia.rotor[0] + gm.spin, inertia.rotor[1] + gm.spin)
    model = Model(robot, inertia if gm is None else with_gearmotor(inertia, gm), task.assembly,
                  tol=0.0)
    row.update({
        "cycle_time_s": res.cycle_time_s,
        "min_type1_distance": float(d.type1.min()), "min_type2_distance": float(d.type2.min()),
        "gci": float(np.mean(dex)),
        "peak_torque_A_Nm": mA.peak_torque_Nm, "peak_torque_D_Nm": mD.peak_torque_Nm,
        "rms_torque_A_Nm": mA.rms_torque_Nm, "rms_torque_D_Nm": mD.rms_torque_Nm,
        "workspace_area_mm2": usable_area_mm2(robot_mm, task.working_mode,
                                              [1e3 * v for v in task.start],
                                              task.tolerances.type2),
        **shaking_summary_si(model, res.t, res.q, res.dq, res.ddq, P=res.P, spin=spin)})
    if gm is not None:
        row.update({"motor": gm.motor.name, "motor_mass_kg": 2.0 * gm.motor.mass,
                    "motor_price": 2.0 * gm.motor.price, "gear_ratio": gm.ratio})
    if reason:
        row["reason"] = reason
        return row, res
    for k in METRICS:
        if k in MOTOR_METRICS and gm is None:
            continue
        if not math.isfinite(float(row[k])):
            row["reason"] = f"{k} is not finite"
            return row, res
    row["feasible"] = True
    return row, res


def _plan(task: Task, robot: FiveBar, inertia: Inertia, motors: MotorLimits | None,
          rms_limit: tuple[float, float] | None) -> ProgramResult:
    """The task on ``robot`` (m) with ``inertia`` and ``motors``: its program planned, or its
    path sampled under its law (a one-move result with the same fields)."""
    if task.path is None:
        return ProgramRequest(robot, inertia, task.moves, task.start, task.working_mode,
                              task.assembly, motors, rms_limit, SWEEP_RATE_HZ,
                              task.grid, task.tolerances, task.cycle).plan()
    model = Model(robot, inertia, task.assembly, tol=task.tolerances.type2)
    law = task.law
    if law is None:  # a law planned on the robot (time-optimal)
        assert task.law_type is not None
        check_path(robot, task.path, mode=task.working_mode, tolerances=task.tolerances,
                   units=SI)
        dyn = RobotAlongPath(model, task.path, task.working_mode, SI)
        law = law_type(task.law_type).build(LawRequest(
            task.path, task.law_values or {}, inertia.point_mass, dyn, SI, motors))
    tr = sample_trajectory(robot, task.path, law, mode=task.working_mode,
                           samples=task.samples, tolerances=task.tolerances, units=SI)
    tau = inverse_dynamics(model, tr.q, tr.dq, tr.ddq, t=tr.t)
    return ProgramResult([], float(law.duration), tr.t, np.zeros(len(tr.t), int), tr.P, tr.q,
                         tr.dq, tr.ddq, tau, motors, rms_limit)


def evaluate_chunk(task: Task, designs: Array, first: int) -> list[dict[str, Any]]:
    """Rows of the designs (m, len(task.columns)) numbered from ``first`` (the unit of work
    of a sweep). A design whose evaluation raises an unexpected error is a row with that
    error as its reason: the sweep never stops for one design, and the error shows in the
    file."""
    rows = []
    for k, design in enumerate(np.asarray(designs, float)):
        try:
            row = evaluate_design(task, design)
        except Exception as exc:  # noqa: BLE001 - kept as the design's reason
            row = _unplanned_row(task, design_values(task, design),
                                 f"internal error: {type(exc).__name__}: {exc}")
        rows.append({"design": first + k, **row})
    return rows


def evaluate_path(task: Task, design: object) -> Array:
    """The end-effector's path (n, 2) in mm of the task on one design (its columns or its
    row, as :func:`evaluate_design` takes them), to draw it."""
    _, res = _evaluate(task, design)
    if res is None:
        x = design_values(task, design)
        robot = FiveBar(*(x[k] for k in LENGTHS)).scaled(1e-3)
        res = _plan(task, robot, inertia_of(task, robot, x), task.motors, task.rms_limit)
    return np.asarray(res.P * 1e3)
