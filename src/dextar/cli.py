"""The ``dextar`` command line. Lengths in mm, angles in degrees.

Every failure is one line on stderr and exit status 2; no traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from . import __version__
from .config import RobotConfig, check_tables, load_toml, robot_from_table
from .errors import ConfigError, DextarError

_MODE_ALIASES = {"pp": "++", "pm": "+-", "mp": "-+", "mm": "--"}


def _mode_arg(text: str) -> str:
    """A working mode: ``+-`` or its alias ``pm`` (p = plus, m = minus)."""
    mode = _MODE_ALIASES.get(text, text)
    if mode not in _MODE_ALIASES.values():
        raise argparse.ArgumentTypeError(f"working mode {text!r} is not one of ++, +-, -+, --")
    return mode


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:
        sys.stderr.write(f"dextar: error: {message} (see dextar --help)\n")
        raise SystemExit(2)


def _robot(path: str | None) -> RobotConfig:
    if path is None:
        return robot_from_table(None)
    doc = load_toml(path)
    check_tables(doc, {"robot", "path", "law", "inertia", "gravity", "friction", "control",
                       "output", "motion"})
    return robot_from_table(doc.get("robot"))


def _emit(args: argparse.Namespace, payload: dict[str, Any], text: str) -> None:
    print(json.dumps(payload) if args.json else text)


def cmd_ik(args: argparse.Namespace) -> int:
    from .kinematics import inverse_kinematics

    rc = _robot(args.robot)
    mode = args.mode or rc.working_mode
    q = inverse_kinematics(rc.geometry_mm, [args.x, args.y], mode)
    phi, psi = (float(v) for v in np.degrees(q))
    _emit(args, {"phi_deg": phi, "psi_deg": psi, "mode": mode},
          f"phi = {phi:.6f} deg, psi = {psi:.6f} deg (working mode {mode})")
    return 0


def cmd_fk(args: argparse.Namespace) -> int:
    from .kinematics import direct_kinematics

    rc = _robot(args.robot)
    assembly = args.assembly or rc.assembly_mode
    P = direct_kinematics(rc.geometry_mm, np.radians([args.phi, args.psi]), assembly)
    x, y = float(P[0]), float(P[1])
    _emit(args, {"x_mm": x, "y_mm": y, "assembly": assembly},
          f"x = {x:.6f} mm, y = {y:.6f} mm (assembly mode {assembly})")
    return 0


def cmd_workspace(args: argparse.Namespace) -> int:
    from .kinematics import plot_workspace, workspace_map
    from .output.files import save_figure

    rc = _robot(args.robot)
    mode = args.mode or rc.working_mode
    out = Path(args.out)
    if out.suffix.lower() not in (".png", ".svg"):
        raise ConfigError(f"--out {str(out)!r} must end in .png or .svg")
    ws = workspace_map(rc.geometry_mm, mode, resolution=args.resolution)
    save_figure(plot_workspace(ws), out, dpi=150)
    area = ws.reachable_area
    _emit(args, {"out": str(out), "mode": mode, "reachable_area_mm2": area},
          f"wrote {out} (working mode {mode}, reachable area {area:.0f} mm^2)")
    return 0


def build_parser() -> argparse.ArgumentParser:
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
    sp.add_argument("--mode", type=_mode_arg, help="working mode: ++, +-, -+ or -- "
                    "(aliases pp, pm, mp, mm)")
    common(sp)
    sp.set_defaults(func=cmd_ik)

    sp = sub.add_parser("fk", help="direct kinematics: end-effector for actuator angles")
    sp.add_argument("phi", type=float, help="phi in degrees (motor at A)")
    sp.add_argument("psi", type=float, help="psi in degrees (motor at D)")
    sp.add_argument("--assembly", choices=["up", "down"], help="assembly mode")
    common(sp)
    sp.set_defaults(func=cmd_fk)

    sp = sub.add_parser("workspace", help="workspace map with singularity curves and dexterity")
    sp.add_argument("--mode", type=_mode_arg, help="working mode: ++, +-, -+ or -- "
                    "(aliases pp, pm, mp, mm)")
    sp.add_argument("--out", default="workspace.png", help="PNG or SVG file")
    sp.add_argument("--resolution", type=int, default=301, help="grid points on the long side")
    common(sp)
    sp.set_defaults(func=cmd_workspace)

    for register in _EXTRA_COMMANDS:
        register(sub)
    return p


#: Later stages add their sub-commands here (plan, torques, simulate, export, run).
_EXTRA_COMMANDS: list[Callable[[Any], None]] = []


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    # negative numbers are values, not options: "dextar ik -10 120"
    argv = list(sys.argv[1:] if argv is None else argv)
    args = parser.parse_args(_protect_negatives(argv))
    try:
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


def _protect_negatives(argv: list[str]) -> list[str]:
    """Let values that look like options through argparse: ``dextar ik -10 120`` (a negative
    number gets a leading space, which argparse reads as a value) and ``--mode --`` or
    ``--mode -+`` (joined as ``--mode=--``)."""
    out: list[str] = []
    for a in argv:
        if out and out[-1] == "--mode" and a in _MODE_ALIASES.values():
            out[-1] = "--mode=" + next(k for k, v in _MODE_ALIASES.items() if v == a)
            continue
        try:
            float(a)
            out.append(" " + a if a.startswith("-") else a)
        except ValueError:
            out.append(a)
    return out


if __name__ == "__main__":
    raise SystemExit(main())
