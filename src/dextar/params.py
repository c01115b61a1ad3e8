"""Declared parameters: a config key's type, unit, default and bounds, checked at the boundary.

Paths and laws declare their keys with :class:`Param` when they register (see
:mod:`dextar.paths.registry` and :mod:`dextar.laws.registry`); the config layer reads any
table against such a declaration with :func:`read_params` (errors name ``[table].key``) and
converts the values from config units to the run's units with :func:`to_run_units`, once.

Units of config keys (what a TOML file speaks) and their conversion:

=============  ===========================================
``"mm"``       lengths (points: each coordinate)
``"mm/s"``     speeds
``"mm/s^2"``   accelerations
``"deg"``      angles (to radians)
``"deg/s"``    angular speeds (to rad per run time unit)
``"rpm"``      motor speeds (to rad per run time unit)
``"s"``        times
``"kg"``       masses
``"N m"``      torques
``"s^2/kg"``   the optimal law's ``eta``
``""``         no unit (counts, words, text)
=============  ===========================================
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, cast

from .errors import ConfigError
from .units import Units

#: The kinds of values a key may hold.
KINDS = ("number", "integer", "text", "point", "points", "pair", "choice")

_REQUIRED = object()

#: The largest length a config may give (mm, any key or coordinate in mm: 1000 km) and the
#: smallest positive one (1 nm): beyond them the squares and fourth powers of the dynamics
#: leave double precision (lengths of 1e300 mm overflowed, 1e-200 mm divided by zero).
MAX_MM = 1e9
MIN_MM = 1e-6


@dataclass(frozen=True)
class Param:
    """One config key.

    Attributes
    ----------
    kind : str
        ``"number"``, ``"integer"``, ``"text"``, ``"point"`` ([x, y]), ``"points"`` (a list
        of points), ``"pair"`` (a number, or [motor A, motor D]) or ``"choice"``.
    unit : str
        The config unit (see the module doc); selects the conversion to run units.
    default : object
        The value when the key is absent; :data:`REQUIRED` when it must be given.
    help : str
        One line for the docs and the command line's help.
    positive : bool
        Numbers must be > 0.
    minimum, maximum : float, optional
        Inclusive bounds on numbers.
    choices : tuple of str
        The allowed words of a ``"choice"``.
    """

    kind: str
    unit: str = ""
    default: Any = _REQUIRED
    help: str = ""
    positive: bool = False
    minimum: float | None = None
    maximum: float | None = None
    choices: tuple[str, ...] = field(default=())

    @property
    def required(self) -> bool:
        """True when the key has no default."""
        return self.default is _REQUIRED


#: The ``default`` of a key that must be given.
REQUIRED = _REQUIRED


def _is_number(v: object) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _where(table: str, key: str) -> str:
    """``config key [table].key`` (a table name already in brackets, ``[[move]] 2 (arc)``,
    is used as it is)."""
    return f"config key {table}.{key}" if table.startswith("[") else f"config key [{table}].{key}"


def number_words(x: float) -> str:
    """A number as a message shows it: NaN called NaN, an infinity ``inf`` or ``-inf``, any
    other in six significant digits."""
    if math.isnan(x):
        return "NaN"
    return f"{x:.6g}"


def _check_number(table: str, key: str, p: Param, v: object) -> float:
    where = _where(table, key)
    if not _is_number(v):
        raise ConfigError(f"{where} must be a number, got {type(v).__name__} {v!r}")
    x = float(cast(float, v))  # a number, checked above
    if not math.isfinite(x):
        raise ConfigError(f"{where} must be finite, got "
                          f"{'NaN' if math.isnan(x) else repr(v)}")
    if p.positive and not x > 0:
        raise ConfigError(f"{where} must be positive, got {v!r}")
    if p.minimum is not None and x < p.minimum:
        raise ConfigError(f"{where} must be at least {p.minimum:g}, got {v!r}")
    if p.maximum is not None and x > p.maximum:
        raise ConfigError(f"{where} must be at most {p.maximum:g}, got {v!r}")
    if p.unit == "mm":
        _check_length(where, x, p.positive)
    return x


def _check_length(where: str, x: float, positive: bool) -> None:
    """A length in mm within :data:`MAX_MM` (and, when positive, at least :data:`MIN_MM`)."""
    if abs(x) > MAX_MM:
        raise ConfigError(f"{where} = {x:g} mm is beyond {MAX_MM:g} mm (1000 km): lengths are "
                          "in mm")
    if positive and x < MIN_MM:
        raise ConfigError(f"{where} = {x:g} mm is below {MIN_MM:g} mm (1 nm): lengths are in "
                          "mm")


def read_value(table: str, key: str, p: Param, v: object) -> Any:
    """Check one value against its declaration; numbers come back as floats, points as
    tuples. Raises :class:`ConfigError` naming ``[table].key``."""
    where = _where(table, key)
    if p.kind == "number":
        return _check_number(table, key, p, v)
    if p.kind == "integer":
        if not isinstance(v, int) or isinstance(v, bool):
            raise ConfigError(f"{where} must be an integer, got {type(v).__name__} {v!r}")
        return int(_check_number(table, key, p, v))
    if p.kind in ("text", "choice"):
        if not isinstance(v, str):
            raise ConfigError(f"{where} must be a string, got {type(v).__name__} {v!r}")
        if p.kind == "choice" and v not in p.choices:
            raise ConfigError(f"{where} must be one of {', '.join(p.choices)}, got {v!r}")
        return v
    if p.kind == "pair":
        if _is_number(v):
            x = _check_number(table, key, p, v)
            return (x, x)
        if isinstance(v, list) and len(v) == 2:
            return tuple(_check_number(table, key, p, x) for x in v)
        raise ConfigError(f"{where} must be a number or a pair of numbers [motor A, motor D], "
                          f"got {type(v).__name__} {v!r}")
    if p.kind == "point":
        return _point(where, v, p.unit)
    if p.kind == "points":
        if not isinstance(v, list):
            raise ConfigError(f"{where} must be a list of points [[x, y], ...], got "
                              f"{type(v).__name__} {v!r}")
        return tuple(_point(f"{where}[{i}]", w, p.unit) for i, w in enumerate(v))
    raise ValueError(f"unknown parameter kind {p.kind!r}")


def _point(where: str, v: object, unit: str = "") -> tuple[float, float]:
    if not (isinstance(v, list) and len(v) == 2 and all(_is_number(x) for x in v)):
        raise ConfigError(f"{where} must be a point [x, y], got {type(v).__name__} {v!r}")
    x, y = (float(c) for c in v)
    if not (math.isfinite(x) and math.isfinite(y)):
        bad = " and ".join(f"{c} is {'NaN' if math.isnan(w) else 'infinite'}"
                           for c, w in (("x", x), ("y", y)) if not math.isfinite(w))
        raise ConfigError(f"{where} must be finite, got {v!r} ({bad})")
    if unit == "mm":
        for w in (x, y):
            _check_length(where, w, False)
    return (x, y)


def read_params(table: str, raw: Mapping[str, object], params: Mapping[str, Param], *,
                ignore: tuple[str, ...] = ()) -> dict[str, Any]:
    """Read a TOML table against its declared keys: unknown keys refused, values checked,
    defaults filled (absent optional keys without a default are left out). Values stay in
    config units."""
    for key in raw:
        if key not in params and key not in ignore:
            raise ConfigError(f"{_where(table, key)} is not known; known keys: "
                              f"{', '.join([*ignore, *params])}")
    out: dict[str, Any] = {}
    for key, p in params.items():
        if key in raw:
            out[key] = read_value(table, key, p, raw[key])
        elif p.required:
            raise ConfigError(f"{_where(table, key)} is required")
        elif p.default is not None:
            out[key] = p.default
    return out


def _converter(unit: str, units: Units) -> Callable[[float], float]:
    table: dict[str, Callable[[float], float]] = {
        "": float,
        "mm": units.length,
        "mm/s": units.speed,
        "mm/s^2": units.acceleration,
        "deg": math.radians,
        "deg/s": lambda v: math.radians(v) * units.time_s,
        "rpm": lambda v: 2 * math.pi / 60 * v * units.time_s,
        "s": units.time,
        "kg": units.mass,
        "N m": units.torque,
        "s^2/kg": lambda v: v * units.mass_kg / units.time_s**2,
    }
    if unit not in table:
        raise ValueError(f"no conversion for the unit {unit!r}")
    return table[unit]


def to_run_units(values: Mapping[str, Any], params: Mapping[str, Param],
                 units: Units) -> dict[str, Any]:
    """The values of :func:`read_params` in the run's units (points and pairs element-wise;
    words and integers unchanged)."""
    out: dict[str, Any] = {}
    for key, v in values.items():
        p = params[key]
        if p.kind in ("text", "choice", "integer") or v is None:
            out[key] = v
            continue
        conv = _converter(p.unit, units)
        if p.kind == "number":
            out[key] = conv(v)
        elif p.kind in ("pair", "point"):
            out[key] = tuple(conv(x) for x in v)
        elif p.kind == "points":
            out[key] = tuple(tuple(conv(x) for x in w) for w in v)
    return out


def describe(params: Mapping[str, Param]) -> str:
    """One line per key for docs and help: ``key (unit, default): help``."""
    lines = []
    for key, p in params.items():
        unit = f"{p.unit}, " if p.unit else ""
        default = "required" if p.required else f"default {p.default!r}"
        lines.append(f"{key} ({unit}{default}): {p.help}")
    return "\n".join(lines)
