"""Options shared by the kinematics commands (``ik``, ``fk``, ``workspace``)."""

from __future__ import annotations

import argparse

MODE_HELP = "working mode: ++, +-, -+ or -- (aliases pp, pm, mp, mm)"


def _mode(text: str) -> str:
    """A working mode by name or alias, through the one parser the config files use too."""
    from ..errors import DextarError
    from ..geometry import canonical_working_mode

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
