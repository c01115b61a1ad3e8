"""Planning a robot program: a sequence of moves, each with its law, under the motors' limits;
the setpoints at the servo rate, the cycle time and the motor sizing.

A program starts at rest at ``start`` in a working mode. Its moves:

* ``line`` to a point, ``arc`` through ``via`` to a point (or about a ``center`` in a
  ``direction``): task-space paths in the current working mode, checked by the geometry
  checker (reach, both singularity types);
* ``dwell`` for a time: holding still, gravity still loads the motors;
* ``joint`` to a point in a (new) working mode, or to joint angles: a straight line in joint
  space, which may cross serial singularities (how a working mode changes) but not a parallel
  one.

Path moves joined by a blend (``blend > 0`` mm) are one motion: each corner is replaced by a
quintic of continuous curvature that stays within ``blend`` of the corner
(:mod:`dextar.paths.composite`), and the law of the first move of the chain runs over the
whole of it, without stopping at the corners. Other moves start and end at rest. A law is
``time-optimal`` (the fastest within the motors) or a fixed-shape law (``uniform``,
``min-jerk``, ``trapezoid``, ``optimal``) with a duration in seconds or ``"fit"``: the
shortest duration for which the law stays within the motors (regula falsi on a bracket).
The computation is in SI units (m, kg, s, N m).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._arrays import Array
from ..dynamics import (
    Inertia,
    Model,
    RobotAlongJointLine,
    RobotAlongPath,
    gravity_torques,
    inverse_dynamics,
)
from ..errors import ConfigError, DextarError, ParameterError
from ..geometry import FiveBar, canonical_working_mode
from ..kinematics import direct_kinematics, inverse_kinematics, singularity_distances
from ..kinematics.checker import DEFAULT_TOLERANCES, Tolerances
from ..laws import Law, LawRequest, MotorLimits, law_type
from ..laws.time_optimal import solve_time_optimal_law
from ..params import to_run_units
from ..paths import Arc, Line, Path
from ..paths.composite import Composite, Quintic, blended
from ..trajectory import (
    CheckedPath,
    JointLine,
    Trajectory,
    check_path,
    sample_joint_trajectory,
    sample_trajectory,
)
from ..units import SI

#: Move types.
MOVE_TYPES = ("line", "arc", "dwell", "joint")
#: Fewest time-optimal grid segments across a blend.
BLEND_SEGMENTS = 20


@dataclass(frozen=True)
class Move:
    """One move as configured (lengths in mm, angles in degrees, times in s).

    Attributes
    ----------
    index : int
        0-based position in the program.
    type : str
        ``line``, ``arc``, ``dwell`` or ``joint``.
    to : (float, float), optional
        Target point (mm).
    via, center : (float, float), optional
        An arc's intermediate point, or its centre (mm).
    direction : str
        ``ccw`` or ``cw`` for an arc given by its centre.
    time : float
        A dwell's duration (s).
    to_deg : (float, float), optional
        A joint move's target angles (deg).
    working_mode : str, optional
        A joint move's target working mode.
    law : str
        The move's law.
    duration : float or "fit", optional
        A fixed-shape law's duration (s) or ``"fit"``.
    params : mapping
        The law's other keys (config units).
    blend : float
        Radius (mm) of the blend that rounds the corner to the next move (0: stop there).
    """

    index: int
    type: str
    to: tuple[float, float] | None = None
    via: tuple[float, float] | None = None
    center: tuple[float, float] | None = None
    direction: str = "ccw"
    time: float = 0.0
    to_deg: tuple[float, float] | None = None
    working_mode: str | None = None
    law: str = "time-optimal"
    duration: float | str | None = None
    params: Mapping[str, Any] = field(default_factory=dict)
    blend: float = 0.0

    @property
    def name(self) -> str:
        """``move 2 (arc)``."""
        return f"move {self.index} ({self.type})"


@dataclass(frozen=True)
class PlannedMove:
    """A move with its law and where it sits in the cycle.

    Attributes
    ----------
    move : Move
    law : Law, optional
        None for a dwell.
    start_s, duration_s : float
    q0, q1 : ndarray, shape (2,)
        Joint angles at its start and end.
    sample : callable
        ``sample(local times) -> Trajectory``-like arrays ``(P, q, dq, ddq)``.
    min_type1_distance, min_type2_distance : float
        Smallest normalised distances to the singularities along the move.
    owner : callable, optional
        For a blended chain of moves (one motion): the move index at each local time.
    members : tuple of (index, start_s, duration_s)
        For a blended chain: where each of its moves sits in the cycle.
    """

    move: Move
    law: Law | None
    start_s: float
    duration_s: float
    q0: Array
    q1: Array
    sample: Callable[[Array], tuple[Array, Array, Array, Array]]
    min_type1_distance: float
    min_type2_distance: float
    owner: Callable[[Array], Array] | None = None
    members: tuple[tuple[int, float, float], ...] = ()


@dataclass(frozen=True)
class ProgramResult:
    """A planned program: the moves, the setpoints at the servo rate and the motor sizing.

    Attributes
    ----------
    moves : list of PlannedMove
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


def plan_program(robot: FiveBar, inertia: Inertia, moves: Sequence[Move], *,
                 start: tuple[float, float], working_mode: str, assembly: str = "up",
                 motors: MotorLimits | None = None,
                 rms_limit: tuple[float, float] | None = None, servo_rate_hz: float = 1000.0,
                 grid: int = 400, tolerances: Tolerances = DEFAULT_TOLERANCES) -> ProgramResult:
    """Plan the moves from rest at ``start`` (mm) in ``working_mode``.

    Parameters
    ----------
    robot : FiveBar
        The geometry in metres (SI).
    inertia : Inertia
        Masses, friction and gravity in SI.
    moves : sequence of Move
    start : (float, float)
        The start point (mm).
    working_mode, assembly : str
    motors : MotorLimits, optional
        Joint-side limits in SI; required by the time-optimal law and by ``"fit"``.
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
    ConfigError
        A move that cannot be planned, naming the move and the cause.
    """
    if not moves:
        raise ConfigError("the program has no move: add [[move]] tables")
    if not (math.isfinite(servo_rate_hz) and servo_rate_hz > 0):
        raise ParameterError(f"servo rate {servo_rate_hz!r} must be positive")
    mode = canonical_working_mode(working_mode)
    P0 = np.array([SI.length(start[0]), SI.length(start[1])])
    try:
        q0 = inverse_kinematics(robot, P0, mode)
    except DextarError as exc:
        raise ConfigError(f"[program].start: {exc}") from None
    planned: list[PlannedMove] = []
    t0 = 0.0
    for group in _chains(moves):
        mv = group[0]
        try:
            if len(group) == 1:
                pm, P0, q0, mode = _plan_move(robot, inertia, mv, P0, q0, mode, assembly,
                                              motors, grid, tolerances, t0)
            else:
                pm, P0, q0 = _plan_chain(robot, inertia, group, P0, q0, mode, assembly,
                                         motors, grid, tolerances, t0)
        except DextarError as exc:
            names = mv.name if len(group) == 1 else (f"{mv.name} (blended with moves "
                                                      f"{group[1].index}-{group[-1].index})")
            raise ConfigError(f"{names}: {exc}") from None
        planned.append(pm)
        t0 += pm.duration_s
    return _setpoints(robot, inertia, assembly, planned, t0, motors, rms_limit, servo_rate_hz)


def _chains(moves: Sequence[Move]) -> list[list[Move]]:
    """Runs of path moves joined by blends (one motion each); every other move alone."""
    groups: list[list[Move]] = []
    for mv in moves:
        prev = groups[-1][-1] if groups else None
        if (prev is not None and prev.blend > 0 and prev.type in ("line", "arc")
                and mv.type in ("line", "arc")):
            groups[-1].append(mv)
        else:
            groups.append([mv])
    return groups


def _plan_chain(robot: FiveBar, inertia: Inertia, group: list[Move], P0: Array, q0: Array,
                mode: str, assembly: str, motors: MotorLimits | None, grid: int,
                tol: Tolerances, start_s: float) -> tuple[PlannedMove, Array, Array]:
    """Moves joined by blends: one path with G2 corners, one law, no stop at the corners."""
    first = group[0]
    for mv in group[1:]:
        if mv.law != first.law or (mv.duration is not None and mv.duration != first.duration):
            raise ConfigError(f"{mv.name} sets law {mv.law!r} (duration {mv.duration!r}) but a "
                              f"blend makes it one motion with {first.name}, whose law "
                              f"{first.law!r} (duration {first.duration!r}) it takes: set them "
                              "in the first move of the chain only")
    pieces: list[Path] = []
    P = P0
    for mv in group:
        piece: Path = Line(tuple(P), tuple(_target(mv))) if mv.type == "line" else _arc(mv, P)
        pieces.append(piece)
        P = _target(mv)
    try:
        path, owner = _blended(tuple(pieces), tuple(SI.length(mv.blend) for mv in group[:-1]))
    except ParameterError as exc:
        raise ConfigError(f"blend: {exc}") from None
    model = Model(robot, inertia, assembly, tol=tol.type2)
    law, sample, q1, poses = _along_path(robot, model, first, path, q0, mode, motors,
                                         chain_grid(path, grid), tol, samples=801)
    owners = np.array([group[o].index for o in owner])

    def owner_of(t: Array) -> Array:
        s_ = law.evaluate(np.clip(t, 0.0, law.duration))[0]
        return np.asarray(owners[path.piece_at(s_)])

    # when each move starts: the time its first piece starts (s(t) increases)
    tt = np.linspace(0.0, law.duration, 4001)
    ss = law.evaluate(tt)[0]
    starts_s = [float(path.starts[owner.index(k)]) for k in range(len(group))]
    t_at = [float(np.interp(v, ss, tt)) for v in starts_s] + [law.duration]
    members = tuple((mv.index, start_s + t_at[k], t_at[k + 1] - t_at[k])
                    for k, mv in enumerate(group))
    pm = PlannedMove(first, law, start_s, law.duration, q0, q1, sample,
                     float(poses.distances.type1.min()), float(poses.distances.type2.min()),
                     owner_of, members)
    return pm, _target(group[-1]), q1


def _along_path(robot: FiveBar, model: Model, mv: Move, path: Path, q0: Array, mode: str,
                motors: MotorLimits | None, grid: int | Array, tol: Tolerances, samples: int
                ) -> tuple[Law, Callable[[Array], tuple[Array, Array, Array, Array]], Array,
                           CheckedPath]:
    """A task-space motion along ``path`` (a line, an arc or a blended chain): the path
    checked, the law of ``mv`` on it, the sampling ``(P, q, dq, ddq)`` at local times with the
    angles continuous with ``q0`` (unwrapped by whole turns), the end angles and the checked
    poses (``samples``: the law's own sampling, for a fitted duration)."""
    poses = check_path(robot, path, mode=mode, tolerances=tol, units=SI)

    def traj(law: Law, times: Array | None = None) -> Trajectory:
        return sample_trajectory(robot, path, law, mode=mode, times=times, samples=samples,
                                 tolerances=tol, units=SI, checked=False)

    along = RobotAlongPath(model, path, mode, SI, checked=False)  # checked above
    law = _law(mv, path.length, along, motors, grid, traj, model, path)
    shift = np.round((q0 - poses.q[0]) / (2 * np.pi)) * 2 * np.pi

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


def _target(mv: Move) -> Array:
    if mv.to is None:
        raise ConfigError(f"key 'to' is required for a {mv.type} move")
    return np.array([SI.length(mv.to[0]), SI.length(mv.to[1])])


def _arc(mv: Move, P0: Array) -> Path:
    """The arc of a move from ``P0``: through ``via`` to ``to``, or about ``center``."""
    P1 = _target(mv)
    if mv.via is not None:
        V = np.array([SI.length(mv.via[0]), SI.length(mv.via[1])])
        a, b = V - P0, P1 - P0
        den = 2.0 * (a[0] * b[1] - a[1] * b[0])
        scale = max(float(np.linalg.norm(a)), float(np.linalg.norm(b)), 1e-300)
        if abs(den) <= 1e-9 * scale**2:
            raise ConfigError("the start, 'via' and 'to' points are collinear: no circle passes "
                              "through them")
        cx = (b[1] * (a @ a) - a[1] * (b @ b)) / den
        cy = (a[0] * (b @ b) - b[0] * (a @ a)) / den
        C = P0 + np.array([cx, cy])
        cw = den < 0  # the via point is on the clockwise side
    elif mv.center is not None:
        C = np.array([SI.length(mv.center[0]), SI.length(mv.center[1])])
        cw = mv.direction == "cw"
        r0, r1 = np.linalg.norm(P0 - C), np.linalg.norm(P1 - C)
        if abs(r0 - r1) > 1e-6 * max(r0, r1):
            raise ConfigError(f"'to' is {r1 * 1e3:.6g} mm from the centre but the start is "
                              f"{r0 * 1e3:.6g} mm from it: not on one circle")
    else:
        raise ConfigError("an arc needs 'via' or 'center'")
    R = float(np.linalg.norm(P0 - C))
    a0 = math.atan2(P0[1] - C[1], P0[0] - C[0])
    a1 = math.atan2(P1[1] - C[1], P1[0] - C[0])
    if cw:
        a0, a1 = -a0, -a1
    sweep = (a1 - a0) % (2 * math.pi)
    if sweep <= 1e-12:
        sweep = 2 * math.pi
    return Arc(R, a0, a0 + sweep, center=(float(C[0]), float(C[1])), clockwise=cw)


def _law(mv: Move, length: float, dynamics: Any, motors: MotorLimits | None,
         grid: int | Array, traj: Callable[[Law], Trajectory], model: Model,
         path: Path | None) -> Law:
    """The move's law: time-optimal, a fixed-shape law with its duration, or ``"fit"``.
    ``traj(law)`` samples the motion on fixed fractions of the law's duration."""
    if mv.law == "time-optimal":
        if motors is None:
            raise ConfigError("the time-optimal law needs a [motors] table")
        return solve_time_optimal_law(dynamics, motors=motors, grid=grid, units=SI)
    kind = law_type(mv.law)
    if kind.needs_dynamics:
        raise ConfigError(f"law {mv.law!r} is not available in a program")
    params = dict(mv.params)
    mass = model.inertia.point_mass

    def build(duration: float) -> Law:
        values = {k: v for k, v in params.items() if v is not None}
        if "duration" in kind.params and not (kind.name == "trapezoid" and mv.duration is None):
            values["duration"] = duration
        run = to_run_units(values, kind.params, SI)
        req = LawRequest(path if path is not None else _Length(length), run, mass, None, SI)
        return kind.build(req)

    if mv.duration != "fit":
        if isinstance(mv.duration, (int, float)):
            return build(float(mv.duration))
        return build(float(params.get("duration") or 1.0))
    if motors is None:
        raise ConfigError("duration = \"fit\" needs a [motors] table")
    if "duration" not in kind.params:
        raise ConfigError(f"law {mv.law!r} has no duration to fit")

    def sampled(T: float) -> float:
        tr_ = traj(build(T))
        tr, sp = motors.ratios(inverse_dynamics(model, tr_.q, tr_.dq, tr_.ddq), tr_.dq)
        return max(tr, sp)

    return build(_shortest_within(_stretched_ratio(build, traj, model, motors) or sampled))


def _shortest_within(ratio: Callable[[float], float]) -> float:
    """The shortest duration ``T`` (s, to 1e-6 relative) with ``ratio(T) <= 1``: a bracket by
    doubling (or halving), then regula falsi with the Illinois correction, keeping a bracket
    ``ratio(lo) > 1 >= ratio(hi)`` and returning its ``hi``."""
    seen: dict[float, float] = {}

    def r(T: float) -> float:  # the excess over the limits, remembered
        if T not in seen:
            seen[T] = ratio(T) - 1.0
        return seen[T]

    hi = 0.05
    while r(hi) > 0.0:
        hi *= 2.0
        if hi > 1e4:
            raise ConfigError("no duration up to 10^4 s keeps the law within the motors")
    lo = hi / 2.0
    if r(lo) <= 0.0:  # even the first try fits: come down
        while lo > 1e-4 and r(lo) <= 0.0:
            hi, lo = lo, lo / 2.0
    r_lo, r_hi, side = r(lo), r(hi), 0
    for _ in range(100):
        if hi - lo <= 1e-6 * hi:
            break
        if math.isfinite(r_lo) and r_lo > r_hi:  # the secant through the bracket's ends
            mid = hi - r_hi * (hi - lo) / (r_hi - r_lo)
            mid = min(max(mid, lo + 1e-3 * (hi - lo)), hi - 1e-3 * (hi - lo))
        else:
            mid = 0.5 * (lo + hi)
        v = r(mid)
        if v > 0.0:
            lo, r_lo = mid, v
            r_hi = r_hi * 0.5 if side < 0 else r_hi  # Illinois: the stale end's weight halves
            side = -1
        else:
            hi, r_hi = mid, v
            r_lo = r_lo * 0.5 if side > 0 else r_lo
            side = 1
    return hi


def _stretched_ratio(build: Callable[[float], Law],
                     traj: Callable[[Law], Trajectory], model: Model,
                     motors: MotorLimits) -> Callable[[float], float] | None:
    """The motors' ratio at any duration ``T`` from one sampling, for a law whose shape only
    stretches with its duration (``s_T(t) = s_1(t / T)``: uniform, min-jerk); None for other
    laws (checked on the law itself). With the joint motion at ``T = 1`` on the same fractions
    of the motion, ``qdot_T = qdot / T`` and ``qddot_T = qddot / T^2``, so the torques are
    ``(M qddot + c(q, qdot)) / T^2 + g(q) + friction(qdot / T)`` exactly."""
    one, two = build(1.0), build(2.0)
    f = np.linspace(0.0, 1.0, 65)
    scale = np.array([1.0, 2.0, 4.0, 8.0])[:, None]
    a, b = one.evaluate(f), two.evaluate(2.0 * f) * scale
    if not np.allclose(a, b, rtol=1e-9, atol=1e-12 * float(np.abs(a).max())):
        return None
    tr = traj(one)
    q, dq, ddq = tr.q, tr.dq, tr.ddq
    ine = model.inertia
    inertial = inverse_dynamics(Model(model.robot, ine.frictionless(), model.assembly,
                                      tol=model.tol), q, dq, ddq)
    g = gravity_torques(model, q)

    def ratio(T: float) -> float:
        dqT = dq / T
        tr, sp = motors.ratios(inertial / (T * T) + g + ine.friction_torques(dqT), dqT)
        return max(tr, sp)

    return ratio


@dataclass(frozen=True)
class _Length(Path):
    """A stand-in path of a given length (joint moves: laws only need the length)."""

    total: float
    p0: float = 0.0
    p1: float = 1.0
    constant_curvature: float = 0.0

    def derivatives(self, p: object) -> tuple[Array, Array, Array, Array]:
        """A straight segment of the length."""
        p = self._check_parameter(p)
        z = np.zeros(np.shape(p) + (2,))
        r = z.copy()
        r[..., 0] = p * self.total
        d = z.copy()
        d[..., 0] = self.total
        return r, d, z, z.copy()

    @property
    def length(self) -> float:
        """The length."""
        return self.total


def _plan_move(robot: FiveBar, inertia: Inertia, mv: Move, P0: Array, q0: Array, mode: str,
               assembly: str, motors: MotorLimits | None, grid: int, tol: Tolerances,
               start_s: float) -> tuple[PlannedMove, Array, Array, str]:
    model = Model(robot, inertia, assembly, tol=tol.type2)
    if mv.type == "dwell":
        if not mv.time > 0:
            raise ConfigError(f"'time' must be positive, got {mv.time!r}")
        qq = q0.copy()

        def hold(t: Array) -> tuple[Array, Array, Array, Array]:
            n = len(t)
            return (np.tile(P0, (n, 1)), np.tile(qq, (n, 1)), np.zeros((n, 2)),
                    np.zeros((n, 2)))

        if motors is not None:  # holding still against gravity must be within the motors
            g = gravity_torques(Model(robot, inertia, assembly, tol=0.0), q0)
            ratio = np.abs(g) / np.asarray(motors.peak_torque)
            if ratio.max() > 1.0:
                i = int(np.argmax(ratio))
                raise ConfigError(f"the motor at {'AD'[i]} needs {abs(g[i]):.4g} N m to hold "
                                  f"the robot still at {SI.point_text(P0)}, above its peak "
                                  f"torque {motors.peak_torque[i]:.4g} N m")
        d1, d2 = singularity_distances(robot, q0, P0)
        return (PlannedMove(mv, None, start_s, float(mv.time), q0, q0, hold, float(d1),
                            float(d2)), P0, q0, mode)
    if mv.type in ("line", "arc"):
        path: Path = Line(tuple(P0), tuple(_target(mv))) if mv.type == "line" else _arc(mv, P0)
        law, sample, q1, poses = _along_path(robot, model, mv, path, q0, mode, motors, grid,
                                             tol, samples=401)
        P1 = _target(mv)  # exactly where the move was sent (the next starts there)
        return (PlannedMove(mv, law, start_s, law.duration, q0, q1, sample,
                            float(poses.distances.type1.min()),
                            float(poses.distances.type2.min())), P1, q1, mode)
    if mv.type == "joint":
        new_mode = canonical_working_mode(mv.working_mode or mode)
        if mv.to_deg is not None:
            q1 = np.radians(np.asarray(mv.to_deg, float))
        else:
            q1 = inverse_kinematics(robot, _target(mv), new_mode)
            q1 = q1 + np.round((q0 - q1) / (2 * np.pi)) * 2 * np.pi  # the nearest turn
        line = JointLine((float(q0[0]), float(q0[1])), (float(q1[0]), float(q1[1])))

        def jtraj(law: Law, times: Array | None = None) -> Trajectory:
            return sample_joint_trajectory(robot, line, law, assembly=assembly, times=times,
                                           samples=401, tolerances=tol, units=SI)

        law = _law(mv, line.length, RobotAlongJointLine(model, line, SI), motors, grid,
                   jtraj, model, None)
        tr = jtraj(law)
        d1, d2 = singularity_distances(robot, tr.q, tr.P)
        P1 = direct_kinematics(robot, q1, assembly)

        def jsample(t: Array) -> tuple[Array, Array, Array, Array]:
            s = jtraj(law, np.clip(t, 0.0, law.duration))
            return s.P, s.q, s.dq, s.ddq

        m1 = _mode_at(robot, q1, P1, new_mode)
        return (PlannedMove(mv, law, start_s, law.duration, q0, q1, jsample, float(d1.min()),
                            float(d2.min())), P1, q1, m1)
    raise ConfigError(f"unknown move type {mv.type!r}; known: {', '.join(MOVE_TYPES)}")


def _mode_at(robot: FiveBar, q: Array, P: Array, fallback: str) -> str:
    from ..kinematics import working_mode

    m = working_mode(robot, q, P)
    if 0 in m:
        return fallback
    return ("+" if m[0] > 0 else "-") + ("+" if m[1] > 0 else "-")


def _setpoints(robot: FiveBar, inertia: Inertia, assembly: str, planned: list[PlannedMove],
               cycle: float, motors: MotorLimits | None, rms_limit: tuple[float, float] | None,
               rate: float) -> ProgramResult:
    n = int(math.ceil(cycle * rate - 1e-9)) + 1
    t = np.arange(n) / rate
    starts = np.array([pm.start_s for pm in planned])
    idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(planned) - 1)
    P, q, dq, ddq = (np.empty((n, 2)) for _ in range(4))
    move = np.array([pm.move.index for pm in planned])[idx]
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
    model = Model(robot, inertia, assembly, tol=0.0)
    tau = inverse_dynamics(model, q, dq, ddq)
    return ProgramResult(planned, cycle, t, move, P, q, dq, ddq, tau, motors, rms_limit)


def sizing(res: ProgramResult) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Per motor: peak and RMS torque, peak speed, peak power, energy (with their ratios to
    the limits), and the violations (each: motor, quantity, value, limit, move, time)."""
    t, tau, dq = res.t, res.tau, res.dq
    power = tau * dq
    dt = np.diff(t)
    motors_out, violations = [], []
    for i, name in enumerate(("A", "D")):
        pos = np.maximum(power[:, i], 0.0)
        energy = float(np.sum(0.5 * (pos[1:] + pos[:-1]) * dt))
        peak_tau = float(np.abs(tau[:, i]).max())
        rms = float(math.sqrt(np.sum(0.5 * (tau[1:, i] ** 2 + tau[:-1, i] ** 2) * dt)
                              / max(t[-1], 1e-300)))
        entry: dict[str, Any] = {
            "motor": name, "peak_torque_Nm": peak_tau, "rms_torque_Nm": rms,
            "peak_speed_rad_s": float(np.abs(dq[:, i]).max()),
            "peak_power_W": float(np.abs(power[:, i]).max()), "energy_J": energy}
        if res.motors is not None:
            m = res.motors
            avail = m.available_torque(dq)[:, i]
            ratio = np.abs(tau[:, i]) / np.maximum(avail, 1e-300)
            entry["peak_torque_ratio"] = float(ratio.max())
            entry["peak_speed_ratio"] = float(np.abs(dq[:, i]).max() / m.max_speed[i])
            k = int(np.argmax(ratio))
            if ratio[k] > 1.0 + 1e-3:
                violations.append({"motor": name, "quantity": "torque", "value": float(
                    abs(tau[k, i])), "limit": float(avail[k]), "move": int(res.move_index[k]),
                    "t_s": float(t[k])})
            k = int(np.argmax(np.abs(dq[:, i])))
            if abs(dq[k, i]) > m.max_speed[i] * (1 + 1e-3):
                violations.append({"motor": name, "quantity": "speed", "value": float(
                    abs(dq[k, i])), "limit": float(m.max_speed[i]),
                    "move": int(res.move_index[k]), "t_s": float(t[k])})
        if res.rms_limit is not None:
            entry["rms_torque_ratio"] = rms / res.rms_limit[i]
            if rms > res.rms_limit[i] * (1 + 1e-3):
                violations.append({"motor": name, "quantity": "rms_torque", "value": rms,
                                   "limit": float(res.rms_limit[i]), "move": None,
                                   "t_s": None})
        motors_out.append(entry)
    return motors_out, violations
