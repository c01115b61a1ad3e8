"""The ``[program]`` table and the ``[[move]]`` tables of a task file, read into
:class:`~dextar.program.Move` objects (config units), every key checked and named as
``[[move]] 2 (arc).via``."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from ..errors import ConfigError, DextarError
from ..geometry import canonical_working_mode
from ..laws import law_type
from ..params import Param, read_params, read_value
from ..program import MOVE_TYPES, Move
from .tables import Table, register_table


@dataclass(frozen=True)
class ProgramTable(Table):
    """``[program]``: where the program starts and the defaults of its moves."""

    NAME: ClassVar[str] = "program"
    PARAMS: ClassVar[dict[str, Param]] = {
        "start": Param("point", "", None, "start point [x, y] in mm (at rest)"),
        "working_mode": Param("text", "", None, "working mode at the start (default "
                              "[robot].working_mode)"),
        "law": Param("text", "", "time-optimal", "default law of every move"),
        "blend": Param("number", "", 0.0, "default corner blend radius, mm", minimum=0.0),
        "grid": Param("integer", "", 400, "time-optimal segments per motion (blended moves "
                      "are one motion; a blend gets at least 20)", minimum=10,
                      maximum=100_000),
    }

    start: tuple[float, float] | None = None
    working_mode: str | None = None
    law: str = "time-optimal"
    blend: float = 0.0
    grid: int = 400

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> ProgramTable:
        """Read ``[program]``."""
        t = cls(**read_params(cls.NAME, raw, cls.PARAMS))
        law_type(t.law)
        if t.working_mode is not None:
            try:
                canonical_working_mode(t.working_mode)
            except DextarError as exc:
                raise ConfigError(f"config key [program].working_mode: {exc}") from None
        return t


register_table(ProgramTable)

#: Keys of a move besides its law's.
MOVE_PARAMS: dict[str, Param] = {
    "type": Param("choice", "", None, "line, arc, dwell or joint", choices=MOVE_TYPES),
    "to": Param("point", "", None, "target point [x, y] in mm"),
    "via": Param("point", "", None, "an arc's intermediate point [x, y] in mm"),
    "center": Param("point", "", None, "an arc's centre [x, y] in mm"),
    "direction": Param("choice", "", "ccw", "ccw or cw (arc about a centre)",
                       choices=("ccw", "cw")),
    "time": Param("number", "", None, "dwell time, s", positive=True),
    "to_deg": Param("point", "", None, "a joint move's target angles [phi, psi] in deg"),
    "working_mode": Param("text", "", None, "a joint move's target working mode"),
    "law": Param("text", "", None, "the move's law (default [program].law)"),
    "blend": Param("number", "", None, "corner blend radius, mm", minimum=0.0),
}


def read_moves(raw: object, program: ProgramTable) -> list[Move]:
    """The ``[[move]]`` tables as moves, in order; errors name the move and the key."""
    if raw is None:
        return []
    if not isinstance(raw, list) or not all(isinstance(m, dict) for m in raw):
        raise ConfigError("config key 'move' must be an array of tables [[move]]")
    return [_read_move(i, m, program) for i, m in enumerate(raw)]


def _read_move(i: int, raw: Mapping[str, Any], program: ProgramTable) -> Move:
    kind = raw.get("type")
    label = f"[[move]] {i} ({kind})" if isinstance(kind, str) else f"[[move]] {i}"
    if "type" not in raw:
        raise ConfigError(f"config key {label}.type is required: one of "
                          f"{', '.join(MOVE_TYPES)}")
    law_name = raw.get("law", program.law)
    try:
        lt = law_type(law_name)
    except ConfigError:
        raise ConfigError(f"config key {label}.law must be one of the laws, got "
                          f"{law_name!r}") from None
    law_keys = {k: p for k, p in lt.params.items() if k != "duration"}
    known = {**MOVE_PARAMS, **law_keys}
    for key in raw:
        if key not in known and key != "duration":
            raise ConfigError(f"config key {label}.{key} is not known; known keys: "
                              f"{', '.join([*MOVE_PARAMS, 'duration', *law_keys])}")
    geo = read_params(label, {k: v for k, v in raw.items() if k in MOVE_PARAMS}, MOVE_PARAMS)
    params = read_params(label, {k: v for k, v in raw.items() if k in law_keys}, law_keys)
    duration: float | str | None = None
    if "duration" in raw:
        d = raw["duration"]
        if d == "fit":
            duration = "fit"
        else:
            duration = float(read_value(label, "duration", Param("number", "", None,
                                                                 positive=True), d))
        if "duration" not in lt.params:
            raise ConfigError(f"config key {label}.duration: the {lt.name} law has no duration")
    elif "duration" in lt.params:
        params["duration"] = lt.params["duration"].default
    t = geo["type"]
    need = {"line": ("to",), "arc": ("to",), "dwell": ("time",), "joint": ()}[t]
    for key in need:
        if key not in geo:
            raise ConfigError(f"config key {label}.{key} is required for a {t} move")
    if t == "arc" and ("via" in geo) == ("center" in geo):
        raise ConfigError(f"config key {label}: an arc needs exactly one of 'via' and 'center'")
    if t == "joint" and ("to" in geo) == ("to_deg" in geo):
        raise ConfigError(f"config key {label}: a joint move needs exactly one of 'to' and "
                          "'to_deg'")
    if geo.get("working_mode") is not None:
        try:
            canonical_working_mode(geo["working_mode"])
        except DextarError as exc:
            raise ConfigError(f"config key {label}.working_mode: {exc}") from None
    return Move(i, t, to=geo.get("to"), via=geo.get("via"), center=geo.get("center"),
                direction=geo.get("direction", "ccw"), time=float(geo.get("time") or 0.0),
                to_deg=geo.get("to_deg"), working_mode=geo.get("working_mode"),
                law=lt.name, duration=duration, params=params,
                blend=float(geo["blend"]) if geo.get("blend") is not None else program.blend)
