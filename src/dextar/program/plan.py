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

import numpy as np

from .._arrays import Array
from ..dynamics import Inertia, Model, RobotAlongPath, inverse_dynamics
from ..errors import AssemblyError, DextarError, ParameterError
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
from ..trajectory import CheckedPath, Trajectory, check_path, sample_trajectory
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
    continuous over the program) and the working mode."""

    P: Array
    q: Array
    mode: str


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
    """

    law: Law | None
    duration_s: float
    sample: Sampler
    end: PlanState
    min_type1_distance: float
    min_type2_distance: float


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
        Of the whole motion the move belongs to.
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

    def timeline(self) -> list[MoveTiming]:
        """Every move of the program in order, each move of a blended chain on its own."""
        out = []
        for pm in self.moves:
            law = pm.law
            members = pm.members or ((pm.index, pm.start_s, pm.duration_s),)
            for idx, start, dur in members:
                out.append(MoveTiming(
                    idx, self.move_types[idx] if self.move_types else pm.move.type,
                    law.name if law else None, int(law.status) if law else 0,
                    law.message if law else "holding still", start, dur,
                    bool(pm.members) and idx != pm.members[-1][0], pm.min_type1_distance,
                    pm.min_type2_distance))
        return out


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
    working_mode, assembly : str
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
    if not (math.isfinite(servo_rate_hz) and servo_rate_hz > 0):
        raise ParameterError(f"servo rate {servo_rate_hz!r} must be positive")
    ctx = PlanContext(robot, inertia, assembly, motors, grid, tolerances)
    mode = canonical_working_mode(working_mode)
    P0 = np.asarray(start, float)
    check_reach(robot, P0[None, :], lambda i: "the start", SI.point_text,
                lambda v: f"{SI.mm(v):.6g} mm")
    q0 = inverse_kinematics(robot, P0, mode)
    check_assembly(robot, q0, P0, mode, assembly, "the start")
    state = PlanState(P0, q0, mode)
    planned: list[PlannedMove] = []
    t0 = 0.0
    for group in _chains(moves):
        i, mv = group[0]
        try:
            if len(group) == 1:
                mp = move_type(mv.type).plan(ctx, mv, state)
                pm = PlannedMove(i, mv, mp.law, t0, mp.duration_s, state.q, mp.end.q,
                                 mp.sample, mp.min_type1_distance, mp.min_type2_distance)
                state = mp.end
            else:
                pm, state = _plan_chain(ctx, group, state, t0)
        except DextarError as exc:
            raise type(exc)(f"{_chain_name(group, exc)}: {exc}") from None
        planned.append(pm)
        t0 += pm.duration_s
    res = _setpoints(ctx, planned, t0, rms_limit, servo_rate_hz,
                     tuple(mv.type for mv in moves))
    _check_ends(ctx, res, moves)
    return res


def _check_ends(ctx: PlanContext, res: ProgramResult, moves: Sequence[Move]) -> None:
    """Every motion ends where it was sent: the forward kinematics (in the program's
    assembly mode) of its last setpoint, at its end time, within :data:`END_TOL` of the
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
        end = direct_kinematics(robot, q_end, ctx.assembly)
        miss = float(np.hypot(*(end - target)))
        if not miss <= tol:
            raise AssemblyError(
                f"{move_name(last, moves[last])}: sent to {SI.point_text(target)}, it ends at "
                f"{SI.point_text(end)} (the forward kinematics of its last setpoint in assembly "
                f"mode {ctx.assembly}), {SI.mm(miss):.4g} mm away")


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
    if isinstance(member, int) and 0 <= member < len(group):
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
    try:
        path, owner = _blended(tuple(pieces), tuple(float(mv.blend) for _, mv in group[:-1]))
    except ParameterError as exc:
        raise ParameterError(f"blend: {exc}") from None
    try:
        law, sample, q1, poses = along_path(ctx, first, path, state, chain_grid(path, ctx.grid),
                                            samples=801)
    except DextarError as exc:
        _blame_piece(ctx, pieces, state, exc)
        raise
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
                     owner_of, members)
    return pm, PlanState(P, q1, state.mode)


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
    duration)."""
    robot, tol, mode = ctx.robot, ctx.tolerances, state.mode
    poses = check_path(robot, path, mode=mode, tolerances=tol, units=SI)

    def traj(law: Law, times: Array | None = None) -> Trajectory:
        return sample_trajectory(robot, path, law, mode=mode, times=times, samples=samples,
                                 tolerances=tol, units=SI, checked=False)

    along = RobotAlongPath(ctx.model, path, mode, SI, checked=False)  # checked above
    law = move_law(mv, path, along, ctx.motors, grid, traj, ctx.model)
    shift = np.round((state.q - poses.q[0]) / (2 * np.pi)) * 2 * np.pi

    def sample(t: Array) -> tuple[Array, Array, Array, Array]:
        st = traj(law, np.clip(t, 0.0, law.duration))
        return st.P, st.q + shift, st.dq, st.ddq

    return law, sample, poses.q[-1] + shift, poses


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
    tau = inverse_dynamics(ctx.free_model, q, dq, ddq)
    return ProgramResult(planned, cycle, t, move, P, q, dq, ddq, tau, ctx.motors, rms_limit,
                         types, servo_rate_hz=rate)
