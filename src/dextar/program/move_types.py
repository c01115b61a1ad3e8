"""The built-in move types: ``line``, ``arc``, ``dwell`` and ``joint`` (each a planner and its
config keys, registered with :func:`dextar.program.moves.register_move`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from .._arrays import Array
from ..dynamics import RobotAlongJointLine, gravity_torques
from ..errors import AssemblyError, DextarError, ParameterError
from ..geometry import canonical_working_mode
from ..kinematics import direct_kinematics, inverse_kinematics, singularity_distances
from ..laws import Law
from ..params import REQUIRED, Param
from ..paths import Line, Path
from ..paths.circles import arc_about, arc_through
from ..trajectory import JointLine, Trajectory, sample_joint_trajectory
from ..units import SI
from .laws import LengthPath, move_law
from .moves import Move, MoveType, move_type, register_move
from .plan import (
    MovePlan,
    PlanContext,
    PlanState,
    canonical_assembly,
    check_assembly,
    mode_at,
    plan_along,
)

#: Samples of a move's own sampling (a fitted duration is checked on them).
MOVE_SAMPLES = 401


def _point(mv: Move, key: str) -> Array:
    return np.asarray(mv.get(key), float)


def line_path(mv: Move, start: Array) -> Path:
    """The straight segment from ``start`` to the move's ``to`` (m)."""
    return Line(tuple(start), tuple(_point(mv, "to")))


def arc_path(mv: Move, start: Array) -> Path:
    """The arc from ``start`` through ``via`` to ``to``, or about ``center`` (m)."""
    if mv.get("via") is not None:
        return arc_through(start, _point(mv, "via"), _point(mv, "to"))
    if mv.get("center") is None:
        raise ParameterError("an arc needs 'via' or 'center'")
    return arc_about(start, _point(mv, "center"), _point(mv, "to"),
                     clockwise=mv.get("direction", "ccw") == "cw", unit=" mm", scale=1e3)


def _plan_path_move(ctx: PlanContext, mv: Move, state: PlanState) -> MovePlan:
    """A line or an arc: its path from the state's point, its law, at rest at ``to``."""
    kind = move_type(mv.type)
    assert kind.path is not None  # registered with a path below
    path = kind.path(mv, state.P)
    pp = plan_along(ctx, mv, path, state, ctx.grid, samples=MOVE_SAMPLES,
                    targets=[(path.length, mv.get("assembly_mode"), "")])
    # exactly where the move was sent, in the assembly mode its path reaches
    end = PlanState(_point(mv, "to"), pp.q1, state.mode, pp.end_assembly)
    d = pp.poses.distances
    return MovePlan(pp.law, pp.law.duration, pp.sample, end, float(d.type1.min()),
                    float(d.type2.min()), pp.torques, pp.crossings)


def _plan_dwell(ctx: PlanContext, mv: Move, state: PlanState) -> MovePlan:
    """Holding still for ``time`` (s); holding against gravity must be within the motors."""
    time = float(mv.get("time", 0.0))
    if not time > 0:
        raise ParameterError(f"'time' must be positive, got {time!r}")
    P0, q0 = state.P, state.q.copy()

    def hold(t: Array) -> tuple[Array, Array, Array, Array]:
        n = len(t)
        return (np.tile(P0, (n, 1)), np.tile(q0, (n, 1)), np.zeros((n, 2)), np.zeros((n, 2)))

    motors = ctx.motors
    if motors is not None:
        g = gravity_torques(replace(ctx.free_model, assembly=state.assembly), state.q)
        ratio = np.abs(g) / np.asarray(motors.peak_torque)
        if ratio.max() > 1.0:
            i = int(np.argmax(ratio))
            raise ParameterError(f"the motor at {'AD'[i]} needs {abs(g[i]):.4g} N m to hold "
                                 f"the robot still at {SI.point_text(P0)}, above its peak "
                                 f"torque {motors.peak_torque[i]:.4g} N m")
    d1, d2 = singularity_distances(ctx.robot, state.q, P0)
    return MovePlan(None, time, hold, state, float(d1), float(d2))


def _plan_joint(ctx: PlanContext, mv: Move, state: PlanState) -> MovePlan:
    """A straight line in joint space to ``to_q`` (rad) or to ``to`` (m) in ``working_mode``
    (the nearest turn); it may change the working mode."""
    robot, q0, assembly = ctx.robot, state.q, state.assembly
    asked = mv.get("assembly_mode")
    if asked is not None and canonical_assembly(asked) != assembly:
        raise AssemblyError(
            f"assembly_mode = \"{canonical_assembly(asked)}\", but a joint move stays in "
            f"assembly mode {assembly}: a straight line in joint space meets the parallel "
            "(type 2) singularity curve only at the edge of the joints' region where the "
            "distal rods still meet, and cannot pass it; change the assembly mode with a line "
            "or an arc across the curve")
    new_mode = canonical_working_mode(mv.get("working_mode") or state.mode)
    if mv.get("to_q") is not None:
        q1 = _point(mv, "to_q")
    else:
        target = _point(mv, "to")
        q1 = inverse_kinematics(robot, target, new_mode)
        check_assembly(robot, q1, target, new_mode, assembly, "the target")
        q1 = q1 + np.round((q0 - q1) / (2 * np.pi)) * 2 * np.pi  # the nearest turn
    line = JointLine((float(q0[0]), float(q0[1])), (float(q1[0]), float(q1[1])))

    def jtraj(law: Law, times: Array | None = None) -> Trajectory:
        return sample_joint_trajectory(robot, line, law, assembly=assembly, times=times,
                                       samples=MOVE_SAMPLES, tolerances=ctx.tolerances,
                                       units=SI)

    model = replace(ctx.model, assembly=assembly)
    law = move_law(mv, LengthPath(line.length), RobotAlongJointLine(model, line, SI),
                   ctx.motors, ctx.grid, jtraj, model)
    tr = jtraj(law)
    d1, d2 = singularity_distances(robot, tr.q, tr.P)
    P1 = direct_kinematics(robot, q1, assembly)

    def sample(t: Array) -> tuple[Array, Array, Array, Array]:
        s = jtraj(law, np.clip(t, 0.0, law.duration))
        return s.P, s.q, s.dq, s.ddq

    end = PlanState(P1, q1, mode_at(robot, q1, P1, new_mode), assembly)
    return MovePlan(law, law.duration, sample, end, float(d1.min()), float(d2.min()))


def _check_mode(v: Mapping[str, Any]) -> str | None:
    if v.get("working_mode") is not None and v["working_mode"] != "auto":
        try:
            canonical_working_mode(v["working_mode"])
        except DextarError as exc:
            return f"working_mode: {exc} (or \"auto\")"
    return None


def _check_arc(v: Mapping[str, Any]) -> str | None:
    if ("via" in v) == ("center" in v):
        return "an arc needs exactly one of 'via' and 'center'"
    return _check_mode(v)


def _check_joint(v: Mapping[str, Any]) -> str | None:
    if ("to" in v) == ("to_deg" in v):
        return "a joint move needs exactly one of 'to' and 'to_deg'"
    if v.get("working_mode") == "auto" and "to_deg" in v:
        return "working_mode = \"auto\" needs a target point 'to' (angles fix the mode)"
    return _check_mode(v)


_TO = Param("point", "mm", REQUIRED, "target point [x, y] in mm")
_ASSEMBLY = Param("choice", "", None, "the assembly mode at the move's end, up or down "
                  "(default: unchanged); another than the start's makes the path cross the "
                  "parallel (type 2) singularity curve under the degeneracy condition "
                  "(law time-optimal)", choices=("up", "down"))

_PATH_MODE = Param("text", "", None, "the working mode the path runs in: ++, +-, -+, -- or "
                   "auto (the planner chooses; see [program].working_mode); another than the "
                   "current one makes the planner change to it first, by a joint move at "
                   "the path's start point (through serial singularities). Default: the "
                   "current mode (auto when [program].working_mode = \"auto\"); a blended "
                   "chain keeps its first move's")

register_move(MoveType("line", {"to": _TO, "assembly_mode": _ASSEMBLY,
                                "working_mode": _PATH_MODE}, _plan_path_move,
                       path=line_path, check=_check_mode, help="a straight segment to a point"))
register_move(MoveType(
    "arc", {"to": _TO,
            "via": Param("point", "mm", None, "an intermediate point [x, y] in mm"),
            "center": Param("point", "mm", None, "the centre [x, y] in mm"),
            "direction": Param("choice", "", "ccw", "ccw or cw (about a centre)",
                               choices=("ccw", "cw")),
            "assembly_mode": _ASSEMBLY, "working_mode": _PATH_MODE},
    _plan_path_move, path=arc_path, check=_check_arc,
    help="an arc through 'via' to a point, or about 'center'"))
register_move(MoveType(
    "dwell", {"time": Param("number", "s", REQUIRED, "dwell time, s", positive=True)},
    _plan_dwell, has_law=False, help="hold still (gravity still loads the motors)"))
register_move(MoveType(
    "joint", {"to": Param("point", "mm", None, "target point [x, y] in mm"),
              "to_deg": Param("point", "deg", None, "target angles [phi, psi] in deg (encoder "
                              "readings: geometric angle - [robot].encoder_offset_deg)"),
              "working_mode": Param("text", "", None, "the target's working mode: ++, +-, -+, "
                                    "-- or auto (the planner chooses the one that makes the "
                                    "cycle shortest; needs 'to'). Default: the current mode "
                                    "(auto when [program].working_mode = \"auto\")"),
              "assembly_mode": Param("choice", "", None, "up or down: a joint move keeps "
                                     "the assembly mode (refused if another)",
                                     choices=("up", "down"))},
    _plan_joint, check=_check_joint, si_keys={"to_deg": "to_q"},
    help="a straight line in joint space (it may change the working mode)"))
