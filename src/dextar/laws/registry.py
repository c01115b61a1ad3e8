"""Laws of motion by their config name (``[law].type``): each declares its keys and builds a
:class:`~dextar.laws.base.Law` from a :class:`LawRequest`.

Adding a law is one file: the law and one :func:`register_law` call. The config files, the
command line's help and the docs list the laws from here. For example, a constant-speed law
under another name::

    from dextar.laws import Law, LawType, Param, register_law

    register_law(LawType("steady", {"duration": Param("number", "s", 1.0, positive=True)},
                         lambda req: UniformLaw(req.path.length, req.params["duration"])))
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..params import Param
from ..paths import Path
from ..registry import Registry
from ..units import Units

if TYPE_CHECKING:  # (the laws' modules import this one to register themselves)
    from .base import Law


@dataclass(frozen=True)
class LawRequest:
    """What a law is planned from.

    Attributes
    ----------
    path : Path
        The path, in run units.
    params : mapping
        The law's config keys, in run units.
    mass : float
        The moving point mass at P (run units), for laws that weigh it (the optimal law).
    dynamics : object, optional
        The robot along the path (a :class:`~dextar.laws.time_optimal.PathDynamics`), for
        laws planned under motor limits; None when the law does not need it.
    units : Units
        The run's units (for the words of an error).
    motors : MotorLimits, optional
        The motors' limits (``[motors]``), for laws planned under them.
    """

    path: Path
    params: Mapping[str, Any]
    mass: float
    dynamics: Any
    units: Units
    motors: Any = None


#: ``shortest(family, t_min) -> T``: the shortest duration ``T >= t_min`` for which the law
#: ``family(T)`` stays within the motors (given by the planner that fits a duration).
Shortest = Callable[[Callable[[float], "Law"], float], float]


@dataclass(frozen=True)
class LawType:
    """A registered law.

    Attributes
    ----------
    name : str
        Its config name (``[law].type``).
    params : mapping of str to Param
        Its config keys.
    build : callable
        ``build(request) -> Law``.
    help : str
        One line for the docs.
    needs_dynamics : bool
        The law is planned on the robot's dynamics (motor limits): the request carries them.
    fit : callable, optional
        How the law's shortest duration within the motors is found (``duration = "fit"`` in
        a program), for a law with more shapes than one per duration:
        ``fit(request, shortest) -> Law``, where ``shortest(family, t_min)`` is the shortest
        duration ``T >= t_min`` for which ``family(T)`` stays within the motors. Without it,
        the law's own duration is fitted.
    """

    name: str
    params: Mapping[str, Param]
    build: Callable[[LawRequest], Law]
    help: str = ""
    needs_dynamics: bool = False
    fit: Callable[[LawRequest, Shortest], Law] | None = None


#: The laws by config name; installed packages add theirs through the entry-point group
#: ``dextar.laws``.
LAW_TYPES: Registry[LawType] = Registry("law", "config key [law].type", group="dextar.laws")


def register_law(kind: LawType) -> LawType:
    """Add a law to the registry (a later registration of the same name replaces it)."""
    return LAW_TYPES.register(kind)


def law_type(name: object, where: str | None = None) -> LawType:
    """The registered law ``name``; an :class:`~dextar.registry.UnknownNameError` (a
    :class:`~dextar.errors.ConfigError`) naming ``where`` lists the known ones."""
    return LAW_TYPES.lookup(name, where)
