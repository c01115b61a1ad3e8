"""The ``dextar`` command line: parse, run one command (:mod:`dextar.commands`), print.

Lengths in mm, angles in degrees. Every failure is one line on stderr and exit status 2; no
traceback. ``--out -`` writes a CSV or JSON result to stdout (the messages then go to stderr).
"""

from __future__ import annotations

import argparse
import atexit
import json
import os
import signal
import sys
import threading
import warnings
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, NoReturn

from . import __version__, config
from ._lazy import lazy_module
from .commands import COMMANDS
from .commands.base import Result
from .errors import DextarError
from .geometry import MODE_ALIASES

if TYPE_CHECKING:  # the registries, imported when a help that lists them is shown
    from . import laws, paths, program
else:
    laws = lazy_module("dextar.laws")
    paths = lazy_module("dextar.paths")
    program = lazy_module("dextar.program")

#: A working mode's alias (``--mode --`` is read as the alias ``mm``).
_ALIAS_OF = {v: k for k, v in MODE_ALIASES.items()}


class _Parser(argparse.ArgumentParser):
    """Usage errors in one line naming the command's help; a command that reads configs
    (``registries``) ends its help with the registered tables, move types, path types and
    laws, looked up only when the help is shown (so that parsing stays light)."""

    registries = False

    def error(self, message: str) -> NoReturn:
        sys.stderr.write(f"dextar: error: {message} (see {self.prog} --help)\n")
        raise SystemExit(2)

    def format_help(self) -> str:
        if self.registries:
            self.epilog = registries_help()
            self.formatter_class = argparse.RawDescriptionHelpFormatter
        return super().format_help()


def registries_help() -> str:
    """The registered config tables, move types, path types and laws."""
    def listing(reg: Mapping[str, Any]) -> str:
        return "\n".join(f"  {k:<14} {v.help}" for k, v in reg.items())

    return (f"config tables: {', '.join(f'[{t}]' for t in config.TABLES)}\n"
            f"[path].type:\n{listing(paths.PATH_TYPES)}\n[law].type:\n"
            f"{listing(laws.LAW_TYPES)}\n[[move]] type:\n{listing(program.MOVE_TYPES)}")


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of every registered command (with ``only``, a command's name:
    every command is listed, and only that one's arguments are added: what parsing its
    command line needs, at a tenth of the cost)."""
    p = _Parser(prog="dextar", description="Five-bar (DexTAR) robot toolkit. Lengths in mm, "
                "angles in degrees on the command line.")
    p.add_argument("--version", action="version", version=f"dextar {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    p.set_defaults(parsers={})
    for name, cmd in COMMANDS.items():
        sp = sub.add_parser(name, help=cmd.help, description=cmd.help)
        sp.registries = cmd.registries_help
        if only is None or only == name:
            cmd.add_arguments(sp)
        p.get_default("parsers")[name] = sp
        sp.set_defaults(command_entry=cmd)
    return p


def _emit(args: argparse.Namespace, res: Result) -> int:
    """Print a command's result: data to stdout (``--out -``), warnings to stderr, then the
    payload (``--json``) or the words (to stderr when stdout carries data)."""
    if res.data is not None:
        sys.stdout.write(res.data)
        sys.stdout.flush()
    for w in res.warnings:
        sys.stderr.write(w + "\n")
    as_json = getattr(args, "json", False)
    if not getattr(args, "quiet", False) or as_json:
        stream = sys.stderr if getattr(args, "out", None) == "-" else sys.stdout
        print(json.dumps(res.payload) if as_json else res.text, file=stream)
    return int(res.code)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line ``argv``; returns the exit status (0, 1 or 2; 130 on interrupt)."""
    # negative numbers are values, not options: "dextar ik -10 120"
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(argv[0] if argv and argv[0] in COMMANDS else "")
    try:
        args, extra = parser.parse_known_args(_protect_negatives(argv))
        if extra:  # the command's own parser says it, pointing to the command's help
            args.parsers[args.command].error(f"unrecognized arguments: {' '.join(extra)}")
    except SystemExit as exc:  # --help, --version, or a usage error (already printed)
        return int(exc.code or 0) if not isinstance(exc.code, str) else 2
    previous = _terminate_as_interrupt()
    try:
        with warnings.catch_warnings():  # numerical warnings of a failing solve: the error
            warnings.simplefilter("ignore", RuntimeWarning)  # that follows says it in words
            return _emit(args, args.command_entry.run(args))
    except KeyboardInterrupt:
        return _interrupted(args.command)
    except Exception as exc:
        if _RECEIVED:  # the interrupt, seen through a library or a cut-short import
            return _interrupted(args.command)
        return _error(args.command, exc)
    finally:  # a caller's own handlers back (main called from a script or a notebook)
        _restore(previous)


def entry() -> NoReturn:
    """The console command ``dextar`` (and ``python -m dextar``): :func:`main`, then the
    process ends at once. The exit handlers run and the output is flushed, as at any exit,
    but the interpreter is not taken apart object by object: with numpy, scipy and
    matplotlib loaded that takes 0.2 s, a tenth of ``dextar run``, for memory the operating
    system frees at once. (Where a thread of a library still runs, the exit is the usual
    one, which waits for it.) Output that cannot be written (a full disk) is an error, exit
    status 2; a reader that went away (``dextar ... | head``) is not."""
    code = main()
    if any(t is not threading.main_thread() and not t.daemon for t in threading.enumerate()):
        raise SystemExit(code)
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (BrokenPipeError, ValueError):  # the reader is gone; a closed stream
            pass
        except OSError as exc:
            if stream is sys.stdout:
                try:
                    sys.stderr.write(f"dextar: error: the output could not be written: "
                                     f"{exc.strerror or exc}\n")
                    sys.stderr.flush()
                except (OSError, ValueError):
                    pass
            code = 2
    os._exit(code)


def _interrupted(command: str) -> int:
    sys.stderr.write(f"dextar {command}: interrupted\n")
    return 130


def _error(command: str, exc: Exception) -> int:
    """One line on stderr for a command's error (bad input, a file, or a bug); 2."""
    if isinstance(exc, DextarError):
        sys.stderr.write(f"dextar {command}: error: {exc}\n")
    elif isinstance(exc, OSError):
        sys.stderr.write(f"dextar {command}: error: {exc.strerror or exc}: "
                         f"{exc.filename or ''}\n")
    elif os.environ.get("DEXTAR_DEBUG"):
        raise exc
    else:  # a bug, not bad input: still one line, no traceback
        sys.stderr.write(f"dextar {command}: internal error: {type(exc).__name__}: {exc} "
                         "(set DEXTAR_DEBUG=1 for a traceback)\n")
    return 2


#: The interrupts (SIGINT, SIGTERM) this process received while a command ran.
_RECEIVED: list[int] = []


def _terminate_as_interrupt() -> dict[int, Any]:
    """SIGTERM unwinds like Ctrl-C, so staging files are removed on the way out; either is
    noted, so that an error it causes on the way (a library that catches the interrupt and
    fails later, a module whose import it cut short) is reported as the interrupt. Returns
    the handlers it replaced."""
    def handler(signum: int, frame: object) -> None:
        _RECEIVED.append(signum)
        raise KeyboardInterrupt

    _RECEIVED.clear()
    previous: dict[int, Any] = {}
    try:
        for sig in (signal.SIGTERM, signal.SIGINT):
            if signal.getsignal(sig) is not signal.SIG_IGN:  # (ignored by the caller: kept)
                previous[sig] = signal.signal(sig, handler)
    except ValueError:  # not in the main thread (embedded use)
        pass
    return previous


def _restore(previous: dict[int, Any]) -> None:
    for sig, h in previous.items():
        signal.signal(sig, h if h is not None else signal.SIG_DFL)


def _is_number_list(text: str) -> bool:
    """True for comma-separated numbers (``-150,150,50,250``)."""
    try:
        [float(v) for v in text.split(",")]
    except ValueError:
        return False
    return True


def _protect_negatives(argv: list[str]) -> list[str]:
    """Let values that look like options through argparse: ``dextar ik -10 120`` (a negative
    number, or a list of numbers such as ``--region -150,150,50,250``, gets a leading space,
    which argparse reads as a value) and the working modes
    ``--mode --``, ``--mode=-+`` (rewritten to their aliases: argparse would drop ``--``),
    ``--modes --,-+`` (joined as ``--modes=--,-+``)."""
    out: list[str] = []
    for a in argv:
        if a.startswith("--mode=") and a[7:] in _ALIAS_OF:
            out.append("--mode=" + _ALIAS_OF[a[7:]])
            continue
        if out and out[-1] == "--mode" and a in _ALIAS_OF:
            out[-1] = "--mode=" + _ALIAS_OF[a]
            continue
        if out and out[-1] == "--modes" and a.startswith("-"):  # --modes --,+-
            out[-1] = "--modes=" + a
            continue
        try:
            float(a)
            out.append(" " + a if a.startswith("-") else a)
        except ValueError:
            if a.startswith("-") and "," in a and _is_number_list(a):  # --region -150,150,..
                out.append(" " + a)
            else:
                out.append(a)
    return out


if __name__ == "__main__":
    entry()
