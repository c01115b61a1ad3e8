"""The commands of the command line, one module each (see :mod:`dextar.commands.base`), in
the registry :data:`COMMANDS`.

A command is a module holding ``HELP`` (one line), ``add_arguments(parser)`` and
``run(args) -> Result``, registered by name with :func:`register_command`; installed packages
add theirs through the entry-point group ``dextar.commands``. The module is imported only
when the command's arguments or its run are needed, so that ``dextar --help`` stays light.
"""

from __future__ import annotations

import argparse
import importlib
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, cast

from ..registry import Registry

if TYPE_CHECKING:
    from .base import Result


@dataclass(frozen=True)
class Command:
    """A registered command.

    Attributes
    ----------
    name : str
        Its name on the command line (``dextar NAME``).
    module : str
        The dotted name of its module (``HELP``, ``add_arguments``, ``run``; optionally
        ``REGISTRIES_HELP = True`` to end its help with the registered tables and types).
    """

    name: str
    module: str

    def load(self) -> ModuleType:
        """The command's module, imported."""
        return importlib.import_module(self.module)

    @property
    def help(self) -> str:
        """The command's one line of help."""
        return str(getattr(self.load(), "HELP", ""))

    @property
    def registries_help(self) -> bool:
        """Its help ends with the registered tables, move types, path types and laws."""
        return bool(getattr(self.load(), "REGISTRIES_HELP", False))

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        """Add the command's arguments to its parser."""
        self.load().add_arguments(parser)

    @property
    def run(self) -> Callable[[argparse.Namespace], Result]:
        """``run(args) -> Result``."""
        return cast("Callable[[argparse.Namespace], Result]", self.load().run)


#: The commands by name, in the order ``dextar --help`` lists them; installed packages add
#: theirs through the entry-point group ``dextar.commands``.
COMMANDS: Registry[Command] = Registry("command", "command", group="dextar.commands")


def register_command(command: Command) -> Command:
    """Add a command (a later registration of the same name replaces it)."""
    return COMMANDS.register(command)


for _name in ("ik", "fk", "workspace", "plan", "torques", "simulate", "export", "program",
              "excite", "identify", "poses", "calibrate", "design", "run"):
    register_command(Command(_name, f"{__name__}.{_name}"))
