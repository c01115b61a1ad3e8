"""Moves of a robot program and the move registry.

A :class:`Move` is one step of a program in SI (m, rad, s); its type, a registered
:class:`MoveType`, declares the type's config keys (with their config units, for the config
layer) and plans it (:mod:`dextar.program.move_types` registers ``line``, ``arc``, ``dwell``
and ``joint``). A new move type is one :func:`register_move` call; see
``tests/program/test_move_registry.py`` for one registered from outside the package.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..params import Param
from ..registry import Registry

if TYPE_CHECKING:
    from ..paths import Path
    from .plan import MovePlan, PlanContext, PlanState


@dataclass(frozen=True)
class Move:
    """One move of a program (SI: m, rad, s).

    Attributes
    ----------
    type : str
        A registered move type (``line``, ``arc``, ``dwell``, ``joint``, ...).
    values : mapping
        The type's own keys in SI (``to``: a point in m, ``time``: s, ``to_q``: rad, ...).
    law : str
        The move's law (a registered law's name); ignored by types without a law.
    duration : float or "fit", optional
        A fixed-shape law's duration (s), ``"fit"`` (the shortest within the motors), or
        None (the law's default).
    law_params : mapping
        The law's other keys, in SI.
    blend : float
        Radius (m) of the blend that rounds the corner to the next move (0: stop there).
    """

    type: str
    values: Mapping[str, Any] = field(default_factory=dict)
    law: str = "time-optimal"
    duration: float | str | None = None
    law_params: Mapping[str, Any] = field(default_factory=dict)
    blend: float = 0.0

    def get(self, key: str, default: Any = None) -> Any:
        """The value of the type's key ``key`` (``default`` when absent)."""
        return self.values.get(key, default)


#: ``plan(context, move, state) -> MovePlan``: the move planned from the state the previous
#: move left (errors are named with the move by the program's planner).
Planner = Callable[["PlanContext", Move, "PlanState"], "MovePlan"]


@dataclass(frozen=True)
class MoveType:
    """A registered move type.

    Attributes
    ----------
    name : str
        Its config name (``type`` of a ``[[move]]``).
    params : mapping of str to Param
        Its own config keys (config units: mm, deg, s), required ones with
        :data:`dextar.params.REQUIRED`.
    plan : callable
        :data:`Planner`: the move planned from a state.
    path : callable, optional
        ``path(move, start) -> Path``: the task-space path from the start point (m), for
        types that move along one; such moves can be joined by blends into one motion.
    has_law : bool
        The move has a law (false for a dwell).
    check : callable, optional
        ``check(values) -> message or None``: a rule across keys (values as read, config
        units), the message naming what is wrong.
    si_keys : mapping of str to str
        Config keys whose value goes into :attr:`Move.values` under another name, because
        the config's name says a unit the SI value no longer has (``to_deg`` -> ``to_q``).
    help : str
        One line for the docs.
    """

    name: str
    params: Mapping[str, Param]
    plan: Planner
    path: Callable[[Move, Any], Path] | None = None
    has_law: bool = True
    check: Callable[[Mapping[str, Any]], str | None] | None = None
    si_keys: Mapping[str, str] = field(default_factory=dict)
    help: str = ""


#: The move types by config name; installed packages add theirs through the entry-point
#: group ``dextar.moves``.
MOVE_TYPES: Registry[MoveType] = Registry("move type", "config key [[move]].type",
                                          group="dextar.moves")


def register_move(kind: MoveType) -> MoveType:
    """Add a move type to the registry (a later registration of the same name replaces it)."""
    return MOVE_TYPES.register(kind)


def move_type(name: object, where: str | None = None) -> MoveType:
    """The registered move type ``name``; an :class:`~dextar.registry.UnknownNameError` (a
    :class:`~dextar.errors.ConfigError`) naming ``where`` lists the known ones."""
    return MOVE_TYPES.lookup(name, where)
