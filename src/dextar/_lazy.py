"""The one mechanism by which dextar defers an import: a module attribute that imports its
module the first time it is used.

Everything inside dextar is imported at module level, so that the import graph is what the
code says (and ``lint-imports`` checks it). Two kinds of import are deferred, because their
cost is measured and a command that never uses them should not pay it
(``benchmarks/bench_start.py``):

* the heavy third-party modules, scipy's solvers and matplotlib: importing
  ``scipy.optimize``, ``scipy.integrate``, ``scipy.signal`` or ``matplotlib.figure`` takes
  0.2-0.6 s each on a quiet 2-core machine (numpy itself 0.06-0.1 s), against a floor of
  0.25 s for a command's start; written ``optimize = lazy_module("scipy.optimize")`` at the
  top of the module that uses it, and used as ``optimize.least_squares(...)``;
* a package's re-exports (``dextar.laws.solve_optimal_law``), so that importing one module
  of a package does not import all of its siblings: ``__getattr__, __dir__ =
  lazy_attributes(__name__, {"solve_optimal_law": ".optimal", ...})`` in its
  ``__init__.py`` (PEP 562).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from types import ModuleType
from typing import Any, cast


class _LazyModule(ModuleType):
    """A stand-in for a module that imports it at the first attribute looked up."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.__dict__["_lazy_target"] = None

    def _load(self) -> ModuleType:
        target = self.__dict__["_lazy_target"]
        if target is None:
            target = importlib.import_module(self.__name__)
            self.__dict__["_lazy_target"] = target
        return cast(ModuleType, target)

    def __getattr__(self, attr: str) -> Any:
        return getattr(self._load(), attr)

    def __dir__(self) -> list[str]:
        return dir(self._load())


def lazy_module(name: str) -> Any:
    """The module ``name``, imported when one of its attributes is first used."""
    return _LazyModule(name)


def lazy_attributes(package: str, where: Mapping[str, str]
                    ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """A package's ``__getattr__`` and ``__dir__`` (PEP 562) for its re-exports: ``where``
    maps each public name to the module (relative to ``package``) that defines it."""

    def attribute(name: str) -> Any:
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(where[name], package), name)
        globals_of(package)[name] = value  # once: the next lookup is a plain attribute
        return value

    def names() -> list[str]:
        return sorted({*globals_of(package), *where})

    return attribute, names


def globals_of(package: str) -> dict[str, Any]:
    """The namespace of the imported module ``package``."""
    return vars(importlib.import_module(package))
