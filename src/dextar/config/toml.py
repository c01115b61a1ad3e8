"""Reading config files (TOML): a missing file, a syntax error or an unknown table is a
:class:`~dextar.errors.ConfigError` that names the file or the table."""

from __future__ import annotations

import tomllib
from collections.abc import Mapping, Set
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..registry import UnknownNameError


def read_config(path: str | Path) -> tuple[dict[str, Any], bytes]:
    """A TOML config file parsed, and its bytes; a missing file, an unreadable one or a
    syntax error becomes a :class:`ConfigError` naming the file."""
    p = Path(path)
    try:
        text = p.read_bytes()
    except FileNotFoundError:
        raise ConfigError(f"config file {str(p)!r} does not exist") from None
    except OSError as exc:
        raise ConfigError(f"config file {str(p)!r} cannot be read: {exc}") from None
    try:
        return tomllib.loads(text.decode("utf-8")), text
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"config file {str(p)!r} is not valid TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(f"config file {str(p)!r} cannot be read: {exc}") from None


def load_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML file; a missing file or a syntax error becomes a :class:`ConfigError`."""
    return read_config(path)[0]


def check_tables(doc: Mapping[str, Any], known: Set[str]) -> None:
    """Every top-level name of ``doc`` is a known table holding a table."""
    for name, value in doc.items():
        if name not in known:
            raise UnknownNameError(f"config table [{name}] is not known; known tables: "
                                   f"{', '.join(sorted(known))}", name, tuple(sorted(known)))
        if not isinstance(value, dict):
            raise ConfigError(f"config key {name!r} must be a table [{name}]")
