"""The ``dextar`` command line. Lengths in mm, angles in degrees.

Every failure is one line on stderr and exit status 2; no traceback.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from . import __version__
from .config import TABLES, RobotConfig, check_tables, load_toml, robot_from_table
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
    check_tables(doc, TABLES)
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
    out = _out_file(args.out, ".png", ".svg")
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
    _terminate_as_interrupt()
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




# ----------------------------------------------------------------------------- stages
def _scenario(path: str | None) -> Any:
    from .scenario import load_scenario

    return load_scenario(path)


def _units_note(sc: Any) -> str:
    u = sc.units
    n = u.names
    if u.system == "paper":
        return (f"paper units: length L = {u.length_mm:g} mm, mass m = {u.mass_kg:g} kg, "
                f"time T = {u.time_s:g} s; angles in rad")
    return f"SI units: {n['length']}, {n['mass']}, {n['time']}; torques in N m; angles in rad"


def _out_file(out: str, *suffixes: str) -> Path:
    """The ``--out`` file, refused unless it ends in one of ``suffixes``."""
    p = Path(out)
    if p.suffix.lower() not in suffixes:
        raise ConfigError(f"--out {out!r} must end in {' or '.join(suffixes)}")
    if p.is_dir():
        raise ConfigError(f"--out {out!r} is a directory")
    return p


def cmd_plan(args: argparse.Namespace) -> int:
    from .output.files import write_text
    from .output.tables import csv_text

    out = _out_file(args.out, ".csv")
    sc = _scenario(args.config)
    law = sc.law()
    tr = sc.trajectory(law)
    write_text(out, csv_text(tr.columns()))
    kin, inert = law.cost_parts(sc.path, sc.inertia.point_mass, sc.law_spec["eta"])
    e = sc.units.names["energy"]
    payload = {"out": str(out), "samples": int(tr.t.size), "law": law.name,
               "cost": kin + inert, "cost_kinetic": kin, "cost_inertial": inert,
               "units": sc.units.describe()}
    _emit(args, payload, f"cost Phi = {kin + inert:.10g} (kinetic {kin:.10g}, inertial "
          f"{inert:.10g}) [{e} x {sc.units.names['time']}]\nwrote {out}: {tr.t.size} samples, "
          f"{law.name} law, working mode {tr.mode} ({_units_note(sc)})")
    return 0


def cmd_torques(args: argparse.Namespace) -> int:
    from .analysis import analyze
    from .output.files import write_text
    from .output.tables import csv_text

    out = _out_file(args.out, ".csv")
    sc = _scenario(args.config)
    an = analyze(sc)
    write_text(out, csv_text(an.columns()))
    peak = np.abs(an.tau).max(axis=0)
    payload: dict[str, Any] = {"out": str(out), "samples": int(an.trajectory.t.size),
                               "peak_torque": [float(v) for v in peak],
                               "units": sc.units.describe()}
    text = (f"wrote {out}: {an.trajectory.t.size} samples; peak |tau| = {peak[0]:.6g}, "
            f"{peak[1]:.6g} [{sc.units.names['torque']}] ({_units_note(sc)})")
    if an.paper is not None:
        payload["paper_model_error"] = an.paper.error
        text += (f"\npaper model (42) error: max {an.paper.error['max_relative']:.1%}, RMS "
                 f"{an.paper.error['rms_relative']:.1%} of the peak exact torque")
    else:
        from .dynamics.paper import paper_model_limits

        why = paper_model_limits(sc.robot, sc.inertia)
        text += f"\nno paper-model columns: the paper's simplified model does not apply ({why})"
    _emit(args, payload, text)
    return 0


def cmd_simulate(args: argparse.Namespace) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .control import simulate_computed_torque
    from .dynamics import Model
    from .output.figures import png_bytes
    from .output.outdir import OutputDir
    from .output.tables import csv_text

    sc = _scenario(args.config)
    tr = sc.trajectory()
    c = sc.control
    controller = Model(sc.robot, sc.inertia, tr.assembly)
    plant_inertia = sc.inertia.scaled_masses(1.0 + c["mass_error"])
    plant_inertia = plant_inertia.with_(payload=plant_inertia.payload + c["payload"])
    plant = Model(sc.robot, plant_inertia, tr.assembly)
    res = simulate_computed_torque(tr, controller, plant, natural_frequency=c["natural_frequency"],
                                   damping=c["damping"], torque_limit=c["torque_limit"],
                                   initial_error=c["initial_error"])
    mm = sc.units.length_mm
    cols = {"t": res.t, "phi_des": tr.q[:, 0], "psi_des": tr.q[:, 1], "phi": res.q[:, 0],
            "psi": res.q[:, 1], "err_phi": res.joint_error[:, 0],
            "err_psi": res.joint_error[:, 1], "task_error_mm": res.task_error * mm,
            "tau1": res.tau[:, 0], "tau2": res.tau[:, 1],
            "saturated": res.saturated.astype(float)}
    summ = res.summary()
    report = {"units": sc.units.describe(), "control": {k: v for k, v in c.items()},
              "max_task_error_mm": summ["max_task_error"] * mm,
              "rms_task_error_mm": summ["rms_task_error"] * mm,
              "final_task_error_mm": summ["final_task_error"] * mm,
              "max_joint_error_deg": float(np.degrees(summ["max_joint_error_rad"])),
              "saturated_fraction": summ["saturated_fraction"]}
    fig, axes = plt.subplots(2, 1, figsize=(6.4, 6), sharex=True)
    axes[0].plot(res.t, res.task_error * mm)
    axes[0].set_ylabel("task-space error [mm]")
    axes[1].plot(res.t, np.degrees(res.joint_error))
    axes[1].set_ylabel("joint error [deg]")
    axes[1].legend([r"$\varphi$", r"$\psi$"])
    axes[1].set_xlabel(f"time [{sc.units.names['time']}]")
    axes[0].set_title(f"Computed-torque tracking: masses {c['mass_error']:+.0%}, unmodelled "
                      f"payload {c['payload_kg']:g} kg", fontsize=10)
    fig.tight_layout()
    with OutputDir(args.out, force=args.force) as od:
        od.write_text("tracking.csv", csv_text(cols))
        od.write_bytes("tracking.png", png_bytes(fig))
        od.write_text("tracking.json", json.dumps(report, indent=2, default=str) + "\n")
    plt.close(fig)
    _emit(args, report, f"wrote {args.out}/tracking.csv, tracking.png, tracking.json: max "
          f"task error {report['max_task_error_mm']:.4g} mm, max joint error "
          f"{report['max_joint_error_deg']:.4g} deg")
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    from .dynamics import Model
    from .export.mjcf import write_mjcf

    sc = _scenario(args.config)
    out = _out_file(args.out, ".xml")
    write_mjcf(Model(sc.robot, sc.inertia, sc.assembly), str(out))
    _emit(args, {"out": str(out), "units": sc.units.describe()},
          f"wrote {out} (MuJoCo model in {_units_note(sc)})")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from .output.run import run

    sc = _scenario(args.config)
    s = run(sc, args.out, force=args.force, quiet=args.quiet)
    if args.json:
        print(json.dumps({"out": args.out, "files": s["files"]}))
    elif not args.quiet:
        claims = s.get("claims", [])
        lines = [f"wrote {len(s['files'])} files to {args.out}/ (open report.html)",
                 f"cost Phi = {s['cost']['total']:.8g}; peak |tau| exact = "
                 f"{max(s['torques']['exact']['peak']):.6g} {s['units']['torque_unit']}"]
        lines += [f"  {c['verdict']:>11}: {c['claim']} ({c['value']:.3g})" for c in claims]
        print("\n".join(lines))
    return 0


def _register_stages(sub: Any) -> None:
    def cfg(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("config", nargs="?", help="TOML config (default: the paper's example)")
        sp.add_argument("--json", action="store_true", help="print one JSON object")

    sp = sub.add_parser("plan", help="law of motion along the path: samples to CSV, cost")
    cfg(sp)
    sp.add_argument("--out", required=True, help="CSV file")
    sp.set_defaults(func=cmd_plan)

    sp = sub.add_parser("torques", help="exact and paper-model motor torques to CSV")
    cfg(sp)
    sp.add_argument("--out", required=True, help="CSV file")
    sp.set_defaults(func=cmd_torques)

    sp = sub.add_parser("simulate", help="computed-torque tracking against a perturbed plant")
    cfg(sp)
    sp.add_argument("--out", default="dextar-sim", help="output directory")
    sp.add_argument("--force", action="store_true", help="write into an existing directory")
    sp.set_defaults(func=cmd_simulate)

    sp = sub.add_parser("export", help="export the robot model (mjcf: MuJoCo XML)")
    sp.add_argument("format", choices=["mjcf"])
    cfg(sp)
    sp.add_argument("--out", required=True, help="XML file")
    sp.set_defaults(func=cmd_export)

    sp = sub.add_parser("run", help="reproduce the paper end to end and write a report")
    cfg(sp)
    sp.add_argument("--out", default="dextar-out", help="output directory (default dextar-out)")
    sp.add_argument("--force", action="store_true", help="write into an existing directory")
    sp.add_argument("--quiet", action="store_true", help="no progress or summary output")
    sp.set_defaults(func=cmd_run)


_EXTRA_COMMANDS.append(_register_stages)


if __name__ == "__main__":
    raise SystemExit(main())
