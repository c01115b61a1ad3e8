"""What every command shares: its result, the ``--out`` file rules, the options of a command
that writes a directory, and the words of a law and of the run's units.

A command module (one per command, registered in :data:`dextar.commands.COMMANDS`) holds
``HELP``, ``add_arguments(parser)`` and ``run(args) -> Result``; ``run`` reads the config,
calls its job (:mod:`dextar.jobs`: one library call, one typed result), writes its files and
says what to print. The jobs and the writers are module attributes imported when the command
runs (:mod:`dextar._lazy`), so that ``--help`` and parsing stay light.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from .. import config
from ..errors import ConfigError, DextarError
from ..output.files import write_text

if TYPE_CHECKING:
    from ..config import Scenario
    from ..laws import Law


@dataclass(frozen=True)
class Result:
    """What a command reports: a JSON payload, the same in words, warnings for stderr, for
    ``--out -`` the data for stdout, and the exit status (0, or 1 for a result computed but
    beyond a limit or fitting poorly)."""

    payload: dict[str, Any]
    text: str
    warnings: list[str] = field(default_factory=list)
    data: str | None = None
    code: int = 0


def shown(path: str | Path, name: str | None = None) -> str:
    """A path as printed: no doubled or trailing separators."""
    p = Path(path)
    return str(p / name) if name else str(p)


def out_file(out: str, *suffixes: str) -> Path | None:
    """The ``--out`` file, refused unless it ends in one of ``suffixes``; None for ``-``."""
    if out == "-":
        return None
    p = Path(out)
    if p.suffix.lower() not in suffixes:
        raise ConfigError(f"--out {out!r} must end in {' or '.join(suffixes)} (or be - for "
                          "stdout)")
    if p.is_dir():
        raise ConfigError(f"--out {out!r} is a directory")
    return p


def write_or_hand_back(out: Path | None, text: str) -> tuple[str, str | None]:
    """Write ``text`` atomically to ``out``; for None (stdout) hand it back as data. Returns
    where it went (for the words) and the data."""
    if out is None:
        return "stdout", text
    write_text(out, text)
    return str(out), None


def into_directory(sp: argparse.ArgumentParser, force: str = "write into an existing "
                   "directory (this run's files replace an earlier run's)",
                   default: str | None = None) -> None:
    """The options of a command that writes a directory: --out, --force, --quiet, --json."""
    if default is None:
        sp.add_argument("--out", required=True, help="output directory")
    else:
        sp.add_argument("--out", default=default, help=f"output directory (default {default})")
    sp.add_argument("--force", action="store_true", help=force)
    sp.add_argument("--quiet", action="store_true", help="no progress or summary output")
    sp.add_argument("--json", action="store_true", help="print one JSON object")


def no_figures_argument(sp: argparse.ArgumentParser, what: str) -> None:
    """``--no-figures``: the command's data files only (``what``), no figures and no
    ``report.html`` (batches, headless machines, resumable runs)."""
    sp.add_argument("--no-figures", dest="figures", action="store_false",
                    help=f"write {what} only (no figures, no report.html)")


def wants_figures(args: argparse.Namespace) -> bool:
    """False when the command line said ``--no-figures``."""
    return bool(getattr(args, "figures", True))


def config_argument(sp: argparse.ArgumentParser, *, required: bool = False,
                    help: str = "TOML config (default: the paper's example)") -> None:
    """The config file of a command (positional, optional unless ``required``) and
    ``--model`` (see :func:`model_argument`)."""
    if required:
        sp.add_argument("config", help=help)
    else:
        sp.add_argument("config", nargs="?", help=help)
    model_argument(sp)


def model_argument(sp: argparse.ArgumentParser) -> None:
    """``--model FILE.toml``: the robot, inertia, friction and gravity of a model file
    (``identified.toml``, ``best.toml``) instead of the config's; its other tables kept."""
    sp.add_argument("--model", metavar="MODEL.toml",
                    help="take [robot], [inertia], [friction] and [gravity] from this file "
                    "(identified.toml, best.toml); the config's other tables are kept")


def csv_command(sp: argparse.ArgumentParser) -> None:
    """The options of a command that writes one CSV of a law's samples: ``[config]``,
    ``--json``, ``--out`` (``-`` for stdout), ``--units``."""
    config_argument(sp)
    json_flag(sp)
    sp.add_argument("--out", required=True, help="CSV file (- for stdout)")
    units_argument(sp)


def json_flag(sp: argparse.ArgumentParser) -> None:
    """``--json``: print one JSON object."""
    sp.add_argument("--json", action="store_true", help="print one JSON object")


def units_argument(sp: argparse.ArgumentParser) -> None:
    """``--units si|paper``: the unit system of the outputs (default ``[output].units``)."""
    sp.add_argument("--units", choices=["si", "paper"], default=None,
                    help="unit system of the output (default: the config's [output].units)")


def units_note(sc: Scenario) -> str:
    """The run's unit system in words."""
    u = sc.units
    n = u.names
    if u.system == "paper":
        return (f"paper units: length L = {u.length_mm:g} mm, mass m = {u.mass_kg:g} kg, "
                f"time T = {u.time_s:g} s; angles in rad")
    return f"SI units: {n['length']}, {n['mass']}, {n['time']}; torques in N m; angles in rad"


def law_line(sc: Scenario, law: Law) -> str:
    """The law, its motion time and its solver's status in words."""
    u = sc.units
    secs = law.duration * u.time_s
    time = (f"{secs:.6g} s" if u.system == "si"
            else f"{law.duration:.6g} {u.names['time']} ({secs:.6g} s)")
    return f"{law.name} law: motion time {time}; status {law.status}: {law.message}"


def law_payload(sc: Scenario, law: Law) -> dict[str, Any]:
    """The law's fields of a command's JSON payload."""
    return {"law": law.name, "duration": law.duration,
            "duration_s": law.duration * sc.units.time_s, "status": int(law.status),
            "success": bool(law.success), "message": law.message}


def law_warnings(command: str, law: Law) -> list[str]:
    """A warning when the law's solver did not meet its tolerance."""
    if law.success:
        return []
    return [f"dextar {command}: warning: {law.name} law status {law.status}: {law.message}"]



def load(args: argparse.Namespace, units: str | None = None) -> Scenario:
    """The scenario of ``args.config`` (with ``args.model``'s robot, inertia, friction and
    gravity when given), computed in ``units`` (``--units``; None: as configured)."""
    sc = config.load_scenario(args.config, model=getattr(args, "model", None))
    return sc.in_units(units)


class Noted(Protocol):
    """A config read by a command (:class:`~dextar.config.Scenario`,
    :class:`~dextar.config.KinematicConfig`): its notes, what the user may not have meant
    (:func:`dextar.config.kinematic.config_notes`)."""

    @property
    def notes(self) -> tuple[str, ...]:
        """What the user may not have meant, in words."""


@contextmanager
def noted(cfg: Noted) -> Iterator[None]:
    """An error raised inside the block carries the config's notes (a robot in metres, an
    empty file), where they are the likely cause."""
    try:
        yield
    except DextarError as exc:
        if cfg.notes and exc.args:
            exc.args = (f"{exc.args[0]} (note: {'; '.join(cfg.notes)})", *exc.args[1:])
        raise


def note_lines(command: str, cfg: Noted) -> list[str]:
    """The config's notes as stderr lines, first among a command's warnings: every command
    that reads a config says them."""
    return [f"dextar {command}: note: {n}" for n in cfg.notes]
