"""Planning a robot program: a sequence of moves, each with its law, under the motors' limits;
the setpoints at the servo rate and the cycle time (the sizing is :mod:`.sizing`).

A program starts at rest at a point in a working mode. Its moves are registered types
(:mod:`dextar.program.moves`; the built-in ones in :mod:`dextar.program.move_types`):

* ``line`` to a point, ``arc`` through ``via`` to a point (or about a ``center`` in a
  ``direction``): task-space paths in the current working mode, checked by the geometry
  checker (reach, both singularity types);
* ``dwell`` for a time: holding still, gravity still loads the motors;
* ``joint`` to a point in a (new) working mode, or to joint angles: a straight line in joint
  space, which may cross serial singularities (how a working mode changes) but not a parallel
  one.

Path moves joined by a blend (``blend > 0``) are one motion: each corner is replaced by a
quintic of continuous curvature that stays within ``blend`` of the corner
(:mod:`dextar.paths.composite`), and the law of the first move of the chain runs over the
whole of it, without stopping at the corners. Other moves start and end at rest. A move's law
is any registered law (:mod:`dextar.program.laws`). Everything is in SI (m, kg, s, N m, rad).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any

import numpy as np

from .._arrays import Array
from ..dynamics import Inertia, Model, RobotAlongPath, inverse_dynamics
from ..dynamics.crossing import (
    CrossingMargin,
    PlannedTorques,
    RobotAcrossPath,
    crossing_margins,
)
from ..errors import AssemblyError, DextarError, InfeasibleError, NumericalError, ParameterError
from ..geometry import (
    FiveBar,
    assembly_mode_name,
    canonical_working_mode,
    parse_assembly_mode,
)
from ..kinematics import assembly_mode, direct_kinematics, inverse_kinematics, working_mode
from ..kinematics.checker import DEFAULT_TOLERANCES, Tolerances, check_reach
from ..laws import Law
from ..motors import MotorLimits
from ..paths import Path
from ..paths.composite import Composite, Quintic, blended
from ..trajectory import (
    CheckedPath,
    Crossing,
    Trajectory,
    check_path,
    find_crossings,
    sample_trajectory,
)
from ..units import SI
from .laws import move_law
from .moves import Move, move_type

#: Fewest time-optimal grid segments across a blend.
BLEND_SEGMENTS = 20

#: ``sample(local times (n,)) -> (P, q, dq, ddq)``, each (n, 2).
Sampler = Callable[[Array], tuple[Array, Array, Array, Array]]


@dataclass(frozen=True)
class PlanContext:
    """What every move of a program is planned with (SI).

    Attributes
    ----------
    robot : FiveBar
        The geometry in metres.
    inertia : Inertia
        Masses, friction and gravity.
    assembly : str
    motors : MotorLimits, optional
        Joint-side limits; laws planned under the motors (and ``"fit"`` durations) need them.
    grid : int
        Time-optimal segments per motion (a blended chain shares them, see
        :func:`chain_grid`).
    tolerances : Tolerances
    """

    robot: FiveBar
    inertia: Inertia
    assembly: str = "up"
    motors: MotorLimits | None = None
    grid: int = 400
    tolerances: Tolerances = DEFAULT_TOLERANCES

    @cached_property
    def model(self) -> Model:
        """The model of the laws (parallel-singularity tolerance of the checker)."""
        return Model(self.robot, self.inertia, self.assembly, tol=self.tolerances.type2)

    @cached_property
    def free_model(self) -> Model:
        """The model of the setpoints' torques and the holding torques (no tolerance: the
        poses were checked when the moves were planned)."""
        return Model(self.robot, self.inertia, self.assembly, tol=0.0)


@dataclass(frozen=True)
class PlanState:
    """Where the robot is between moves, at rest: the point (m), the joint angles (rad,
    continuous over the program), the working mode and the assembly mode (``""`` in a
    move's end state: unchanged, the state's it started from)."""

    P: Array
    q: Array
    mode: str
    assembly: str = ""


@dataclass(frozen=True)
class MovePlan:
    """What a move type's planner gives (:data:`dextar.program.moves.Planner`).

    Attributes
    ----------
    law : Law, optional
        None for a move without a law (a dwell).
    duration_s : float
    sample : callable
        ``sample(local times (n,)) -> (P, q, dq, ddq)``, each (n, 2), SI.
    end : PlanState
        Where the move leaves the robot, at rest.
    min_type1_distance, min_type2_distance : float
        Smallest normalised distances to the singularities along the move.
    torques : callable, optional
        ``torques(local times (n,)) -> (n, 2)`` feedforward torques (N m) where the exact
        kernel on the joint motion cannot give them: a move across the parallel singularity
        curve (None: the kernel's, in the move's assembly mode).
    crossings : tuple of CrossingMargin
        The move's crossings of the parallel singularity curve (local times).
    """

    law: Law | None
    duration_s: float
    sample: Sampler
    end: PlanState
    min_type1_distance: float
    min_type2_distance: float
    torques: Callable[[Array], Array] | None = None
    crossings: tuple[CrossingMargin, ...] = ()


@dataclass(frozen=True)
class PlannedMove:
    """A move (or a blended chain of moves) with its law and where it sits in the cycle.

    Attributes
    ----------
    index : int
        The move's position in the program (the chain's first move).
    move : Move
    law : Law, optional
        None for a dwell.
    start_s, duration_s : float
    q0, q1 : ndarray, shape (2,)
        Joint angles at its start and end.
    sample : callable
        ``sample(local times) -> (P, q, dq, ddq)``.
    min_type1_distance, min_type2_distance : float
        Smallest normalised distances to the singularities along the move.
    owner : callable, optional
        For a blended chain of moves (one motion): the move index at each local time.
    members : tuple of (index, start_s, duration_s)
        For a blended chain: where each of its moves sits in the cycle.
    assembly, end_assembly : str
        The assembly mode at its start and at its end (they differ across a crossing of the
        parallel singularity curve).
    mode : str
        The working mode at its end.
    torques : callable, optional
        The move's own feedforward torques (:attr:`MovePlan.torques`).
    crossings : tuple of CrossingMargin
        Its crossings of the parallel singularity curve (local times).
    mode_change : bool
        A joint move the mode planner put before move ``index`` (a path move) to change the
        working mode there (``working_mode = "auto"``, :func:`plan_program`).
    member_distances : tuple of (float, float)
        For a blended chain: each move's smallest normalised distances to the singularities
        (type 1, type 2) along its own stretch of the path (a blend counts with the move it
        leaves).
    """

    index: int
    move: Move
    law: Law | None
    start_s: float
    duration_s: float
    q0: Array
    q1: Array
    sample: Sampler
    min_type1_distance: float
    min_type2_distance: float
    owner: Callable[[Array], Array] | None = None
    members: tuple[tuple[int, float, float], ...] = ()
    assembly: str = "up"
    end_assembly: str = "up"
    mode: str = ""
    torques: Callable[[Array], Array] | None = None
    crossings: tuple[CrossingMargin, ...] = ()
    mode_change: bool = False
    member_distances: tuple[tuple[float, float], ...] = ()


@dataclass(frozen=True)
class MoveTiming:
    """One move of the program as it runs: each move of a blended chain has its own.

    Attributes
    ----------
    index : int
    type : str
    law : str, optional
        None for a move without a law (a dwell).
    law_status : int
    law_message : str
    start_s, duration_s : float
    blended_with_next : bool
    min_type1_distance, min_type2_distance : float
        Along the move (a move of a blended chain: along its own stretch of the chain's
        path).
    working_mode, assembly_mode : str
        The modes the move ends in.
    crossings : tuple of dict
        Its crossings of the parallel singularity curve, JSON-ready (:func:`crossing_dict`).
    mode_change : bool
        A joint move the mode planner put before move ``index`` to change the working mode
        (to ``working_mode``) at the point where that move starts.
    """

    index: int
    type: str
    law: str | None
    law_status: int
    law_message: str
    start_s: float
    duration_s: float
    blended_with_next: bool
    min_type1_distance: float
    min_type2_distance: float
    working_mode: str = ""
    assembly_mode: str = ""
    crossings: tuple[dict[str, Any], ...] = ()
    mode_change: bool = False


@dataclass(frozen=True)
class ProgramResult:
    """A planned program: the moves and the setpoints at the servo rate.

    Attributes
    ----------
    moves : list of PlannedMove
        One per motion (a blended chain of moves is one).
    cycle_time_s : float
    t : ndarray, shape (n,)
        Setpoint times (s), ``1 / servo_rate_hz`` apart, from 0 to the first tick at or after
        the cycle time (the robot holds its final pose after the cycle).
    move_index : ndarray of int, shape (n,)
    P : ndarray, shape (n, 2)
        End-effector (m).
    q, dq, ddq : ndarray, shape (n, 2)
        Joint angles (rad), rates (rad/s), accelerations (rad/s^2).
    tau : ndarray, shape (n, 2)
        Feedforward torques of the exact model (N m).
    motors : MotorLimits, optional
    rms_limit : (float, float), optional
        The motors' continuous ratings (N m).
    move_types : tuple of str
        Every move's type, in program order.
    rms_fit : RmsFit, optional
        How the cycle was fitted within the RMS ratings (``cycle = "fit-rms"``).
    servo_rate_hz : float, optional
        The setpoints' rate: ``t = arange(n) / servo_rate_hz`` (None: samples of another
        kind, a sweep's run task).
    mode_choice : ModeChoice, optional
        The working modes the planner chose (``working_mode = "auto"``), or None.
    """

    moves: list[PlannedMove]
    cycle_time_s: float
    t: Array
    move_index: Array
    P: Array
    q: Array
    dq: Array
    ddq: Array
    tau: Array
    motors: MotorLimits | None
    rms_limit: tuple[float, float] | None = None
    move_types: tuple[str, ...] = ()
    rms_fit: RmsFit | None = None
    servo_rate_hz: float | None = None
    mode_choice: ModeChoice | None = None

    def timeline(self) -> list[MoveTiming]:
        """Every move of the program in order, each move of a blended chain on its own."""
        out = []
        for pm in self.moves:
            law = pm.law
            members = pm.members or ((pm.index, pm.start_s, pm.duration_s),)
            peak = None if self.motors is None else self.motors.peak_torque
            for k, (idx, start, dur) in enumerate(members):
                mine = tuple(crossing_dict(c, pm.start_s, peak) for c in pm.crossings
                             if start <= pm.start_s + c.t <= start + dur)
                d1, d2 = (pm.member_distances[k] if pm.member_distances else
                          (pm.min_type1_distance, pm.min_type2_distance))
                out.append(MoveTiming(
                    idx, pm.move.type if pm.mode_change or not self.move_types
                    else self.move_types[idx],
                    law.name if law else None, int(law.status) if law else 0,
                    law.message if law else "holding still", start, dur,
                    bool(pm.members) and idx != pm.members[-1][0], d1, d2, pm.mode,
                    pm.end_assembly if idx == members[-1][0] else _assembly_at(pm, start + dur),
                    mine, pm.mode_change))
        return out


def _assembly_at(pm: PlannedMove, t: float) -> str:
    """The assembly mode of a blended chain's motion at the cycle time ``t``."""
    n = sum(1 for c in pm.crossings if pm.start_s + c.t <= t)
    return pm.assembly if n % 2 == 0 else assembly_mode_name(-parse_assembly_mode(pm.assembly))


def crossing_dict(c: CrossingMargin, start_s: float,
                  peak: tuple[float, float] | None) -> dict[str, Any]:
    """A crossing of the parallel singularity curve in ``summary.json`` (SI, mm): its time in
    the cycle, the point, the path speed, the degeneracy condition's residual (N, and its
    ratio to the terms that cancel in it), whether it holds, the torque peak within the
    crossing's neighbourhood and its ratio to the motors' peak torques, the neighbourhood's
    times and the assembly modes on either side."""
    tp = [float(v) for v in c.torque_peak]
    return {"time_s": start_s + c.t, "point_mm": [1e3 * float(v) for v in c.crossing.P],
            "speed_mm_s": 1e3 * c.speed, "residual_N": c.residual,
            "residual_ratio": c.residual_ratio, "condition_holds": c.holds,
            "torque_peak_Nm": tp,
            "torque_peak_ratio": None if peak is None else [v / p for v, p in
                                                            zip(tp, peak, strict=True)],
            "neighbourhood_s": [start_s + c.span[0], start_s + c.span[1]],
            "assembly_before": c.crossing.assembly_before,
            "assembly_after": c.crossing.assembly_after}


@dataclass(frozen=True)
class RmsFit:
    """A cycle planned within the motors' RMS ratings (``cycle = "fit-rms"``): the moves
    planned within lower peak torques, ``peak_scale`` times the motors', the largest scale
    (to ``1e-3`` of the cycle time) whose cycle keeps every motor's RMS torque over the
    repeated cycle within its rating.

    Attributes
    ----------
    peak_scale : float
        1 when the motors' own peaks already keep the RMS within the ratings.
    bound_by : str
        What bounds the cycle: ``"peak torque"`` (scale 1) or ``"RMS rating of motor A"``
        (or D).
    rms_ratio : (float, float)
        Each motor's RMS torque over its rating at the planned cycle.
    plans : int
        Programs planned by the search.
    """

    peak_scale: float
    bound_by: str
    rms_ratio: tuple[float, float]
    plans: int

    def as_dict(self) -> dict[str, object]:
        """JSON-ready."""
        return {"peak_scale": self.peak_scale, "bound_by": self.bound_by,
                "rms_ratio": list(self.rms_ratio), "plans": self.plans}


#: The cycles a program can be planned for: the moves' own laws, or the shortest cycle within
#: the RMS ratings.
CYCLES = ("as-planned", "fit-rms")


@dataclass(frozen=True)
class ProgramRequest:
    """Everything a program is planned from (SI; see :func:`plan_program`), as the config
    layer builds it once."""

    robot: FiveBar
    inertia: Inertia
    moves: tuple[Move, ...]
    start: tuple[float, float]
    working_mode: str
    assembly: str = "up"
    motors: MotorLimits | None = None
    rms_limit: tuple[float, float] | None = None
    servo_rate_hz: float = 1000.0
    grid: int = 400
    tolerances: Tolerances = DEFAULT_TOLERANCES
    cycle: str = "as-planned"

    def plan(self) -> ProgramResult:
        """The program planned (:func:`plan_program`), or with ``cycle = "fit-rms"`` the
        shortest cycle within the RMS ratings (:func:`fit_rms`)."""
        if self.cycle == "fit-rms":
            return fit_rms(self)
        if self.cycle != "as-planned":
            raise ParameterError(f"cycle {self.cycle!r} must be one of {', '.join(CYCLES)}")
        return self.plan_with(self.motors)

    def plan_with(self, motors: MotorLimits | None) -> ProgramResult:
        """The program planned within ``motors`` (sized against this request's motors)."""
        res = plan_program(self.robot, self.inertia, self.moves, start=self.start,
                           working_mode=self.working_mode, assembly=self.assembly,
                           motors=motors, rms_limit=self.rms_limit,
                           servo_rate_hz=self.servo_rate_hz, grid=self.grid,
                           tolerances=self.tolerances)
        return res if motors is self.motors else replace(res, motors=self.motors)


def rms_ratios(res: ProgramResult) -> tuple[float, float]:
    """Each motor's RMS torque over the cycle (trapezoidal, over the setpoints' times) over
    its rating."""
    assert res.rms_limit is not None
    t, tau = res.t, res.tau
    dt = np.diff(t)
    rms = np.sqrt(np.sum(0.5 * (tau[1:] ** 2 + tau[:-1] ** 2) * dt[:, None], axis=0)
                  / max(float(t[-1]), 1e-300))
    return float(rms[0] / res.rms_limit[0]), float(rms[1] / res.rms_limit[1])


def fit_rms(req: ProgramRequest, *, rtol: float = 1e-3) -> ProgramResult:
    """The shortest cycle whose RMS torques over the repeated cycle are within the ratings:
    the moves planned within the motors' peak torques times a scale (the time-optimal and
    fitted moves slow down with it), the largest scale in ``(0, 1]`` that keeps both RMS
    ratios at most 1, by bisection on the scale until the cycle times of the bracket differ
    by less than ``rtol``. The result's ``rms_fit`` says what bounds the cycle.

    Raises
    ------
    ParameterError
        No motors or no ratings, or no scale down to the torques that hold the robot keeps
        the RMS within the ratings (named: the motor and its RMS at the lowest scale tried).
    """
    if req.motors is None or req.rms_limit is None:
        raise ParameterError("cycle = \"fit-rms\" needs the motors' peak_torque and "
                             "rms_torque")
    base = req.motors
    plans = 0

    def plan(scale: float) -> ProgramResult:
        nonlocal plans
        plans += 1
        if scale == 1.0:
            return req.plan_with(base)
        m = replace(base, peak_torque=(base.peak_torque[0] * scale,
                                       base.peak_torque[1] * scale))
        return req.plan_with(m)

    full = plan(1.0)
    r = rms_ratios(full)
    if max(r) <= 1.0:
        return replace(full, rms_fit=RmsFit(1.0, "peak torque", r, plans))
    hi, res_hi = 1.0, full  # exceeds
    lo, res_lo = 0.5, None
    while res_lo is None:
        try:
            cand = plan(lo)
        except DextarError as exc:
            rr = rms_ratios(res_hi)
            i = int(np.argmax(rr))
            raise ParameterError(
                f"no cycle keeps the RMS torques within the ratings: motor {'AD'[i]} has "
                f"{rr[i] * req.rms_limit[i]:.4g} N m RMS against its rating "
                f"{req.rms_limit[i]:.4g} N m with the peak torques scaled by {hi:.3g}, and "
                f"scaled by {lo:.3g} the program cannot be planned ({exc})") from None
        if max(rms_ratios(cand)) <= 1.0:
            res_lo = cand
            break
        hi, res_hi = lo, cand
        lo *= 0.5
        if lo < 1e-3:
            rr = rms_ratios(res_hi)
            i = int(np.argmax(rr))
            raise ParameterError(
                f"no cycle keeps the RMS torques within the ratings: motor {'AD'[i]} still "
                f"has {rr[i] * req.rms_limit[i]:.4g} N m RMS against its rating "
                f"{req.rms_limit[i]:.4g} N m with the peak torques scaled by {2 * lo:.3g}")
    for _ in range(40):
        if res_lo.cycle_time_s - res_hi.cycle_time_s <= rtol * res_lo.cycle_time_s:
            break
        mid = 0.5 * (lo + hi)
        cand = plan(mid)
        if max(rms_ratios(cand)) <= 1.0:
            lo, res_lo = mid, cand
        else:
            hi, res_hi = mid, cand
    r = rms_ratios(res_lo)
    return replace(res_lo, rms_fit=RmsFit(lo, f"RMS rating of motor {'AD'[int(np.argmax(r))]}",
                                          r, plans))


#: A move's own arguments, which a caller might put among its type's values.
_MOVE_ARGUMENTS = ("law", "duration", "law_params", "blend")


def _check_keys(moves: Sequence[Move]) -> None:
    """Every move of a registered type, with none but its type's keys among its values (a
    key it does not know would be ignored), or a :class:`ParameterError` naming the move and
    the key."""
    for i, mv in enumerate(moves):
        kind = move_type(mv.type, f"move {i}'s type")
        known = sorted({kind.si_keys.get(k, k) for k in kind.params})
        unknown = sorted(set(mv.values) - set(known))
        if unknown:
            key = unknown[0]
            hint = (f" ({key} is an argument of Move itself: Move({mv.type!r}, ..., {key}=...))"
                    if key in _MOVE_ARGUMENTS else
                    f" ({key} is the config's key; a Move takes {kind.si_keys[key]}, in SI)"
                    if key in kind.si_keys else "")
            raise ParameterError(f"{move_name(i, mv)}: {key!r} is not a key of a {mv.type} "
                                 f"move; its keys: {', '.join(known)}{hint}")


def move_name(index: int, mv: Move) -> str:
    """``move 2 (arc)``."""
    return f"move {index} ({mv.type})"


#: How far (a fraction of the robot's reach ``max(l1 + L1, l2 + L2)``) a move may end from
#: its target: the forward kinematics of its last setpoint against the point it was sent to.
#: Moves that end where they were sent do so to rounding (the examples' moves: at most
#: 2.5e-17 m on the DexTAR, whose tolerance is 1.6e-7 m); one that ends in the other assembly
#: mode misses by tens of millimetres (a joint move to (100, 10) mm in "--": 155 mm).
END_TOL = 1e-6


def check_assembly(robot: FiveBar, q: Array, P: Array, mode: str, assembly: str,
                   what: str) -> None:
    """Refuse a point that the working mode ``mode`` reaches (angles ``q``) only in the other
    assembly mode than the program's ``assembly`` (or at a parallel singularity, where the
    assemblies meet): ``what`` names it ("the start", "the target")."""
    sigma = int(assembly_mode(robot, q, P))
    if sigma == parse_assembly_mode(assembly):
        return
    where = (f"{what} {SI.point_text(P)} in working mode {mode}")
    if sigma == 0:
        raise AssemblyError(f"{where} is at a parallel singularity, where the assembly modes "
                            "meet: choose another point")
    raise AssemblyError(
        f"{where} lies in assembly mode {assembly_mode_name(sigma)}, but the program is in "
        f"assembly mode {assembly_mode_name(-sigma)}: in that working mode the robot reaches "
        f"it only in the other assembly mode. "
        f"Choose another point or working mode, or set [robot].assembly_mode = "
        f"\"{assembly_mode_name(sigma)}\" for the whole program")


def move_target(mv: Move) -> Array | None:
    """The point a move is sent to (m), or None (a dwell, a joint move to angles)."""
    to = mv.get("to")
    return None if to is None else np.asarray(to, float)


def plan_program(robot: FiveBar, inertia: Inertia, moves: Sequence[Move], *,
                 start: tuple[float, float], working_mode: str, assembly: str = "up",
                 motors: MotorLimits | None = None,
                 rms_limit: tuple[float, float] | None = None, servo_rate_hz: float = 1000.0,
                 grid: int = 400, tolerances: Tolerances = DEFAULT_TOLERANCES) -> ProgramResult:
    """Plan the moves from rest at ``start`` in ``working_mode`` (SI throughout).

    Parameters
    ----------
    robot : FiveBar
        The geometry in metres.
    inertia : Inertia
        Masses, friction and gravity in SI.
    moves : sequence of Move
        In SI (points in m, angles in rad, times in s); a move's index is its position.
    start : (float, float)
        The start point (m), at rest.
    working_mode : str
        The working mode at the start, or ``"auto"``: the planner chooses it and the mode of
        every move that sets none (see :func:`chooses_modes`).
    assembly : str
    motors : MotorLimits, optional
        Joint-side limits in SI; required by laws planned under the motors and by ``"fit"``.
    rms_limit : (float, float), optional
        Continuous ratings (N m) for the sizing.
    servo_rate_hz : float
        Setpoint rate.
    grid : int
        Time-optimal grid: segments per motion (blended moves are one motion, see
        :func:`chain_grid`).
    tolerances : Tolerances

    Returns
    -------
    ProgramResult

    Raises
    ------
    DextarError
        A move that cannot be planned, naming the move (and, in a blended chain, the move
        of the chain at fault) and the cause.
    """
    if not moves:
        raise ParameterError("the program has no move")
    _check_keys(moves)
    if not (math.isfinite(servo_rate_hz) and servo_rate_hz > 0):
        raise ParameterError(f"servo rate {servo_rate_hz!r} must be positive")
    ctx = PlanContext(robot, inertia, assembly, motors, grid, tolerances)
    if chooses_modes(moves, working_mode):
        return _plan_modes(ctx, moves, start, working_mode, rms_limit, servo_rate_hz)
    mode = canonical_working_mode(working_mode)
    P0 = np.asarray(start, float)
    check_reach(robot, P0[None, :], lambda i: "the start", SI.point_text,
                lambda v: f"{SI.mm(v):.6g} mm")
    q0 = inverse_kinematics(robot, P0, mode)
    check_assembly(robot, q0, P0, mode, assembly, "the start")
    state = PlanState(P0, q0, mode, assembly)
    planned: list[PlannedMove] = []
    t0 = 0.0
    for group in _chains(moves):
        pm, state = _plan_group(ctx, group, state, t0)
        planned.append(pm)
        t0 += pm.duration_s
    res = _setpoints(ctx, planned, t0, rms_limit, servo_rate_hz,
                     tuple(mv.type for mv in moves))
    _check_ends(ctx, res, moves)
    return res


def _plan_group(ctx: PlanContext, group: list[tuple[int, Move]], state: PlanState,
                t0: float) -> tuple[PlannedMove, PlanState]:
    """One motion (a move, or a blended chain) from ``state`` at the cycle time ``t0``; errors
    named with the move."""
    i, mv = group[0]
    try:
        if len(group) > 1:
            return _plan_chain(ctx, group, state, t0)
        mp = move_type(mv.type).plan(ctx, mv, state)
    except DextarError as exc:
        raise type(exc)(f"{_chain_name(group, exc)}: {exc}") from None
    end = mp.end if mp.end.assembly else replace(mp.end, assembly=state.assembly)
    pm = PlannedMove(i, mv, mp.law, t0, mp.duration_s, state.q, mp.end.q,
                     mp.sample, mp.min_type1_distance, mp.min_type2_distance,
                     assembly=state.assembly, end_assembly=end.assembly,
                     mode=end.mode, torques=mp.torques, crossings=mp.crossings)
    return pm, end


def _check_ends(ctx: PlanContext, res: ProgramResult, moves: Sequence[Move]) -> None:
    """Every motion ends where it was sent: the forward kinematics (in the assembly mode it
    ends in) of its last setpoint, at its end time, within :data:`END_TOL` of the
    reach of the target of its last move.

    Raises
    ------
    AssemblyError
        Naming the move, its target, where it ends and how far apart.
    """
    robot = ctx.robot
    tol = END_TOL * max(robot.l1 + robot.L1, robot.l2 + robot.L2)
    for pm in res.moves:
        last = pm.members[-1][0] if pm.members else pm.index
        target = move_target(moves[last])
        if target is None:
            continue
        q_end = pm.sample(np.array([pm.duration_s]))[1][-1]
        end = direct_kinematics(robot, q_end, pm.end_assembly)
        miss = float(np.hypot(*(end - target)))
        if not miss <= tol:
            raise AssemblyError(
                f"{move_name(last, moves[last])}: sent to {SI.point_text(target)}, it ends at "
                f"{SI.point_text(end)} (the forward kinematics of its last setpoint in assembly "
                f"mode {pm.end_assembly}), {SI.mm(miss):.4g} mm away")


def _chains(moves: Sequence[Move]) -> list[list[tuple[int, Move]]]:
    """Runs of path moves joined by blends (one motion each); every other move alone, each
    with its index in the program."""
    groups: list[list[tuple[int, Move]]] = []
    for i, mv in enumerate(moves):
        prev = groups[-1][-1][1] if groups else None
        if (prev is not None and prev.blend > 0 and move_type(prev.type).path is not None
                and move_type(mv.type).path is not None):
            groups[-1].append((i, mv))
        else:
            groups.append([(i, mv)])
    return groups


def _chain_name(group: list[tuple[int, Move]], exc: DextarError) -> str:
    """The move to name for an error: the move itself, or in a chain the member the error
    points at (a piece's path), else the chain as a whole."""
    i, mv = group[0]
    if len(group) == 1:
        return move_name(i, mv)
    member = getattr(exc, "member", None)
    if isinstance(member, int) and 0 < member < len(group):  # (the first: the chain's name)
        j, mj = group[member]
        return f"{move_name(j, mj)}, in the motion blended from move {i}"
    last = group[-1][0]
    return (f"{move_name(i, mv)}, blended with move{'s' if len(group) > 2 else ''} "
            f"{group[1][0]}" + (f"-{last}" if len(group) > 2 else ""))


def _plan_chain(ctx: PlanContext, group: list[tuple[int, Move]], state: PlanState,
                start_s: float) -> tuple[PlannedMove, PlanState]:
    """Moves joined by blends: one path with G2 corners, one law, no stop at the corners."""
    first = group[0][1]
    for i, mv in group[1:]:
        if mv.law != first.law or (mv.duration is not None and mv.duration != first.duration):
            raise ParameterError(
                f"{move_name(i, mv)} sets law {mv.law!r} (duration {mv.duration!r}) but a "
                f"blend makes it one motion with move {group[0][0]}, whose law {first.law!r} "
                f"(duration {first.duration!r}) it takes: set them in the first move of the "
                "chain only")
    pieces: list[Path] = []
    P = state.P
    for _, mv in group:
        kind = move_type(mv.type)
        assert kind.path is not None  # a chain holds path moves only (_chains)
        pieces.append(kind.path(mv, P))
        P = _end(mv, pieces[-1])
    blends = tuple(float(mv.blend) for _, mv in group[:-1])
    _check_blends_fit(pieces, blends)
    try:
        path, owner = _blended(tuple(pieces), blends)
    except ParameterError as exc:
        corner = getattr(exc, "corner", None)
        if not isinstance(corner, int):
            raise ParameterError(f"blend: {exc}") from None
        x, y = (1e3 * float(v) for v in pieces[corner].position(pieces[corner].p1))
        named = ParameterError(f"the blend at the end of move {group[corner][0]}, "
                               f"({x:.6g}, {y:.6g}) mm, into move {group[corner + 1][0]}: "
                               f"{exc}")
        named.member = corner  # type: ignore[attr-defined]  # read back by _chain_name
        raise named from None
    # the assembly modes the members ask for where they end (the next member's start)
    ends = [float(path.starts[owner.index(k + 1)]) for k in range(len(group) - 1)]
    targets = [(s_end, mv.get("assembly_mode"), move_name(i, mv))
               for s_end, (i, mv) in zip([*ends, path.length], group, strict=True)]
    try:
        pp = plan_along(ctx, first, path, state, chain_grid(path, ctx.grid), samples=801,
                        targets=targets)
    except DextarError as exc:
        if not isinstance(exc, AssemblyError):
            _blame_piece(ctx, pieces, state, exc)
        raise
    law, sample, q1, poses = pp.law, pp.sample, pp.q1, pp.poses
    owners = np.array([group[o][0] for o in owner])

    def owner_of(t: Array) -> Array:
        s_ = law.evaluate(np.clip(t, 0.0, law.duration))[0]
        return np.asarray(owners[path.piece_at(s_)])

    # when each move starts: the time its first piece starts (s(t) increases)
    tt = np.linspace(0.0, law.duration, 4001)
    ss = law.evaluate(tt)[0]
    starts_s = [float(path.starts[owner.index(k)]) for k in range(len(group))]
    t_at = [float(np.interp(v, ss, tt)) for v in starts_s] + [law.duration]
    members = tuple((i, start_s + t_at[k], t_at[k + 1] - t_at[k])
                    for k, (i, _) in enumerate(group))
    pm = PlannedMove(group[0][0], first, law, start_s, law.duration, state.q, q1, sample,
                     float(poses.distances.type1.min()), float(poses.distances.type2.min()),
                     owner_of, members, assembly=state.assembly, end_assembly=pp.end_assembly,
                     mode=state.mode, torques=pp.torques, crossings=pp.crossings,
                     member_distances=_member_distances(poses, owner, len(group)))
    return pm, PlanState(P, q1, state.mode, pp.end_assembly)


def _member_distances(poses: CheckedPath, owner: Sequence[int], n: int
                      ) -> tuple[tuple[float, float], ...]:
    """Each of a chain's ``n`` moves' smallest distances to the singularities (type 1, type
    2) over the checked poses on its pieces (``owner``: the move of each of the composite
    path's pieces, whose parameter runs from ``j`` to ``j + 1`` on piece ``j``), the poses
    where it meets its neighbours included; a stretch between two poses takes the nearer."""
    bounds = [owner.index(k) for k in range(n)] + [len(owner)]
    d1, d2, p = poses.distances.type1, poses.distances.type2, poses.p
    out = []
    for k in range(n):
        on = (p >= bounds[k]) & (p <= bounds[k + 1])
        if not on.any():  # (a stretch shorter than the poses' spacing: the nearest)
            gap = np.abs(p - 0.5 * (bounds[k] + bounds[k + 1]))
            on = gap == gap.min()
        out.append((float(d1[on].min()), float(d2[on].min())))
    return tuple(out)


def _end(mv: Move, path: Path) -> Array:
    """Where a path move ends: exactly its ``to`` when it has one (so the next move's path
    is the same on every robot), else its path's last point."""
    to = mv.get("to")
    return np.asarray(to if to is not None else path.position(path.p1), float)


def _blame_piece(ctx: PlanContext, pieces: list[Path], state: PlanState,
                 exc: DextarError) -> None:
    """After a chain failed its path check: check its pieces one by one (unblended) and mark
    ``exc`` with the first that fails on its own (``exc.member``), so the error names that
    move rather than the chain's first."""
    for k, piece in enumerate(pieces):
        try:
            check_path(ctx.robot, piece, mode=state.mode, tolerances=ctx.tolerances, units=SI)
        except DextarError:
            exc.member = k  # type: ignore[attr-defined]  # read back by _chain_name
            return


def along_path(ctx: PlanContext, mv: Move, path: Path, state: PlanState, grid: int | Array,
               *, samples: int) -> tuple[Law, Sampler, Array, CheckedPath]:
    """A task-space motion along ``path`` (a line, an arc or a blended chain) from ``state``:
    the path checked, the law of ``mv`` on it, the sampling ``(P, q, dq, ddq)`` at local
    times with the angles continuous with the state's (unwrapped by whole turns), the end
    angles and the checked poses (``samples``: the law's own sampling, for a fitted
    duration). The path may not cross the parallel singularity curve (:func:`plan_along`
    plans the moves that do)."""
    pp = plan_along(ctx, mv, path, state, grid, samples=samples)
    return pp.law, pp.sample, pp.q1, pp.poses


@dataclass(frozen=True)
class PathPlan:
    """A task-space motion planned by :func:`plan_along`.

    Attributes
    ----------
    law : Law
    sample : callable
        ``sample(local times) -> (P, q, dq, ddq)``.
    q1 : ndarray, shape (2,)
        The end angles, continuous with the start's.
    poses : CheckedPath
        The path's poses as the geometry checker checked them.
    end_assembly : str
        The assembly mode at its end.
    torques : callable, optional
        The feedforward torques at local times, for a motion across the parallel singularity
        curve (None: the exact kernel's on the joint motion).
    crossings : tuple of CrossingMargin
        Its crossings of the curve (local times).
    """

    law: Law
    sample: Sampler
    q1: Array
    poses: CheckedPath
    end_assembly: str
    torques: Callable[[Array], Array] | None = None
    crossings: tuple[CrossingMargin, ...] = ()


#: ``(arc length, assembly mode or None, who)``: the assembly mode a move asks for at the
#: arc length where it ends along a motion (None: none asked), and the move's name.
Target = tuple[float, str | None, str]


def plan_along(ctx: PlanContext, mv: Move, path: Path, state: PlanState, grid: int | Array,
               *, samples: int, targets: Sequence[Target] = ()) -> PathPlan:
    """:func:`along_path` with the assembly modes ``targets`` asks for at arc lengths along
    the path (a move's ``assembly_mode``): where they differ from the state's, the path must
    cross the parallel singularity curve of the working mode an odd number of times before
    (each crossing changes the assembly mode), and the law (time-optimal) makes every
    crossing under the degeneracy condition (:mod:`dextar.dynamics.crossing`).

    Raises
    ------
    AssemblyError
        An assembly mode the path does not reach (it does not cross the curve, or crosses it
        an even number of times), named with the move and its path.
    ParameterError
        A crossing asked of a law other than the second-order time-optimal one.
    InfeasibleError
        A crossing the motors' limits cannot make, with the reason.
    """
    robot, tol, mode = ctx.robot, ctx.tolerances, state.mode
    asked = [(s_end, asm, who) for s_end, asm, who in targets if asm is not None]
    crossings: tuple[Crossing, ...] = ()
    if asked:
        crossings = find_crossings(robot, path, mode=mode, units=SI)
        _check_targets(path, state, crossings, asked)
    model = replace(ctx.model, assembly=state.assembly)
    poses = check_path(robot, path, mode=mode, tolerances=tol, units=SI, crossings=crossings)

    def traj(law: Law, times: Array | None = None) -> Trajectory:
        return sample_trajectory(robot, path, law, mode=mode, times=times, samples=samples,
                                 tolerances=tol, units=SI, checked=False, crossings=crossings)

    shift = np.round((state.q - poses.q[0]) / (2 * np.pi)) * 2 * np.pi
    torques: Callable[[Array], Array] | None = None
    margins: tuple[CrossingMargin, ...] = ()
    if not crossings:
        along = RobotAlongPath(model, path, mode, SI, checked=False)  # checked above
        law = move_law(mv, path, along, ctx.motors, grid, traj, model)
    else:
        law, margins, torques = _across(ctx, mv, path, mode, crossings, grid, traj, model)

    def sample(t: Array) -> tuple[Array, Array, Array, Array]:
        st = traj(law, np.clip(t, 0.0, law.duration))
        return st.P, st.q + shift, st.dq, st.ddq

    end = state.assembly if len(crossings) % 2 == 0 else crossings[-1].assembly_after
    return PathPlan(law, sample, poses.q[-1] + shift, poses, end, torques, margins)


def _flip(assembly: str, times: int) -> str:
    return assembly if times % 2 == 0 else assembly_mode_name(-parse_assembly_mode(assembly))


def _check_targets(path: Path, state: PlanState, crossings: tuple[Crossing, ...],
                   asked: Sequence[Target]) -> None:
    """Every assembly mode asked is the one the path reaches there (named otherwise)."""
    ends = f"from {SI.point_text(path.position(np.array([path.p0]))[0])}"
    for s_end, asm, who in asked:
        wanted = canonical_assembly(asm or "")
        n = sum(1 for c in crossings if c.s < s_end)
        got = _flip(state.assembly, n)
        if got == wanted:
            continue
        who = f"{who}: " if who else ""
        if n == 0:
            raise AssemblyError(
                f"{who}assembly_mode = \"{wanted}\", but its path {ends} does not cross the "
                f"parallel (type 2) singularity curve of working mode {state.mode}, so it "
                f"stays in assembly mode {got}: only a path across the curve changes the "
                "assembly mode (the workspace figure draws the curve)")
        raise AssemblyError(
            f"{who}assembly_mode = \"{wanted}\", but its path {ends} crosses the parallel "
            f"(type 2) singularity curve of working mode {state.mode} {n} times (at "
            + ", ".join(SI.point_text(c.P) for c in crossings if c.s < s_end)
            + f") and so ends in assembly mode {got}")


def canonical_assembly(name: str) -> str:
    """``"up"`` or ``"down"`` from a name or a sign (refused by name otherwise)."""
    return assembly_mode_name(parse_assembly_mode(name))


def _across(ctx: PlanContext, mv: Move, path: Path, mode: str,
            crossings: tuple[Crossing, ...], grid: int | Array,
            traj: Callable[[Law, Array | None], Trajectory], model: Model
            ) -> tuple[Law, tuple[CrossingMargin, ...], Callable[[Array], Array]]:
    """The law across the parallel singularity curve (time-optimal under the degeneracy
    condition), its crossings' margins and its torques."""
    where = ", ".join(SI.point_text(c.P) for c in crossings)
    if mv.law != "time-optimal":
        raise ParameterError(
            f"its path crosses the parallel (type 2) singularity curve at {where}: a crossing "
            f"needs law = \"time-optimal\", the law planned under the degeneracy condition "
            f"there; law \"{mv.law}\" ignores it and would need unbounded torques at the "
            "crossing")
    if ctx.motors is not None and ctx.motors.third_order:
        raise ParameterError(
            f"its path crosses the parallel (type 2) singularity curve at {where}: a crossing "
            "is planned by the second-order time-optimal law, and [motors].max_jerk or "
            "max_torque_rate asks the jerk-limited one, which does not impose the degeneracy "
            "condition")
    dynamics = RobotAcrossPath(replace(model, tol=0.0), path, mode, crossings, SI)
    try:
        law = move_law(mv, path, dynamics, ctx.motors, grid, traj, model)
    except InfeasibleError as exc:
        if getattr(exc, "holding", False):  # gravity alone at a rest point: not the crossing
            raise
        raise InfeasibleError(
            f"the crossing of the parallel (type 2) singularity curve at {where} cannot be "
            f"made within the motors' limits (the degeneracy condition fixes the "
            f"acceleration there for each speed): {exc}") from None
    margins = crossing_margins(dynamics, law)
    bad = [m for m in margins if not m.holds]
    if bad:  # (the law imposes it: a failure here is a numerical one)
        m = bad[0]
        raise NumericalError(
            f"the degeneracy condition at the crossing {SI.point_text(m.crossing.P)} does not "
            f"hold along the planned law: residual {m.residual:.3g} N, "
            f"{m.residual_ratio:.3g} of its terms")
    planned = PlannedTorques(dynamics, law)

    def torques(t: Array) -> Array:
        return planned(np.clip(t, 0.0, law.duration))

    return law, margins, torques


def _check_blends_fit(pieces: list[Path], blends: tuple[float, ...]) -> None:
    """Each piece of a chain longer than the blends cut from it (the one at its start and
    the one at its end), or a :class:`ParameterError` marked with the piece (``member``)
    that quotes them in mm, as the program gives them."""
    for k, piece in enumerate(pieces):
        start = blends[k - 1] if k > 0 else 0.0
        end = blends[k] if k < len(blends) else 0.0
        if start + end >= piece.length * (1.0 - 1e-9):  # (blended trims in rounding)
            parts = ([f"{1e3 * start:.6g} mm at its start"] if start > 0 else []) + (
                [f"{1e3 * end:.6g} mm at its end"] if end > 0 else [])
            exc = ParameterError(
                f"its blend{'s' if len(parts) > 1 else ''} of {' and '.join(parts)} "
                f"{'do' if len(parts) > 1 else 'does'} not fit its length of "
                f"{1e3 * piece.length:.6g} mm (a blend is cut from the moves on both sides "
                "of its corner): make the blends shorter")
            exc.member = k  # type: ignore[attr-defined]  # read back by _chain_name
            raise exc


@functools.lru_cache(maxsize=32)
def _blended(pieces: tuple[Path, ...], blends: tuple[float, ...]
             ) -> tuple[Composite, tuple[int, ...]]:
    """:func:`~dextar.paths.composite.blended`, kept for the next robot: the task-space path of
    a chain depends on the task only, and its blends' arc-length tables are costly."""
    path, owner = blended(pieces, blends)
    return path, tuple(owner)


def chain_grid(path: Composite, grid: int) -> Array:
    """The time-optimal grid (arc lengths) of a blended chain, one motion: its ``grid``
    segments shared among the pieces by length, a blend at least :data:`BLEND_SEGMENTS` (its
    curvature and so its torques change fast), any piece at least 10; the pieces' joints are
    grid points."""
    parts = [np.zeros(1)]
    for piece, start in zip(path.pieces, path.starts[:-1], strict=True):
        share = math.ceil(grid * piece.length / path.length)
        n = max(share, BLEND_SEGMENTS if isinstance(piece, Quintic) else 10)
        parts.append(start + np.linspace(0.0, piece.length, n + 1)[1:])
    s = np.concatenate(parts)
    s[-1] = path.length
    return s


def mode_at(robot: FiveBar, q: Array, P: Array, fallback: str) -> str:
    """The working mode of the pose ``(q, P)`` (``fallback`` on a serial singularity)."""
    m = working_mode(robot, q, P)
    if 0 in m:
        return fallback
    return ("+" if m[0] > 0 else "-") + ("+" if m[1] > 0 else "-")


def _setpoints(ctx: PlanContext, planned: list[PlannedMove], cycle: float,
               rms_limit: tuple[float, float] | None, rate: float,
               types: tuple[str, ...]) -> ProgramResult:
    n = int(math.ceil(cycle * rate - 1e-9)) + 1
    t = np.arange(n) / rate
    starts = np.array([pm.start_s for pm in planned])
    idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(planned) - 1)
    P, q, dq, ddq = (np.empty((n, 2)) for _ in range(4))
    move = np.array([pm.index for pm in planned])[idx]
    for k, pm in enumerate(planned):
        sel = np.flatnonzero(idx == k)
        if sel.size:
            P[sel], q[sel], dq[sel], ddq[sel] = pm.sample(t[sel] - pm.start_s)
            if pm.owner is not None:
                move[sel] = pm.owner(t[sel] - pm.start_s)
    past = t > cycle  # after the cycle: hold the final pose
    if past.any():
        dq[past] = 0.0
        ddq[past] = 0.0
    tau = np.empty((n, 2))
    for k, pm in enumerate(planned):
        sel = np.flatnonzero((idx == k) & ~past)
        if pm.torques is not None and sel.size:
            tau[sel] = pm.torques(t[sel] - pm.start_s)
        elif sel.size:
            tau[sel] = inverse_dynamics(replace(ctx.free_model, assembly=pm.assembly), q[sel],
                                        dq[sel], ddq[sel])
    if past.any():
        tau[past] = inverse_dynamics(replace(ctx.free_model, assembly=planned[-1].end_assembly),
                                     q[past], dq[past], ddq[past])
    return ProgramResult(planned, cycle, t, move, P, q, dq, ddq, tau, ctx.motors, rms_limit,
                         types, servo_rate_hz=rate)


# ---------------------------------------------------------------- working modes chosen
#: ``working_mode = "auto"`` (``[program]`` or a move): the planner chooses the mode.
AUTO = "auto"

#: The four working modes, in the order the mode planner tries them (a tie keeps the first).
MODES = ("++", "+-", "-+", "--")


@dataclass(frozen=True)
class ModeChoice:
    """The working modes the planner chose (``working_mode = "auto"``, :func:`plan_program`).

    Attributes
    ----------
    start_mode : str
        The working mode at the start.
    modes : tuple of str
        The working mode each move of the program ends in, in program order.
    changes : tuple of int
        The path moves before which the planner put a joint move that changes the working
        mode at the point where they start.
    plans : int
        Motions planned by the search (each candidate move once per mode it may start in).
    """

    start_mode: str
    modes: tuple[str, ...]
    changes: tuple[int, ...]
    plans: int

    def as_dict(self) -> dict[str, object]:
        """JSON-ready."""
        return {"start_mode": self.start_mode, "modes": list(self.modes),
                "changes_before_moves": list(self.changes), "plans": self.plans}


def _asked_mode(mv: Move) -> str | None:
    """A move's own ``working_mode``: a canonical mode, :data:`AUTO` or None."""
    wm = mv.get("working_mode")
    if wm is None:
        return None
    return AUTO if wm == AUTO else canonical_working_mode(wm)


def chooses_modes(moves: Sequence[Move], working_mode: str) -> bool:
    """Whether the mode planner plans the program: ``working_mode = "auto"`` for the program
    or a move, or a path move (line, arc) with its own ``working_mode``."""
    return working_mode == AUTO or any(
        _asked_mode(mv) == AUTO
        or (mv.get("working_mode") is not None and move_type(mv.type).path is not None)
        for mv in moves)


#: A move of the concrete program the mode planner builds: the index of the program's move
#: it stands for, the move, and whether it is a change of working mode the planner put there.
Step = tuple[int, Move, bool]


@dataclass(frozen=True)
class _Node:
    """The shortest way found to a (working mode, assembly mode) after some moves."""

    cost: float
    state: PlanState
    start_mode: str
    steps: tuple[Step, ...]


def _options(group: list[tuple[int, Move]], state: PlanState, auto: bool) -> list[str | None]:
    """The working modes a motion may run in (a path) or end in (a joint move to a point) from
    ``state``; ``[None]``: the move decides (a dwell, a joint move to angles)."""
    i, mv = group[0]
    kind = move_type(mv.type)
    if kind.path is not None:
        asked = _asked_mode(mv)
        for j, other in group[1:]:
            if _asked_mode(other) not in (None, asked):
                raise ParameterError(
                    f"{move_name(j, other)} sets working_mode = \"{other.get('working_mode')}\" "
                    f"but a blend makes it one motion with move {i}, which keeps one working "
                    "mode along its path: set working_mode in the first move of the chain only")
    elif "working_mode" in kind.params and mv.get("to") is not None:
        asked = _asked_mode(mv)
    else:
        return [None]
    if asked is None:
        asked = AUTO if auto else state.mode
    return list(MODES) if asked == AUTO else [asked]


def _without_mode(mv: Move) -> Move:
    return replace(mv, values={k: v for k, v in mv.values.items() if k != "working_mode"})


def _realise(ctx: PlanContext, group: list[tuple[int, Move]], state: PlanState,
             mode: str | None) -> list[list[Step]]:
    """The concrete motions that run ``group`` in ``mode`` from ``state``: a joint move to a
    point ends in it; a path runs in it, after a joint move at its start point from the
    state's mode when they differ (time-optimal within the motors; without motors, with the
    path's law and duration)."""
    i, mv = group[0]
    if mode is None:
        return [[(j, _without_mode(m) if _asked_mode(m) == AUTO else m, False)
                 for j, m in group]]
    if move_type(mv.type).path is None:
        return [[(i, replace(mv, values={**mv.values, "working_mode": mode}), False)]]
    out: list[list[Step]] = []
    if mode != state.mode:
        to = {"to": (float(state.P[0]), float(state.P[1])), "working_mode": mode}
        change = (Move("joint", to) if ctx.motors is not None
                  else Move("joint", to, law=mv.law, duration=mv.duration,
                            law_params=mv.law_params))
        out.append([(i, change, True)])
    out.append([(j, _without_mode(m), False) for j, m in group])
    return out


def _plan_modes(ctx: PlanContext, moves: Sequence[Move], start: tuple[float, float],
                working_mode: str, rms_limit: tuple[float, float] | None,
                rate: float) -> ProgramResult:
    """The program with the working modes chosen: dynamic programming over the motions, the
    state the (working, assembly) mode at each motion's end, the cost the planned durations;
    each candidate motion planned once per mode it may start in. The best sequence is then
    planned as a program of its own and its moves numbered as the program's."""
    auto = working_mode == AUTO
    robot, asm = ctx.robot, ctx.assembly
    P0 = np.asarray(start, float)
    check_reach(robot, P0[None, :], lambda i: "the start", SI.point_text,
                lambda v: f"{SI.mm(v):.6g} mm")
    layer: dict[tuple[str, str], _Node] = {}
    failed: list[tuple[str, DextarError]] = []
    for m in MODES if auto else (canonical_working_mode(working_mode),):
        try:
            q0 = inverse_kinematics(robot, P0, m)
            check_assembly(robot, q0, P0, m, asm, "the start")
        except DextarError as exc:
            failed.append((m, exc))
            continue
        layer[(m, asm)] = _Node(0.0, PlanState(P0, q0, m, asm), m, ())
    if not layer:
        if len(failed) == 1:
            raise failed[0][1]
        raise AssemblyError(f"working_mode = \"auto\": no working mode reaches the start "
                            f"{SI.point_text(P0)} in assembly mode {asm} ("
                            + "; ".join(f"{m}: {e}" for m, e in failed) + ")")
    plans = 0
    for group in _chains(moves):
        nxt: dict[tuple[str, str], _Node] = {}
        fails: list[tuple[str, str | None, DextarError]] = []
        for node in layer.values():
            for mode in _options(group, node.state, auto):
                parts = _realise(ctx, group, node.state, mode)
                state, cost = node.state, node.cost
                try:
                    for part in parts:
                        pm, state = _plan_group(ctx, [(j, m) for j, m, _ in part], state, 0.0)
                        plans += 1
                        cost += pm.duration_s
                except DextarError as exc:
                    fails.append((node.state.mode, mode, exc))
                    continue
                key = (state.mode, state.assembly)
                if key not in nxt or cost < nxt[key].cost:
                    nxt[key] = _Node(cost, state, node.start_mode,
                                     node.steps + tuple(s for part in parts for s in part))
        if not nxt:
            raise _no_mode(group, fails)
        layer = nxt
    best = min(layer.values(), key=lambda n: n.cost)
    concrete = [m for _, m, _ in best.steps]
    res = plan_program(robot, ctx.inertia, concrete, start=start, working_mode=best.start_mode,
                       assembly=asm, motors=ctx.motors, rms_limit=rms_limit,
                       servo_rate_hz=rate, grid=ctx.grid, tolerances=ctx.tolerances)
    origin = np.array([i for i, _, _ in best.steps])
    planned = [_renumbered(pm, origin, best.steps[pm.index][2]) for pm in res.moves]
    res = replace(res, moves=planned, move_index=origin[res.move_index],
                  move_types=tuple(mv.type for mv in moves))
    ends = {t.index: t.working_mode for t in res.timeline() if not t.mode_change}
    choice = ModeChoice(best.start_mode, tuple(ends[i] for i in range(len(moves))),
                        tuple(i for i, _, inserted in best.steps if inserted), plans)
    return replace(res, mode_choice=choice)


def _renumbered(pm: PlannedMove, origin: Array, inserted: bool) -> PlannedMove:
    """A motion of the concrete program numbered as the program's move it stands for."""
    owner = pm.owner
    if owner is not None:
        inner = owner

        def owner(t: Array) -> Array:
            return np.asarray(origin[inner(t)])

    return replace(pm, index=int(origin[pm.index]), owner=owner, mode_change=inserted,
                   members=tuple((int(origin[k]), s, d) for k, s, d in pm.members))


def _no_mode(group: list[tuple[int, Move]],
             fails: Sequence[tuple[str, str | None, DextarError]]) -> DextarError:
    """The error of a motion that no working mode plans: the move, its target (mm) and, per
    mode tried, the first reason."""
    i, mv = group[-1] if move_type(group[0][1].type).path is not None else group[0]
    target = move_target(mv)
    what = "" if target is None else f" to its target {SI.point_text(target)}"
    seen: dict[str | None, DextarError] = {}
    for _, mode, exc in fails:
        seen.setdefault(mode, exc)
    if len(seen) == 1:  # one mode tried: its own error (it names the move)
        return fails[0][2]
    # the modes that failed for the same reason, together
    modes_of: dict[str, list[str]] = {}
    for mode, exc in seen.items():
        modes_of.setdefault(str(exc), []).append(mode or "its own mode")
    why = "; ".join(f"in {', '.join(modes)}: {text}" for text, modes in modes_of.items())
    first = fails[0][2]
    return type(first)(f"{move_name(i, mv)}: working_mode = \"auto\": no working mode plans "
                       f"it{what} from where the moves before it can leave the robot ({why})")
