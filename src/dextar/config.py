"""Configuration files (TOML): tables validated key by key at the boundary.

Config files speak millimetres, degrees, kilograms and seconds. Every unknown key or wrong type
is refused with a :class:`ConfigError` that names the key as ``[table].key``.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .errors import ConfigError, DextarError
from .geometry import FiveBar, canonical_working_mode, parse_assembly_mode, preset

NUMBER = (int, float)

#: Keys that have one home elsewhere: ``[law].samples`` was a second name for the number of
#: written samples, which is ``[output].samples``.
MOVED = {("law", "samples"): "[output].samples (the number of samples written)"}

#: Every table a config file may hold (each command reads the ones it needs).
TABLES = {"robot", "path", "law", "inertia", "friction", "gravity", "control", "paper",
          "output"}


def load_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML file; a missing file or a syntax error becomes a :class:`ConfigError`."""
    p = Path(path)
    try:
        with p.open("rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise ConfigError(f"config file {str(p)!r} does not exist") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"config file {str(p)!r} is not valid TOML: {exc}") from None
    except OSError as exc:
        raise ConfigError(f"config file {str(p)!r} cannot be read: {exc.strerror}") from None


def check_tables(doc: dict[str, Any], known: set[str]) -> None:
    for name, value in doc.items():
        if name not in known:
            raise ConfigError(f"config table [{name}] is not known; known tables: "
                              f"{', '.join(sorted(known))}")
        if not isinstance(value, dict):
            raise ConfigError(f"config key {name!r} must be a table [{name}]")


def take(table: dict[str, Any], name: str, spec: dict[str, Any],
         required: tuple[str, ...] = ()) -> dict[str, Any]:
    """Check ``table`` (the TOML table ``[name]``) against ``spec`` (key -> allowed types).

    Numbers must be finite; ``bool`` is never taken for a number.
    """
    for key, value in table.items():
        if (name, key) in MOVED:
            raise ConfigError(f"config key [{name}].{key} is not known: use "
                              f"{MOVED[name, key]}")
        if key not in spec:
            raise ConfigError(f"config key [{name}].{key} is not known; known keys: "
                              f"{', '.join(spec)}")
        types = spec[key] if isinstance(spec[key], tuple) else (spec[key],)
        ok = isinstance(value, types) and not (isinstance(value, bool) and bool not in types)
        if not ok:
            words = dict.fromkeys("number" if t in NUMBER else t.__name__ for t in types)
            want = " or ".join(words)
            raise ConfigError(f"config key [{name}].{key} must be a {want}, got "
                              f"{type(value).__name__} {value!r}")
        if isinstance(value, float) and not math.isfinite(value):
            raise ConfigError(f"config key [{name}].{key} must be finite, got {value!r}")
    for key in required:
        if key not in table:
            raise ConfigError(f"config key [{name}].{key} is required")
    return dict(table)


@dataclass(frozen=True)
class RobotConfig:
    """The ``[robot]`` table: geometry in millimetres and the two modes."""

    geometry_mm: FiveBar
    working_mode: str = "+-"
    assembly_mode: str = "up"


ROBOT_KEYS: dict[str, Any] = {
    "preset": str, "l1": NUMBER, "l2": NUMBER, "L1": NUMBER, "L2": NUMBER, "d": NUMBER,
    "working_mode": str, "assembly_mode": str,
}


def robot_from_table(table: dict[str, Any] | None) -> RobotConfig:
    t = take(table or {}, "robot", ROBOT_KEYS)
    lengths = {k: t[k] for k in ("l1", "l2", "L1", "L2", "d") if k in t}
    try:
        if "preset" in t:
            base = preset(t["preset"])
            geom = FiveBar(**{**base.as_dict(), **lengths})
        elif lengths:
            missing = [k for k in ("l1", "l2", "L1", "L2", "d") if k not in lengths]
            if missing:
                raise ConfigError(f"config key [robot].{missing[0]} is required when no preset "
                                  "is given")
            geom = FiveBar(**lengths)
        else:
            geom = preset("dextar")
        wm = canonical_working_mode(t.get("working_mode", "+-"))
        am = t.get("assembly_mode", "up")
        parse_assembly_mode(am)
    except ConfigError:
        raise
    except DextarError as exc:
        raise ConfigError(f"config table [robot]: {exc}") from None
    return RobotConfig(geom, wm, am)
