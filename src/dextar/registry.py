"""The one registry type: named items that the config files, the command line and the docs
list, and that installed packages extend.

Laws, path types, move types, config tables, constraints and commands are each a
:class:`Registry`. A registry maps a name to an item; ``registry.register(item)`` adds one
(under ``item.name``, or the name given), ``registry.lookup(name, where)`` finds one or raises
:class:`UnknownNameError`, which lists the known names.

Plugins. A registry with an entry-point group (``dextar.laws``, ``dextar.paths``,
``dextar.moves``, ``dextar.constraints``, ``dextar.commands``) loads, the first time it is
listed or asked for a name it does not hold, every entry point of that group that the
installed distributions declare. Each names a callable taking no argument that registers
its items, e.g. in a plugin's ``pyproject.toml``::

    [project.entry-points."dextar.moves"]
    nudge = "dextar_nudge:register"      # def register(): register_move(MoveType(...))

A plugin that fails to load is a :class:`PluginError` naming the entry point.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator, MutableMapping
from importlib import metadata
from typing import Generic, TypeVar, cast

from .errors import ConfigError, DextarError

T = TypeVar("T")


class UnknownNameError(ConfigError):
    """A name that no item of a registry has; the message lists the known names.

    Attributes
    ----------
    name : object
        The name asked for.
    known : tuple of str
        The registered names.
    """

    def __init__(self, message: str, name: object, known: tuple[str, ...]) -> None:
        super().__init__(message)
        self.name = name
        self.known = known


class PluginError(DextarError):
    """An installed plugin (an entry point) that failed to load or to register its items."""


class _Deferred:
    """An item registered by where it is defined (``"package.module:attribute"``), imported
    when it is first asked for."""

    def __init__(self, target: str) -> None:
        self.target = target

    def load(self) -> object:
        module, _, attribute = self.target.partition(":")
        return getattr(importlib.import_module(module), attribute)


class Registry(MutableMapping[str, T], Generic[T]):
    """Items by name, in registration order, extended by the plugins of one entry-point group.

    Parameters
    ----------
    what : str
        What an item is, in words (``"law"``), for the docs.
    key : str
        Where a name is written (``"[law].type"``), for the words of an unknown name.
    group : str, optional
        The entry-point group whose plugins register into it (``"dextar.laws"``).
    """

    def __init__(self, what: str, key: str, group: str | None = None) -> None:
        self.what = what
        self.key = key
        self.group = group
        self._items: dict[str, T | _Deferred] = {}
        self._plugins_loaded = group is None
        self._plugin_error: PluginError | None = None

    def register(self, item: T, name: str | None = None) -> T:
        """Add ``item`` under ``name`` (default ``item.name``); a later registration of the
        same name replaces the earlier one. Returns the item (usable as a decorator)."""
        key = name if name is not None else getattr(item, "name", None)
        if key is None:
            key = getattr(item, "NAME", None)
        if not isinstance(key, str) or not key:
            raise TypeError(f"a {self.what} needs a name to be registered, got {key!r}")
        self._items[key] = item
        return item

    def register_deferred(self, name: str, target: str) -> None:
        """Add the item ``target`` (``"package.module:attribute"``) under ``name``, imported
        the first time it is asked for: its name is listed (and checked) without importing
        what defines it."""
        self._items[name] = _Deferred(target)

    def _resolved(self, name: str) -> T:
        item = self._items[name]
        if isinstance(item, _Deferred):
            item = self._items[name] = cast(T, item.load())
        return item

    def lookup(self, name: object, where: str | None = None) -> T:
        """The item ``name``; an :class:`UnknownNameError` naming ``where`` (default the
        registry's ``key``) and listing the known names otherwise."""
        if isinstance(name, str) and name in self._items:
            return self._resolved(name)
        self.load_plugins()
        if isinstance(name, str) and name in self._items:
            return self._resolved(name)
        known = tuple(self._items)
        raise UnknownNameError(f"{where or self.key} must be one of {', '.join(known)}, got "
                               f"{name!r}", name, known)

    def load_plugins(self) -> None:
        """Load the entry points of the registry's group (once; each plugin's callable
        registers its items)."""
        if self._plugin_error is not None:  # said again at every use, never half loaded
            raise self._plugin_error
        if self._plugins_loaded:
            return
        self._plugins_loaded = True  # first: a plugin may consult the registry it extends
        assert self.group is not None
        for ep in metadata.entry_points(group=self.group):
            try:
                register: Callable[[], object] = ep.load()
                register()
            except Exception as exc:
                self._plugin_error = PluginError(
                    f"plugin {ep.name!r} of {self.group} ({ep.value}) failed to load: "
                    f"{type(exc).__name__}: {exc}")
                raise self._plugin_error from exc

    def __getitem__(self, name: str) -> T:
        if name not in self._items:  # (a package registering its own items loads no plugin)
            self.load_plugins()
        return self._resolved(name)

    def __setitem__(self, name: str, item: T) -> None:
        self._items[name] = item

    def __delitem__(self, name: str) -> None:
        del self._items[name]

    def __iter__(self) -> Iterator[str]:
        self.load_plugins()
        return iter(dict(self._items))

    def __len__(self) -> int:
        self.load_plugins()
        return len(self._items)

    def __contains__(self, name: object) -> bool:
        if name not in self._items:
            self.load_plugins()
        return name in self._items

    def __repr__(self) -> str:
        return f"Registry({self.what!r}: {', '.join(self._items)})"
