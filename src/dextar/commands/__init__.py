"""The commands of the command line, one module each (see :mod:`dextar.commands.base`), in
the registry :data:`COMMANDS`.

A command is a module holding ``add_arguments(parser)`` and ``run(args) -> Result``,
registered with its name and one line of help by :func:`register_command`; installed
packages add theirs through the entry-point group ``dextar.commands``. The module is imported
only when the command's arguments or its run are needed: ``dextar --help`` imports none, and
``dextar CMD`` imports CMD's only.
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
        The dotted name of its module (``add_arguments(parser)``, ``run(args)``).
    help : str
        One line for ``dextar --help`` and the command's own help.
    registries_help : bool
        Its help ends with the registered config tables, move types, path types and laws
        (the commands that read a whole config).
    """

    name: str
    module: str
    help: str = ""
    registries_help: bool = False

    def load(self) -> ModuleType:
        """The command's module, imported."""
        return importlib.import_module(self.module)

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


#: The built-in commands: name, one line of help, whether it lists the registries.
_BUILTIN = (
    ("ik", "inverse kinematics: encoder readings for a point", False),
    ("fk", "direct kinematics: end-effector for encoder readings", False),
    ("workspace", "workspace map with singularity curves and dexterity", False),
    ("plan", "law of motion along the path: samples to CSV, cost", True),
    ("torques", "exact and paper-model motor torques to CSV", True),
    ("simulate", "computed-torque tracking against a perturbed plant (exit 1 when the robot "
     "leaves [control].tolerance_mm, the files written)", True),
    ("export", "export the robot model (mjcf: MuJoCo XML)", True),
    ("program", "plan a robot program under the motors: setpoints and sizing (exit 1 when a "
     "motor limit is exceeded)", True),
    ("excite", "an exciting trajectory for identification (a Fourier series per motor, "
     "regressor condition number minimised, coverage floors checked: a warning below "
     "them) to CSV", False),
    ("identify", "identify the base parameters from measured motion and write a config with "
     "them (exit 1 when poorly determined, not physical or a poor fit)", False),
    ("poses", "measurement poses for a kinematic calibration (D-optimal over the working "
     "modes) to CSV", False),
    ("calibrate", "calibrate the kinematics from measured poses and write a config with the "
     "identified lengths, encoder offsets and instrument frame (exit 1 when the fit does not "
     "fit)", False),
    ("design", "sweep five-bar geometries for a task on Dask: designs, Pareto front, the "
     "chosen robot", True),
    ("run", "reproduce the paper end to end and write a report (exit 1 when a physics check "
     "fails, the files written)", True),
)
for _name, _help, _registries in _BUILTIN:
    register_command(Command(_name, f"{__name__}.{_name}", _help, _registries))
