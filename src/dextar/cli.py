"""The ``dextar`` command line. Lengths in mm, angles in degrees.

Every failure is one line on stderr and exit status 2; no traceback. ``--out -`` writes a CSV
or JSON result to stdout (the messages then go to stderr).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import warnings
from collections.abc import Callable, Sequence
from typing import Any, NoReturn

from . import __version__, jobs
from .errors import DextarError
from .geometry import MODE_ALIASES, WORKING_MODES, canonical_working_mode

MODE_HELP = "working mode: ++, +-, -+ or -- (aliases pp, pm, mp, mm)"


def _mode_arg(text: str) -> str:
    """A working mode by name or alias, through the one parser the config files use too."""
    try:
        return canonical_working_mode(text)
    except DextarError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:
        sys.stderr.write(f"dextar: error: {message} (see dextar --help)\n")
        raise SystemExit(2)


def _emit(args: argparse.Namespace, payload: dict[str, Any], text: str) -> None:
    """Print the JSON payload (``--json``) or the text; to stderr when stdout carries data."""
    stream = sys.stderr if getattr(args, "out", None) == "-" else sys.stdout
    print(json.dumps(payload) if args.json else text, file=stream)


def _print(args: argparse.Namespace, res: Any) -> int:
    """Print a job's result: data to stdout (``--out -``), warnings to stderr, then the
    payload (``--json``) or the words."""
    if res.data is not None:
        sys.stdout.write(res.data)
        sys.stdout.flush()
    for w in res.warnings:
        sys.stderr.write(w + "\n")
    if not getattr(args, "quiet", False) or args.json:
        _emit(args, res.payload, res.text)
    return int(res.code)


def _cmd_ik(args: argparse.Namespace) -> int:
    return _print(args, jobs.ik(args.x, args.y, mode=args.mode, robot=args.robot))


def _cmd_fk(args: argparse.Namespace) -> int:
    return _print(args, jobs.fk(args.phi, args.psi, assembly=args.assembly, robot=args.robot))


def _cmd_workspace(args: argparse.Namespace) -> int:
    return _print(args, jobs.workspace(args.out, mode=args.mode, resolution=args.resolution,
                                       robot=args.robot))


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every command (registered stages included)."""
    p = _Parser(prog="dextar", description="Five-bar (DexTAR) robot toolkit. Lengths in mm, "
                "angles in degrees on the command line.")
    p.add_argument("--version", action="version", version=f"dextar {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def common(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--robot", metavar="FILE.toml", help="TOML file with a [robot] table")
        sp.add_argument("--json", action="store_true", help="print one JSON object")

    sp = sub.add_parser("ik", help="inverse kinematics: actuator angles for a point")
    sp.add_argument("x", type=float, help="x in mm")
    sp.add_argument("y", type=float, help="y in mm")
    sp.add_argument("--mode", type=_mode_arg, help=MODE_HELP)
    common(sp)
    sp.set_defaults(func=_cmd_ik)

    sp = sub.add_parser("fk", help="direct kinematics: end-effector for actuator angles")
    sp.add_argument("phi", type=float, help="phi in degrees (motor at A)")
    sp.add_argument("psi", type=float, help="psi in degrees (motor at D)")
    sp.add_argument("--assembly", choices=["up", "down"], help="assembly mode")
    common(sp)
    sp.set_defaults(func=_cmd_fk)

    sp = sub.add_parser("workspace", help="workspace map with singularity curves and dexterity")
    sp.add_argument("--mode", type=_mode_arg, help=MODE_HELP)
    sp.add_argument("--out", default="workspace.png", help="PNG or SVG file")
    sp.add_argument("--resolution", type=int, default=301, help="grid points on the long side")
    common(sp)
    sp.set_defaults(func=_cmd_workspace)

    for register in _EXTRA_COMMANDS:
        register(sub)
    return p


#: Later stages add their sub-commands here (plan, torques, simulate, export, run).
_EXTRA_COMMANDS: list[Callable[[Any], None]] = []


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line ``argv``; returns the exit status (0, 1 or 2; 130 on interrupt)."""
    parser = build_parser()
    # negative numbers are values, not options: "dextar ik -10 120"
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = parser.parse_args(_protect_negatives(argv))
    except SystemExit as exc:  # --help, --version, or a usage error (already printed)
        return int(exc.code or 0) if not isinstance(exc.code, str) else 2
    _terminate_as_interrupt()
    try:
        with warnings.catch_warnings():  # numerical warnings of a failing solve: the error
            warnings.simplefilter("ignore", RuntimeWarning)  # that follows says it in words
            return int(args.func(args))
    except DextarError as exc:
        sys.stderr.write(f"dextar {args.command}: error: {exc}\n")
        return 2
    except OSError as exc:
        sys.stderr.write(f"dextar {args.command}: error: {exc.strerror or exc}: "
                         f"{exc.filename or ''}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write(f"dextar {args.command}: interrupted\n")
        return 130
    except Exception as exc:  # a bug, not bad input: still one line, no traceback
        if os.environ.get("DEXTAR_DEBUG"):
            raise
        sys.stderr.write(f"dextar {args.command}: internal error: {type(exc).__name__}: {exc} "
                         "(set DEXTAR_DEBUG=1 for a traceback)\n")
        return 2


def _terminate_as_interrupt() -> None:
    """SIGTERM unwinds like Ctrl-C, so staging files are removed on the way out."""
    import signal

    def handler(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    try:
        signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not in the main thread (embedded use)
        pass


def _protect_negatives(argv: list[str]) -> list[str]:
    """Let values that look like options through argparse: ``dextar ik -10 120`` (a negative
    number gets a leading space, which argparse reads as a value) and the working modes
    ``--mode --``, ``--mode=-+`` (rewritten to their aliases: argparse would drop ``--``)."""
    out: list[str] = []
    for a in argv:
        if a.startswith("--mode=") and a[7:] in WORKING_MODES:
            out.append("--mode=" + _ALIAS_OF[a[7:]])
            continue
        if out and out[-1] == "--mode" and a in WORKING_MODES:
            out[-1] = "--mode=" + _ALIAS_OF[a]
            continue
        try:
            float(a)
            out.append(" " + a if a.startswith("-") else a)
        except ValueError:
            out.append(a)
    return out


_ALIAS_OF = {v: k for k, v in MODE_ALIASES.items()}


# ----------------------------------------------------------------------------- stages
def _cmd_plan(args: argparse.Namespace) -> int:
    return _print(args, jobs.plan(args.config, args.out))


def _cmd_torques(args: argparse.Namespace) -> int:
    return _print(args, jobs.torques(args.config, args.out))


def _cmd_simulate(args: argparse.Namespace) -> int:
    return _print(args, jobs.simulate(args.config, args.out, force=args.force))


def _cmd_export(args: argparse.Namespace) -> int:
    return _print(args, jobs.export_mjcf(args.config, args.out))


def _cmd_program(args: argparse.Namespace) -> int:
    return _print(args, jobs.program(args.config, args.out, force=args.force))


def _cmd_run(args: argparse.Namespace) -> int:
    return _print(args, jobs.run(args.config, args.out, force=args.force, quiet=args.quiet))


def _cmd_excite(args: argparse.Namespace) -> int:
    return _print(args, jobs.excite(args.config, args.out, duration=args.duration,
                                    harmonics=args.harmonics, base_hz=args.base_hz,
                                    seed=args.seed))


def _cmd_identify(args: argparse.Namespace) -> int:
    return _print(args, jobs.identify(args.data, args.out, config=args.config,
                                      validate=args.validate, cutoff_hz=args.cutoff_hz,
                                      force=args.force))


def _cmd_design(args: argparse.Namespace) -> int:
    progress = None
    if sys.stderr.isatty() and not args.quiet:
        def progress(done: int, total: int) -> None:
            sys.stderr.write(f"\rdesigns {done}/{total}" + ("\n" if done == total else ""))
            sys.stderr.flush()
    return _print(args, jobs.design(args.config, args.out, samples=args.samples,
                                    seed=args.seed, workers=args.workers,
                                    scheduler=args.scheduler, resume=args.resume,
                                    force=args.force, progress=progress))


def _registries_help() -> str:
    """The registered config tables, path types and laws (read when the parser is built, so
    a type registered by a plug-in is listed too)."""
    from .config import TABLES
    from .laws import LAW_TYPES
    from .paths import PATH_TYPES

    laws = "\n".join(f"  {k:<14} {v.help}" for k, v in LAW_TYPES.items())
    paths = "\n".join(f"  {k:<14} {v.help}" for k, v in PATH_TYPES.items())
    return (f"config tables: {', '.join(f'[{t}]' for t in TABLES)}\n"
            f"[path].type:\n{paths}\n[law].type:\n{laws}")


def into_directory(sp: argparse.ArgumentParser, force: str = "write into an existing "
                   "directory") -> None:
    """The options of a command that writes a directory: --out, --force, --quiet, --json."""
    sp.add_argument("--out", required=True, help="output directory")
    sp.add_argument("--force", action="store_true", help=force)
    sp.add_argument("--quiet", action="store_true", help="no progress or summary output")
    sp.add_argument("--json", action="store_true", help="print one JSON object")


def _register_stages(sub: Any) -> None:
    epilog = _registries_help()

    def cfg(sp: argparse.ArgumentParser) -> None:
        sp.formatter_class = argparse.RawDescriptionHelpFormatter
        sp.epilog = epilog
        sp.add_argument("config", nargs="?", help="TOML config (default: the paper's example)")
        sp.add_argument("--json", action="store_true", help="print one JSON object")

    sp = sub.add_parser("plan", help="law of motion along the path: samples to CSV, cost")
    cfg(sp)
    sp.add_argument("--out", required=True, help="CSV file (- for stdout)")
    sp.set_defaults(func=_cmd_plan)

    sp = sub.add_parser("torques", help="exact and paper-model motor torques to CSV")
    cfg(sp)
    sp.add_argument("--out", required=True, help="CSV file (- for stdout)")
    sp.set_defaults(func=_cmd_torques)

    sp = sub.add_parser("simulate", help="computed-torque tracking against a perturbed plant")
    cfg(sp)
    sp.add_argument("--out", default="dextar-sim", help="output directory")
    sp.add_argument("--force", action="store_true", help="write into an existing directory")
    sp.set_defaults(func=_cmd_simulate)

    sp = sub.add_parser("export", help="export the robot model (mjcf: MuJoCo XML)")
    sp.add_argument("format", choices=["mjcf"])
    cfg(sp)
    sp.add_argument("--out", required=True, help="XML file (- for stdout)")
    sp.set_defaults(func=_cmd_export)

    sp = sub.add_parser("program", help="plan a robot program under the motors: setpoints "
                        "and sizing (exit 1 when a motor limit is exceeded)")
    sp.add_argument("config", help="TOML task file with [program], [[move]] and [motors]")
    into_directory(sp)
    sp.set_defaults(func=_cmd_program)

    sp = sub.add_parser("excite", help="an exciting trajectory for identification (a Fourier "
                        "series per motor, regressor condition number minimised) to CSV")
    sp.add_argument("config", help="TOML config: the robot, its prior masses, [motors]")
    sp.add_argument("--json", action="store_true", help="print one JSON object")
    sp.add_argument("--out", required=True, help="CSV file (- for stdout)")
    sp.add_argument("--duration", type=float, default=20.0,
                    help="seconds, rounded up to whole periods (default 20)")
    sp.add_argument("--harmonics", type=int, default=5, help="harmonics per motor (default 5)")
    sp.add_argument("--base-hz", type=float, default=0.2,
                    help="base frequency, Hz (default 0.2: a 5 s period)")
    sp.add_argument("--seed", type=int, default=0, help="seed of the optimiser's starts")
    sp.add_argument("--quiet", action="store_true", help="no summary output")
    sp.set_defaults(func=_cmd_excite)

    sp = sub.add_parser("identify", help="identify the base parameters from measured motion "
                        "and write a config with them")
    sp.add_argument("data", help="CSV with t_s, phi_rad, psi_rad, tau1_Nm, tau2_Nm (SI)")
    sp.add_argument("--config", help="TOML config: the robot and the prior masses")
    sp.add_argument("--validate", metavar="DATA2.csv",
                    help="data not used in the fit: predicted against measured torques")
    sp.add_argument("--cutoff-hz", type=float, default=None,
                    help="low-pass cut-off, Hz (default: from the data's bandwidth)")
    into_directory(sp)
    sp.set_defaults(func=_cmd_identify)

    sp = sub.add_parser("design", help="sweep five-bar geometries for a task on Dask: designs, "
                        "Pareto front, the chosen robot")
    sp.add_argument("config", help="TOML task file (a program task or a run config) with "
                    "[design]")
    into_directory(sp, force="overwrite a non-empty --out")
    sp.add_argument("--samples", type=int, default=None, help="designs (default [design])")
    sp.add_argument("--seed", type=int, default=None, help="sampling seed (default [design])")
    where = sp.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None,
                       help="processes of a local Dask cluster (default: the cores)")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="a running Dask scheduler, e.g. tcp://host:8786")
    sp.add_argument("--resume", action="store_true",
                    help="complete the sweep in --out (evaluate only what is missing)")
    sp.set_defaults(func=_cmd_design)

    sp = sub.add_parser("run", help="reproduce the paper end to end and write a report")
    cfg(sp)
    sp.add_argument("--out", default="dextar-out", help="output directory (default dextar-out)")
    sp.add_argument("--force", action="store_true", help="write into an existing directory")
    sp.add_argument("--quiet", action="store_true", help="no progress or summary output")
    sp.set_defaults(func=_cmd_run)


_EXTRA_COMMANDS.append(_register_stages)


if __name__ == "__main__":
    raise SystemExit(main())
