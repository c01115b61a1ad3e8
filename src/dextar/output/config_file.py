"""A robot model written as a config file (TOML in config units), loadable by every command."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from ..dynamics import Inertia
from ..errors import DextarError, NumericalError
from ..geometry import FiveBar
from .tables import number


def toml_number(v: float) -> str:
    """A finite number as TOML (the shortest text of the same double)."""
    v = float(v)
    if not math.isfinite(v):
        raise NumericalError(f"value {v!r} to write in a config is not finite")
    return number(v)


def _pair(a: float, b: float) -> str:
    return f"[{toml_number(a)}, {toml_number(b)}]"


def model_toml(robot_mm: FiveBar, working_mode: str, assembly_mode: str, inertia: Inertia,
               *, coulomb_speed_deg_s: float, gravity_mm_s2: tuple[float, float],
               extra: Mapping[str, Mapping[str, Any]] | None = None,
               comment: str = "") -> str:
    """A config with ``[robot]``, ``[inertia]``, ``[friction]``, ``[gravity]`` (and the
    tables of ``extra`` as given) whose model is ``inertia`` (SI) on ``robot_mm``; values in
    config units (mm, kg, kg mm^2, N m, N m s/rad), written to 17 digits."""
    p1, p2 = inertia.proximal
    weights: list[str] = []
    if inertia.has_counterweights:
        try:  # the rods apart from their counterweights (read back, they fold the same)
            p1, p2 = inertia.bare_proximal
        except DextarError:  # rods that no longer hold their record: the folded rods
            pass
        else:
            c1, c2 = inertia.counterweights
            weights = [f"counterweight_mass = {_pair(c1.mass, c2.mass)}",
                       f"counterweight_distance = {_pair(c1.distance * 1e3, c2.distance * 1e3)}",
                       f"counterweight_inertia = {_pair(c1.inertia * 1e6, c2.inertia * 1e6)}"]
    d1, d2 = inertia.distal
    kgmm2 = 1e6
    lines = [f"# {line}" for line in comment.splitlines()] + [
        "",
        "[robot]",
        *(f"{k} = {toml_number(v)}" for k, v in robot_mm.as_dict().items()),
        f'working_mode = "{working_mode}"',
        f'assembly_mode = "{assembly_mode}"',
        "",
        "[inertia]            # kg, mm, kg mm^2",
        f"effector_mass = {toml_number(inertia.effector_mass)}",
        f"payload = {toml_number(inertia.payload)}",
        f"proximal_mass = {_pair(p1.mass, p2.mass)}",
        f"proximal_com = {_pair(p1.com * 1e3, p2.com * 1e3)}",
        f"proximal_inertia = {_pair(p1.inertia * kgmm2, p2.inertia * kgmm2)}",
        f"distal_mass = {_pair(d1.mass, d2.mass)}",
        f"distal_com = {_pair(d1.com * 1e3, d2.com * 1e3)}",
        f"distal_inertia = {_pair(d1.inertia * kgmm2, d2.inertia * kgmm2)}",
        f"rotor_inertia = {_pair(inertia.rotor[0] * kgmm2, inertia.rotor[1] * kgmm2)}",
        *weights,
        "",
        "[friction]           # N m s/rad, N m, deg/s",
        f"viscous = {_pair(*inertia.viscous)}",
        f"coulomb = {_pair(*inertia.coulomb)}",
        f"coulomb_speed_deg_s = {toml_number(coulomb_speed_deg_s)}",
        "",
        "[gravity]            # mm/s^2",
        f"vector = {_pair(*gravity_mm_s2)}",
    ]
    for name, table in (extra or {}).items():
        lines += ["", f"[{name}]"]
        for k, v in table.items():
            if isinstance(v, (list, tuple)):
                lines.append(f"{k} = [{', '.join(toml_number(x) for x in v)}]")
            elif isinstance(v, str):
                lines.append(f'{k} = "{v}"')
            else:
                lines.append(f"{k} = {toml_number(v)}")
    return "\n".join(lines) + "\n"
