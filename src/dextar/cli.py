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
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from . import __version__
from .config import TABLES, RobotConfig, check_tables, load_toml, robot_from_table
from .errors import ConfigError, DextarError
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


def _robot(path: str | None) -> RobotConfig:
    if path is None:
        return robot_from_table(None)
    doc = load_toml(path)
    check_tables(doc, TABLES)
    return robot_from_table(doc.get("robot"))


def _emit(args: argparse.Namespace, payload: dict[str, Any], text: str) -> None:
    """Print the JSON payload (``--json``) or the text; to stderr when stdout carries data."""
    stream = sys.stderr if getattr(args, "out", None) == "-" else sys.stdout
    print(json.dumps(payload) if args.json else text, file=stream)


def _shown(path: str | Path, name: str | None = None) -> str:
    """A path as printed: no doubled or trailing separators."""
    p = Path(path)
    return str(p / name) if name else str(p)


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
    from .kinematics import workspace_map
    from .output.figures import plot_workspace
    from .output.files import save_figure

    rc = _robot(args.robot)
    mode = args.mode or rc.working_mode
    out = _out_file(args.out, ".png", ".svg")
    ws = workspace_map(rc.geometry_mm, mode, resolution=args.resolution)
    save_figure(plot_workspace(ws), out, dpi=150)
    area = ws.reachable_area
    reach = ws.dexterity[ws.reachable]
    payload = {"out": str(out), "mode": mode, "robot_mm": rc.geometry_mm.as_dict(),
               "resolution": [int(ws.x.size), int(ws.y.size)], "reachable_area_mm2": area,
               "dexterity_mean": float(reach.mean()) if reach.size else 0.0,
               "dexterity_max": float(reach.max()) if reach.size else 0.0,
               "type2_curve_in_workspace": bool((ws.type2[ws.reachable] > 0).any()
                                                and (ws.type2[ws.reachable] < 0).any())}
    _emit(args, payload, f"wrote {out} (working mode {mode}, reachable area {area:.0f} mm^2)")
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
    sp.add_argument("--mode", type=_mode_arg, help=MODE_HELP)
    common(sp)
    sp.set_defaults(func=cmd_ik)

    sp = sub.add_parser("fk", help="direct kinematics: end-effector for actuator angles")
    sp.add_argument("phi", type=float, help="phi in degrees (motor at A)")
    sp.add_argument("psi", type=float, help="psi in degrees (motor at D)")
    sp.add_argument("--assembly", choices=["up", "down"], help="assembly mode")
    common(sp)
    sp.set_defaults(func=cmd_fk)

    sp = sub.add_parser("workspace", help="workspace map with singularity curves and dexterity")
    sp.add_argument("--mode", type=_mode_arg, help=MODE_HELP)
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


def _out_file(out: str, *suffixes: str) -> Path | None:
    """The ``--out`` file, refused unless it ends in one of ``suffixes``; None for ``-``
    (stdout)."""
    if out == "-":
        return None
    p = Path(out)
    if p.suffix.lower() not in suffixes:
        raise ConfigError(f"--out {out!r} must end in {' or '.join(suffixes)} (or be - for "
                          "stdout)")
    if p.is_dir():
        raise ConfigError(f"--out {out!r} is a directory")
    return p


def _write(out: Path | None, text: str) -> str:
    """Write ``text`` atomically to ``out`` (stdout for None); the words for the message."""
    from .output.files import write_text

    if out is None:
        sys.stdout.write(text)
        sys.stdout.flush()
        return "stdout"
    write_text(out, text)
    return str(out)


def _law_line(sc: Any, law: Any) -> str:
    """Motion time and the law solver's outcome, in words."""
    u = sc.units
    secs = law.duration * u.time_s
    time = (f"{secs:.6g} s" if u.system == "si"
            else f"{law.duration:.6g} {u.names['time']} ({secs:.6g} s)")
    return f"{law.name} law: motion time {time}; status {law.status}: {law.message}"


def _law_payload(sc: Any, law: Any) -> dict[str, Any]:
    return {"law": law.name, "duration": law.duration, "duration_s": law.duration * sc.units.time_s,
            "status": int(law.status), "success": bool(law.success), "message": law.message}


def _warn_law(args: argparse.Namespace, law: Any) -> None:
    if not law.success:
        sys.stderr.write(f"dextar {args.command}: warning: {law.name} law status {law.status}: "
                         f"{law.message}\n")


def cmd_plan(args: argparse.Namespace) -> int:
    from .output.tables import csv_text, trajectory_columns

    out = _out_file(args.out, ".csv")
    sc = _scenario(args.config)
    law = sc.law()
    tr = sc.trajectory(law)
    where = _write(out, csv_text(trajectory_columns(tr, sc.units)))
    payload: dict[str, Any] = {"out": where, "samples": int(tr.t.size), **_law_payload(sc, law),
                               "units": sc.units.describe()}
    lines = [_law_line(sc, law)]
    if law.name == "optimal":
        kin, inert = law.kinetic, law.inertial
        payload.update(cost=kin + inert, cost_kinetic=kin, cost_inertial=inert)
        lines.append(f"cost Phi = {kin + inert:.10g} (kinetic {kin:.10g}, inertial "
                     f"{inert:.10g}) [{sc.units.names['energy']} x {sc.units.names['time']}]")
    lines.append(f"wrote {where}: {tr.t.size} samples, working mode {tr.mode} "
                 f"({_units_note(sc)})")
    _warn_law(args, law)
    _emit(args, payload, "\n".join(lines))
    return 0


def cmd_torques(args: argparse.Namespace) -> int:
    from .analysis import analyze
    from .output.tables import csv_text, torque_columns

    out = _out_file(args.out, ".csv")
    sc = _scenario(args.config)
    an = analyze(sc)
    where = _write(out, csv_text(torque_columns(an)))
    peak = np.abs(an.tau).max(axis=0)
    payload: dict[str, Any] = {"out": where, "samples": int(an.trajectory.t.size),
                               **_law_payload(sc, an.law),
                               "peak_torque": [float(v) for v in peak],
                               "units": sc.units.describe()}
    text = (f"{_law_line(sc, an.law)}\nwrote {where}: {an.trajectory.t.size} samples; peak "
            f"|tau| = {peak[0]:.6g}, {peak[1]:.6g} [{sc.units.names['torque']}] "
            f"({_units_note(sc)})")
    if an.paper is not None:
        payload["paper_model_error"] = an.paper.error
        text += (f"\npaper model (42) error: max {an.paper.error['max_relative']:.1%}, RMS "
                 f"{an.paper.error['rms_relative']:.1%} of the peak exact torque")
    else:
        from .dynamics.paper import paper_model_limits

        why = paper_model_limits(sc.robot, sc.inertia)
        text += f"\nno paper-model columns: the paper's simplified model does not apply ({why})"
    _warn_law(args, an.law)
    _emit(args, payload, text)
    return 0


def cmd_simulate(args: argparse.Namespace) -> int:
    from .control import simulate_computed_torque
    from .dynamics import Model
    from .output.figures import png_bytes, tracking_figure
    from .output.outdir import OutputDir
    from .output.tables import csv_text, unit_tokens

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
    u = unit_tokens(sc.units)
    cols = {f"t_{u['time']}": res.t, "phi_des_rad": tr.q[:, 0], "psi_des_rad": tr.q[:, 1],
            "phi_rad": res.q[:, 0], "psi_rad": res.q[:, 1], "err_phi_rad": res.joint_error[:, 0],
            "err_psi_rad": res.joint_error[:, 1], "task_error_mm": res.task_error * mm,
            f"tau1_{u['torque']}": res.tau[:, 0], f"tau2_{u['torque']}": res.tau[:, 1],
            "saturated": res.saturated.astype(float)}
    summ = res.summary()
    report = {"units": sc.units.describe(), "control": {k: v for k, v in c.items()},
              "status": res.status, "message": res.message,
              "max_task_error_mm": summ["max_task_error"] * mm,
              "rms_task_error_mm": summ["rms_task_error"] * mm,
              "final_task_error_mm": summ["final_task_error"] * mm,
              "max_joint_error_deg": float(np.degrees(summ["max_joint_error_rad"])),
              "saturated_fraction": summ["saturated_fraction"]}
    fig = tracking_figure(res, sc.units, c["mass_error"], c["payload_kg"])
    with OutputDir(args.out, force=args.force) as od:
        od.write_text("tracking.csv", csv_text(cols))
        od.write_bytes("tracking.png", png_bytes(fig))
        od.write_text("tracking.json", json.dumps(report, indent=2, default=str) + "\n")
    if summ["saturated_fraction"] > 0:
        sys.stderr.write(f"dextar simulate: warning: the torque limit "
                         f"{c['torque_limit_nm']:g} N m saturates a motor during "
                         f"{summ['saturated_fraction']:.1%} of the motion; tracking is not "
                         "guaranteed\n")
    files = ", ".join(_shown(args.out, n) for n in ("tracking.csv", "tracking.png",
                                                     "tracking.json"))
    _emit(args, report, f"wrote {files}: max task error {report['max_task_error_mm']:.4g} mm, "
          f"max joint error {report['max_joint_error_deg']:.4g} deg, torque saturated "
          f"{report['saturated_fraction']:.1%} of the time")
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    from .export.mjcf import to_mjcf

    sc = _scenario(args.config)
    out = _out_file(args.out, ".xml")
    tr = sc.trajectory(samples=2)
    where = _write(out, to_mjcf(sc.model(tr.assembly), start=(tr.q[0], tr.dq[0])))
    _emit(args, {"out": where, "units": sc.units.describe()},
          f"wrote {where} (MuJoCo model in {_units_note(sc)}; keyframe 'start' at the "
          "motion's start)")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from .output.run import run

    sc = _scenario(args.config)
    s = run(sc, args.out, force=args.force, quiet=args.quiet)
    if not s["law"]["success"]:
        sys.stderr.write(f"dextar run: warning: {s['law']['type']} law status "
                         f"{s['law']['status']}: {s['law']['message']}\n")
    if args.json:
        print(json.dumps(s))
    elif not args.quiet:
        law = s["law"]
        secs = law["duration_s"]
        claims = s.get("claims", [])
        lines = [f"wrote {len(s['files'])} files to {_shown(args.out)} (open "
                 f"{_shown(args.out, 'report.html')})",
                 f"{law['type']} law: motion time {secs:.6g} s; status {law['status']}: "
                 f"{law['message']}"]
        if "cost" in s:
            lines.append(f"cost Phi = {s['cost']['total']:.8g} [{s['cost']['unit']}]")
        lines.append(f"peak |tau| exact = {max(s['torques']['exact']['peak']):.6g} "
                     f"{s['units']['torque_unit']}")
        lines += [f"  {c['verdict']:>11}: {c['claim']} ({c['value']:.3g})" for c in claims]
        print("\n".join(lines))
    return 0


def _register_stages(sub: Any) -> None:
    def cfg(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("config", nargs="?", help="TOML config (default: the paper's example)")
        sp.add_argument("--json", action="store_true", help="print one JSON object")

    sp = sub.add_parser("plan", help="law of motion along the path: samples to CSV, cost")
    cfg(sp)
    sp.add_argument("--out", required=True, help="CSV file (- for stdout)")
    sp.set_defaults(func=cmd_plan)

    sp = sub.add_parser("torques", help="exact and paper-model motor torques to CSV")
    cfg(sp)
    sp.add_argument("--out", required=True, help="CSV file (- for stdout)")
    sp.set_defaults(func=cmd_torques)

    sp = sub.add_parser("simulate", help="computed-torque tracking against a perturbed plant")
    cfg(sp)
    sp.add_argument("--out", default="dextar-sim", help="output directory")
    sp.add_argument("--force", action="store_true", help="write into an existing directory")
    sp.set_defaults(func=cmd_simulate)

    sp = sub.add_parser("export", help="export the robot model (mjcf: MuJoCo XML)")
    sp.add_argument("format", choices=["mjcf"])
    cfg(sp)
    sp.add_argument("--out", required=True, help="XML file (- for stdout)")
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
