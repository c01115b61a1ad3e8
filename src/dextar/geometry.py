"""Geometry of the planar five-bar (RRRRR) robot and the names of its modes.

Conventions (SPEC section 1): fixed pivots ``A = (d/2, 0)`` (motor angle ``phi``, leg 1 with
proximal rod ``AB = l1`` and distal rod ``BP = L1``) and ``D = (-d/2, 0)`` (motor angle
``psi``, leg 2 with ``DC = l2`` and ``CP = L2``). Angles from +x, counter-clockwise.

Working mode (inverse kinematics branch): ``s1 = sign((B - A) x (P - B))``,
``s2 = sign((C - D) x (P - C))``, written ``"+-"`` for ``s1 = +1, s2 = -1``.
Assembly mode (direct kinematics branch): ``sign((B - C) x (P - C))``, ``+1`` = ``"up"``.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from ._arrays import Array
from .errors import GeometryError, ParameterError

WORKING_MODES: tuple[str, ...] = ("++", "+-", "-+", "--")
ASSEMBLY_MODES: dict[str, int] = {"up": 1, "down": -1}


@dataclass(frozen=True)
class FiveBar:
    """Lengths of a general five-bar robot (any consistent length unit).

    Parameters
    ----------
    l1, l2 : float
        Proximal rods ``|AB|`` (driven by ``phi`` at A) and ``|DC|`` (driven by ``psi`` at D).
    L1, L2 : float
        Distal rods ``|BP|`` and ``|CP|``.
    d : float
        Distance ``|AD|`` between the fixed pivots, ``A = (d/2, 0)``, ``D = (-d/2, 0)``.
    """

    l1: float
    l2: float
    L1: float
    L2: float
    d: float

    def __post_init__(self) -> None:
        for name in ("l1", "l2", "L1", "L2", "d"):
            value = getattr(self, name)
            if not isinstance(value, numbers.Real) or isinstance(value, bool):
                raise GeometryError(f"geometry length {name} = {value!r} is not a number")
            if not math.isfinite(value) or value <= 0.0:
                raise GeometryError(
                    f"geometry length {name} = {value!r} must be positive and finite"
                )
        # Each leg reaches an annulus about its pivot; the two annuli must overlap.
        r1, R1 = abs(self.l1 - self.L1), self.l1 + self.L1
        r2, R2 = abs(self.l2 - self.L2), self.l2 + self.L2
        if R1 + R2 < self.d:
            raise GeometryError(
                f"geometry can never close: the legs reach at most l1 + L1 = {R1:g} and "
                f"l2 + L2 = {R2:g}, together less than d = {self.d:g}"
            )
        if r1 - R2 > self.d or r2 - R1 > self.d:
            leg, (rin, other) = (1, (r1, R2)) if r1 - R2 > self.d else (2, (r2, R1))
            raise GeometryError(
                f"geometry can never close: leg {leg} cannot come nearer than |l{leg} - L{leg}| = "
                f"{rin:g} to its pivot, beyond the other leg's reach {other:g} + d = {other + self.d:g}"
            )

    # ------------------------------------------------------------------ derived quantities
    @property
    def A(self) -> Array:
        """Pivot of leg 1, shape (2,)."""
        return np.array([0.5 * self.d, 0.0])

    @property
    def D(self) -> Array:
        """Pivot of leg 2, shape (2,)."""
        return np.array([-0.5 * self.d, 0.0])

    @property
    def is_symmetric(self) -> bool:
        """True when ``l1 == l2`` and ``L1 == L2`` (the DexTAR case)."""
        return math.isclose(self.l1, self.l2) and math.isclose(self.L1, self.L2)

    def reach(self, leg: int) -> tuple[float, float]:
        """Inner and outer radius of the annulus that leg ``leg`` (1 or 2) reaches."""
        l, L = (self.l1, self.L1) if leg == 1 else (self.l2, self.L2)
        return abs(l - L), l + L

    def scaled(self, factor: float) -> FiveBar:
        """The same robot with every length multiplied by ``factor``."""
        return FiveBar(*(factor * v for v in (self.l1, self.l2, self.L1, self.L2, self.d)))

    def as_dict(self) -> dict[str, float]:
        """The five lengths by name."""
        return {"l1": self.l1, "l2": self.l2, "L1": self.L1, "L2": self.L2, "d": self.d}


#: The DexTAR of the paper, in millimetres: ``l = 72``, ``L = 87``, ``d = 60``.
DEXTAR_MM = FiveBar(l1=72.0, l2=72.0, L1=87.0, L2=87.0, d=60.0)

PRESETS: dict[str, FiveBar] = {"dextar": DEXTAR_MM}


def preset(name: str) -> FiveBar:
    """A named geometry in millimetres (``"dextar"``)."""
    try:
        return PRESETS[name.lower()]
    except KeyError:
        raise GeometryError(f"unknown robot preset {name!r}; known: {', '.join(PRESETS)}") from None


#: Aliases of the working modes, for shells where ``--`` is awkward (p = plus, m = minus).
MODE_ALIASES: dict[str, str] = {"pp": "++", "pm": "+-", "mp": "-+", "mm": "--"}


def parse_working_mode(mode: str | tuple[int, int]) -> tuple[int, int]:
    """``"+-"`` (or its alias ``"pm"``) -> ``(1, -1)``; a tuple of two signs is checked.

    The one parser of working modes: the command line and the config files both use it.
    """
    if isinstance(mode, str):
        name = MODE_ALIASES.get(mode.lower(), mode)
        if name not in WORKING_MODES:
            raise ParameterError(f"working mode {mode!r} is not one of {', '.join(WORKING_MODES)} "
                                 f"(aliases {', '.join(MODE_ALIASES)})")
        return (1 if name[0] == "+" else -1, 1 if name[1] == "+" else -1)
    s1, s2 = mode
    if s1 not in (1, -1) or s2 not in (1, -1):
        raise ParameterError(f"working mode {mode!r} must be two signs +1/-1")
    return int(s1), int(s2)


def canonical_working_mode(mode: str | tuple[int, int]) -> str:
    """The canonical name (``"+-"``) of a working mode given by name, alias or signs."""
    return working_mode_name(parse_working_mode(mode))


def working_mode_name(signs: tuple[int, int]) -> str:
    """``(1, -1)`` -> ``"+-"``."""
    return ("+" if signs[0] > 0 else "-") + ("+" if signs[1] > 0 else "-")


def parse_assembly_mode(mode: str | int) -> int:
    """``"up"`` -> +1, ``"down"`` -> -1; +1/-1 pass through."""
    if isinstance(mode, str):
        try:
            return ASSEMBLY_MODES[mode.lower()]
        except KeyError:
            raise ParameterError(f"assembly mode {mode!r} is not 'up' or 'down'") from None
    if mode not in (1, -1):
        raise ParameterError(f"assembly mode {mode!r} must be +1 (up) or -1 (down)")
    return int(mode)


def assembly_mode_name(sign: int) -> str:
    """+1 -> ``"up"``, -1 -> ``"down"``."""
    return "up" if sign > 0 else "down"
