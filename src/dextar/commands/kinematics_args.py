"""Options shared by the kinematics commands (``ik``, ``fk``, ``workspace``)."""

from __future__ import annotations

import argparse

from ..config.kinematic import InstrumentTable
from ..errors import ConfigError, DextarError
from ..geometry import canonical_working_mode

MODE_HELP = "working mode: ++, +-, -+ or -- (aliases pp, pm, mp, mm)"


def _mode(text: str) -> str:
    """A working mode by name or alias, through the one parser the config files use too."""
    try:
        return canonical_working_mode(text)
    except DextarError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def mode_argument(sp: argparse.ArgumentParser) -> None:
    """``--mode``: a working mode."""
    sp.add_argument("--mode", type=_mode, help=MODE_HELP)


def robot_argument(sp: argparse.ArgumentParser) -> None:
    """``--robot FILE.toml``: the robot of a config file."""
    sp.add_argument("--robot", metavar="FILE.toml", help="TOML file with a [robot] table")


def frame_argument(sp: argparse.ArgumentParser, what: str) -> None:
    """``--frame robot|instrument``: the robot frame (default) or the measuring instrument's
    (``[instrument]`` of ``--robot``)."""
    sp.add_argument("--frame", choices=["robot", "instrument"], default="robot",
                    help=f"{what}: the robot frame (default) or the measuring instrument's "
                    "([instrument] of --robot)")


def instrument_of(table: InstrumentTable | None, path: str | None) -> InstrumentTable:
    """The ``[instrument]`` table, or a one-line error when the file has none."""
    if table is None:
        raise ConfigError("--frame instrument needs an [instrument] table in --robot FILE.toml"
                          + ("" if path is None else f" ({path} has none)"))
    return table
