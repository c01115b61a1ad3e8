"""The ``[program]`` table and the ``[[move]]`` tables of a task file, read into
:class:`~dextar.program.Move` objects (converted from config units to SI once, here), every
key checked against the move type's declaration and named as ``[[move]] 2 (arc).via``."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any, ClassVar

from ..errors import ConfigError, DextarError
from ..geometry import canonical_working_mode
from ..laws import LawType, law_type
from ..params import Param, read_params, read_value, to_run_units
from ..program import MOVE_TYPES, Move, MoveType, move_type
from ..units import SI
from .base import Table


@dataclass(frozen=True)
class ProgramTable(Table):
    """``[program]``: where the program starts and the defaults of its moves."""

    NAME: ClassVar[str] = "program"
    PARAMS: ClassVar[dict[str, Param]] = {
        "start": Param("point", "", None, "start point [x, y] in mm (at rest)"),
        "working_mode": Param("text", "", None, "working mode at the start (default "
                              "[robot].working_mode), or auto: the planner chooses the start's "
                              "mode and the mode of every move that sets none (joint moves to "
                              "a point end in it; a line or an arc runs in it, after a joint "
                              "move at its start that changes the mode through serial "
                              "singularities where needed), the modes that make the cycle "
                              "shortest within the motors (exact: dynamic programming over "
                              "the moves; a blended chain keeps one mode)"),
        "law": Param("text", "", "time-optimal", "default law of every move"),
        "blend": Param("number", "", 0.0, "default corner blend radius, mm", minimum=0.0),
        "grid": Param("integer", "", 400, "time-optimal segments per motion (blended moves "
                      "are one motion; a blend gets at least 20)", minimum=10,
                      maximum=100_000),
        "cycle": Param("choice", "", "as-planned", "as-planned (each move's own law) or "
                       "fit-rms (the shortest cycle within [motors].rms_torque: the moves "
                       "planned within lower peak torques)", choices=("as-planned", "fit-rms")),
    }

    start: tuple[float, float] | None = None
    working_mode: str | None = None
    law: str = "time-optimal"
    blend: float = 0.0
    grid: int = 400
    cycle: str = "as-planned"

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> ProgramTable:
        """Read ``[program]``."""
        t = cls(**read_params(cls.NAME, raw, cls.PARAMS))
        law_type(t.law, "config key [program].law")
        if t.working_mode is not None and t.working_mode != "auto":
            try:
                canonical_working_mode(t.working_mode)
            except DextarError as exc:
                raise ConfigError(f"config key [program].working_mode: {exc} (or "
                                  "\"auto\")") from None
        return t


#: The key of a path move (one that can be blended into the next).
BLEND_PARAM = Param("number", "", None, "corner blend radius, mm", minimum=0.0)


def read_moves(raw: object, program: ProgramTable,
               encoder_offset_deg: tuple[float, float] = (0.0, 0.0)) -> list[Move]:
    """The ``[[move]]`` tables as moves (SI), in order; errors name the move and the key.

    A task file speaks encoder readings: a joint move's ``to_deg`` becomes the geometric
    angles ``to_q = reading + offset`` (rad) of the domain, ``encoder_offset_deg`` the
    ``[robot]`` offsets."""
    if raw is None:
        return []
    if not isinstance(raw, list) or not all(isinstance(m, dict) for m in raw):
        raise ConfigError("config key 'move' must be an array of tables [[move]]")
    moves = [_read_move(i, m, program) for i, m in enumerate(raw)]
    if encoder_offset_deg != (0.0, 0.0):
        off = tuple(math.radians(v) for v in encoder_offset_deg)
        moves = [replace(m, values={**m.values, "to_q": (m.values["to_q"][0] + off[0],
                                                          m.values["to_q"][1] + off[1])})
                 if m.values.get("to_q") is not None else m for m in moves]
    return moves


def _move_kind(label: str, raw: Mapping[str, Any]) -> MoveType:
    if "type" not in raw:
        raise ConfigError(f"config key {label}.type is required: one of "
                          f"{', '.join(MOVE_TYPES)}")
    return move_type(raw["type"], f"config key {label}.type")


def _read_move(i: int, raw: Mapping[str, Any], program: ProgramTable) -> Move:
    kind = raw.get("type")
    label = f"[[move]] {i} ({kind})" if isinstance(kind, str) else f"[[move]] {i}"
    mt = _move_kind(label, raw)
    lt = None
    if mt.has_law:
        lt = law_type(raw.get("law", program.law), f"config key {label}.law")
    law_keys = {k: p for k, p in (lt.params if lt else {}).items() if k != "duration"}
    known = ["type", *mt.params, *(("law", "duration") if lt else ()),
             *(("blend",) if mt.path is not None else ()), *law_keys]
    for key in raw:
        if key not in known:
            raise ConfigError(f"config key {label}.{key} is not known; known keys: "
                              f"{', '.join(known)}")
    own = read_params(label, {k: v for k, v in raw.items() if k in mt.params}, mt.params)
    if mt.check is not None and (why := mt.check(own)) is not None:
        raise ConfigError(f"config key {label}: {why}")
    law_raw = {k: v for k, v in raw.items() if k in law_keys}
    law_params = read_params(label, law_raw, {k: law_keys[k] for k in law_raw})
    values = {mt.si_keys.get(k, k): v for k, v in to_run_units(own, mt.params, SI).items()}
    blend = raw.get("blend")
    blend_mm = (program.blend if blend is None or mt.path is None
                else float(read_value(label, "blend", BLEND_PARAM, blend)))
    return Move(mt.name, values, law=lt.name if lt else "", duration=_duration(label, raw, lt),
                law_params=to_run_units(law_params, law_keys, SI), blend=SI.length(blend_mm))


def _duration(label: str, raw: Mapping[str, Any], lt: LawType | None) -> float | str | None:
    """A move's ``duration``: seconds, ``"fit"`` or None (absent)."""
    if "duration" not in raw:
        return None
    assert lt is not None  # only a move with a law knows the key
    if "duration" not in lt.params:
        raise ConfigError(f"config key {label}.duration: the {lt.name} law has no duration")
    d = raw["duration"]
    if d == "fit":
        return "fit"
    return float(read_value(label, "duration", Param("number", "", None, positive=True), d))
