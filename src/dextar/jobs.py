"""One function per command: read the config, compute through the stages, write the outputs,
and return what to print. The command line (:mod:`dextar.cli`) only parses, calls one of
these and prints its :class:`JobResult`.
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .config import RobotTable, Scenario, check_tables, load_scenario, load_toml
from .config.tables import TABLES
from .errors import ConfigError
from .laws import Law

if TYPE_CHECKING:
    from .dynamics import Model


@dataclass(frozen=True)
class JobResult:
    """What a command reports: a JSON payload, the same in words, warnings for stderr and,
    for ``--out -``, the data for stdout."""

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


def _write(out: Path | None, text: str) -> tuple[str, str | None]:
    """Write ``text`` atomically to ``out``; for None (stdout) hand it back as data."""
    from .output.files import write_text

    if out is None:
        return "stdout", text
    write_text(out, text)
    return str(out), None


def _units_note(sc: Scenario) -> str:
    u = sc.units
    n = u.names
    if u.system == "paper":
        return (f"paper units: length L = {u.length_mm:g} mm, mass m = {u.mass_kg:g} kg, "
                f"time T = {u.time_s:g} s; angles in rad")
    return f"SI units: {n['length']}, {n['mass']}, {n['time']}; torques in N m; angles in rad"


def _law_line(sc: Scenario, law: Law) -> str:
    u = sc.units
    secs = law.duration * u.time_s
    time = (f"{secs:.6g} s" if u.system == "si"
            else f"{law.duration:.6g} {u.names['time']} ({secs:.6g} s)")
    return f"{law.name} law: motion time {time}; status {law.status}: {law.message}"


def _law_payload(sc: Scenario, law: Law) -> dict[str, Any]:
    return {"law": law.name, "duration": law.duration,
            "duration_s": law.duration * sc.units.time_s, "status": int(law.status),
            "success": bool(law.success), "message": law.message}


def _law_warnings(command: str, law: Law) -> list[str]:
    if law.success:
        return []
    return [f"dextar {command}: warning: {law.name} law status {law.status}: {law.message}"]


# ----------------------------------------------------------------------------- kinematics
def robot_table(path: str | None) -> RobotTable:
    """``[robot]`` of a config file (the DexTAR without one)."""
    if path is None:
        return RobotTable()
    doc = load_toml(path)
    check_tables({k: v for k, v in doc.items() if k != "move"}, set(TABLES))
    return RobotTable.from_toml(doc.get("robot", {}))


def ik(x: float, y: float, *, mode: str | None = None, robot: str | None = None) -> JobResult:
    """Actuator angles (deg) for the point ``(x, y)`` mm."""
    from .kinematics import inverse_kinematics

    rc = robot_table(robot)
    mode = mode or rc.working_mode
    q = inverse_kinematics(rc.geometry_mm, [x, y], mode)
    phi, psi = (float(v) for v in np.degrees(q))
    return JobResult({"phi_deg": phi, "psi_deg": psi, "mode": mode},
                     f"phi = {phi:.6f} deg, psi = {psi:.6f} deg (working mode {mode})")


def fk(phi: float, psi: float, *, assembly: str | None = None,
       robot: str | None = None) -> JobResult:
    """The end-effector (mm) for the actuator angles ``(phi, psi)`` deg."""
    from .kinematics import direct_kinematics

    rc = robot_table(robot)
    assembly = assembly or rc.assembly_mode
    P = direct_kinematics(rc.geometry_mm, np.radians([phi, psi]), assembly)
    x, y = float(P[0]), float(P[1])
    return JobResult({"x_mm": x, "y_mm": y, "assembly": assembly},
                     f"x = {x:.6f} mm, y = {y:.6f} mm (assembly mode {assembly})")


def workspace(out: str, *, mode: str | None = None, resolution: int = 301,
              robot: str | None = None) -> JobResult:
    """The workspace map of a working mode, drawn to ``out`` (PNG or SVG)."""
    from .kinematics import workspace_map
    from .output.figures import plot_workspace
    from .output.files import save_figure

    rc = robot_table(robot)
    mode = mode or rc.working_mode
    path = out_file(out, ".png", ".svg")
    if path is None:
        raise ConfigError("--out - is for CSV and JSON; a workspace map is a PNG or SVG file")
    ws = workspace_map(rc.geometry_mm, mode, resolution=resolution)
    save_figure(plot_workspace(ws), path, dpi=150)
    area = ws.reachable_area
    reach = ws.dexterity[ws.reachable]
    payload = {"out": str(path), "mode": mode, "robot_mm": rc.geometry_mm.as_dict(),
               "resolution": [int(ws.x.size), int(ws.y.size)], "reachable_area_mm2": area,
               "dexterity_mean": float(reach.mean()) if reach.size else 0.0,
               "dexterity_max": float(reach.max()) if reach.size else 0.0,
               "type2_curve_in_workspace": bool((ws.type2[ws.reachable] > 0).any()
                                                and (ws.type2[ws.reachable] < 0).any())}
    return JobResult(payload, f"wrote {path} (working mode {mode}, reachable area {area:.0f} "
                     "mm^2)")


# ----------------------------------------------------------------------------- stages
def plan(config: str | None, out: str) -> JobResult:
    """The configured law along the path: samples to CSV, motion time, solver status."""
    from .output.tables import csv_text, trajectory_columns

    path = out_file(out, ".csv")
    sc = load_scenario(config)
    law = sc.law()
    tr = sc.trajectory(law)
    where, data = _write(path, csv_text(trajectory_columns(tr, sc.units)))
    payload: dict[str, Any] = {"out": where, "samples": int(tr.t.size), **_law_payload(sc, law),
                               "units": sc.units.describe()}
    lines = [_law_line(sc, law)]
    kin, inert = getattr(law, "kinetic", None), getattr(law, "inertial", None)
    if law.name == "optimal" and kin is not None and inert is not None:
        payload.update(cost=kin + inert, cost_kinetic=kin, cost_inertial=inert)
        lines.append(f"cost Phi = {kin + inert:.10g} (kinetic {kin:.10g}, inertial "
                     f"{inert:.10g}) [{sc.units.names['energy']} x {sc.units.names['time']}]")
    lines.append(f"wrote {where}: {tr.t.size} samples, working mode {tr.mode} "
                 f"({_units_note(sc)})")
    return JobResult(payload, "\n".join(lines), _law_warnings("plan", law), data)


def torques(config: str | None, out: str) -> JobResult:
    """Exact (and paper-model) torques, powers, energy and joint forces to CSV."""
    from .analysis import analyze
    from .dynamics.paper import paper_model_limits
    from .output.tables import csv_text, torque_columns

    path = out_file(out, ".csv")
    sc = load_scenario(config)
    an = analyze(sc.inputs(), sc.law())
    where, data = _write(path, csv_text(torque_columns(an)))
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
        why = paper_model_limits(sc.robot, sc.inertia)
        text += f"\nno paper-model columns: the paper's simplified model does not apply ({why})"
    return JobResult(payload, text, _law_warnings("torques", an.law), data)


def simulate(config: str | None, out: str, *, force: bool = False) -> JobResult:
    """Computed-torque tracking of the configured motion by a perturbed plant."""
    from .dynamics import Model
    from .output.figures import png_bytes, tracking_figure
    from .output.outdir import OutputDir
    from .output.tables import csv_text, unit_tokens
    from .simulation import simulate_computed_torque

    sc = load_scenario(config)
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
    report = {"units": sc.units.describe(), "control": dict(c),
              "status": res.status, "message": res.message,
              "max_task_error_mm": summ["max_task_error"] * mm,
              "rms_task_error_mm": summ["rms_task_error"] * mm,
              "final_task_error_mm": summ["final_task_error"] * mm,
              "max_joint_error_deg": float(np.degrees(summ["max_joint_error_rad"])),
              "saturated_fraction": summ["saturated_fraction"]}
    fig = tracking_figure(res, sc.units, c["mass_error"], c["payload_kg"])
    with OutputDir(out, force=force) as od:
        od.write_text("tracking.csv", csv_text(cols))
        od.write_bytes("tracking.png", png_bytes(fig))
        od.write_text("tracking.json", json.dumps(report, indent=2, default=str) + "\n")
    warnings = []
    if summ["saturated_fraction"] > 0:
        warnings.append(f"dextar simulate: warning: the torque limit {c['torque_limit_nm']:g} "
                        f"N m saturates a motor during {summ['saturated_fraction']:.1%} of the "
                        "motion; tracking is not guaranteed")
    files = ", ".join(shown(out, n) for n in ("tracking.csv", "tracking.png", "tracking.json"))
    return JobResult(report, f"wrote {files}: max task error "
                     f"{report['max_task_error_mm']:.4g} mm, max joint error "
                     f"{report['max_joint_error_deg']:.4g} deg, torque saturated "
                     f"{report['saturated_fraction']:.1%} of the time", warnings)


def export_mjcf(config: str | None, out: str) -> JobResult:
    """The MuJoCo model of the configured robot with a keyframe at the motion's start."""
    from .output.mjcf import to_mjcf

    sc = load_scenario(config)
    path = out_file(out, ".xml")
    tr = sc.trajectory(samples=2)
    where, data = _write(path, to_mjcf(sc.model(tr.assembly), start=(tr.q[0], tr.dq[0])))
    return JobResult({"out": where, "units": sc.units.describe()},
                     f"wrote {where} (MuJoCo model in {_units_note(sc)}; keyframe 'start' at "
                     "the motion's start)", data=data)


def run(config: str | None, out: str, *, force: bool = False,
        quiet: bool = False) -> JobResult:
    """The main job: the paper's example (or the configured scenario) end to end, every file
    written to ``out``."""
    from .analysis import analyze, run_summary, validation
    from .output.outdir import OutputDir
    from .output.run import Progress, staged, write_run

    sc = load_scenario(config)
    prog = Progress(enabled=not quiet and sys.stderr.isatty())
    stage = staged(prog)
    inputs = sc.inputs()
    with OutputDir(out, force=force) as od:
        an = stage(f"{sc.law_table.type} law, trajectory and torques",
                   lambda: analyze(inputs, sc.law()))
        uniform = stage("uniform law (Fig. 3)", lambda: inputs.trajectory(sc.law("uniform")))
        checks = stage("validation (power balance, forward re-simulation)",
                       lambda: validation(an))
        s = run_summary(an, checks, inputs.trajectory(uniform.law, samples=201))
        write_run(od, an, uniform, s, figures=sc.output.figures,
                  animation_frames=sc.output.animation_frames, stage=stage, progress=prog)
    law = s["law"]
    warnings = ([] if law["success"] else
                [f"dextar run: warning: {law['type']} law status {law['status']}: "
                 f"{law['message']}"])
    lines = [f"wrote {len(s['files'])} files to {shown(out)} (open "
             f"{shown(out, 'report.html')})",
             f"{law['type']} law: motion time {law['duration_s']:.6g} s; status "
             f"{law['status']}: {law['message']}"]
    if "cost" in s:
        lines.append(f"cost Phi = {s['cost']['total']:.8g} [{s['cost']['unit']}]")
    lines.append(f"peak |tau| exact = {max(s['torques']['exact']['peak']):.6g} "
                 f"{s['units']['torque_unit']}")
    lines += [f"  {c['verdict']:>11}: {c['claim']} ({c['value']:.3g})"
              for c in s.get("claims", [])]
    return JobResult(s, "\n".join(lines), warnings)


def program(config: str, out: str, *, force: bool = False, figures: bool = True) -> JobResult:
    """Plan a robot program (``[program]``, ``[[move]]``, ``[motors]``) and write its
    setpoints and sizing to ``out``; exit code 1 when it exceeds a motor limit."""
    from .config.program import ProgramTable
    from .config.tables import MotorsTable
    from .output.outdir import OutputDir
    from .output.tables import csv_text
    from .program import plan_program, sizing
    from .units import SI

    sc = load_scenario(config)
    prog = sc.table("program")
    assert isinstance(prog, ProgramTable)
    if prog.start is None:
        raise ConfigError("config key [program].start is required (the start point, at rest)")
    model = si_model(sc)
    robot, inertia = model.robot, model.inertia
    motors_t = sc.table("motors")
    assert isinstance(motors_t, MotorsTable)
    res = plan_program(robot, inertia, sc.moves, start=prog.start,
                       working_mode=prog.working_mode or sc.mode, assembly=sc.assembly,
                       motors=motors_t.limits(SI), rms_limit=motors_t.rms_torque,
                       servo_rate_hz=sc.output.servo_rate_hz, grid=prog.grid,
                       tolerances=sc.tolerances)
    motors, violations = sizing(res)
    cols = {"t_s": res.t, "move": res.move_index.astype(float), "x_mm": res.P[:, 0] * 1e3,
            "y_mm": res.P[:, 1] * 1e3, "phi_rad": res.q[:, 0], "psi_rad": res.q[:, 1],
            "dphi_rad_s": res.dq[:, 0], "dpsi_rad_s": res.dq[:, 1],
            "ddphi_rad_s2": res.ddq[:, 0], "ddpsi_rad_s2": res.ddq[:, 1],
            "tau1_Nm": res.tau[:, 0], "tau2_Nm": res.tau[:, 1]}
    summary: dict[str, Any] = {
        "status": "exceeds" if violations else "fits", "cycle_time_s": res.cycle_time_s,
        "servo_rate_hz": sc.output.servo_rate_hz, "config": config,
        "moves": [{"index": idx, "type": sc.moves[idx].type,
                   "law": pm.law.name if pm.law else None,
                   "law_status": pm.law.status if pm.law else 0,
                   "law_message": pm.law.message if pm.law else "holding still",
                   "start_s": start, "duration_s": dur,
                   "blended_with_next": bool(pm.members) and idx != pm.members[-1][0],
                   "min_type1_distance": pm.min_type1_distance,
                   "min_type2_distance": pm.min_type2_distance}
                  for pm in res.moves
                  for idx, start, dur in (pm.members or ((pm.move.index, pm.start_s,
                                                          pm.duration_s),))],
        "motors": motors, "violations": violations,
        "units": "SI: s, rad, N m, W, J; positions in mm in setpoints.csv"}
    with OutputDir(out, force=force) as od:
        od.write_text("setpoints.csv", csv_text(cols))
        if figures:
            from .output.figures import png_bytes, svg_bytes
            from .output.program_figures import (
                motion_figure,
                moves_figure,
                operating_points_figure,
                program_report,
            )

            pngs: dict[str, bytes] = {}
            for name, fig in (("moves", moves_figure(res, sc.robot_mm,
                                                     prog.working_mode or sc.mode)),
                              ("motion", motion_figure(res)),
                              ("operating_points", operating_points_figure(res, motors))):
                pngs[name] = png_bytes(fig)
                od.write_bytes(f"{name}.png", pngs[name])
                od.write_bytes(f"{name}.svg", svg_bytes(fig))
            od.write_text("report.html", program_report(summary, pngs))
        od.write_text("summary.json", json.dumps(summary, indent=2, allow_nan=False) + "\n")
    lines = [f"program: cycle time {res.cycle_time_s:.6g} s, {len(summary['moves'])} moves; "
             f"{summary['status']} the motors",
             *(f"  move {m['index']} ({m['type']}): {m['law'] or 'dwell'} {m['duration_s']:.4g} s "
               f"from {m['start_s']:.4g} s" + (", blended into the next"
                                               if m["blended_with_next"] else "")
               for m in summary["moves"]),
             *(f"  motor {m['motor']}: peak {m['peak_torque_Nm']:.4g} N m, RMS "
               f"{m['rms_torque_Nm']:.4g} N m, peak speed {m['peak_speed_rad_s']:.4g} rad/s"
               for m in motors),
             f"wrote {shown(out, 'setpoints.csv')} ({res.t.size} setpoints at "
             f"{sc.output.servo_rate_hz:g} Hz) and {shown(out, 'summary.json')}"]
    warnings = [f"dextar program: motor {v['motor']} {v['quantity']} {v['value']:.4g} above its "
                f"limit {v['limit']:.4g}" + (f" at t = {v['t_s']:.4g} s in move {v['move']}"
                                             if v["t_s"] is not None else "")
                for v in violations]
    return JobResult(summary, "\n".join(lines), warnings, code=1 if violations else 0)


# ----------------------------------------------------------------------------- identification
def si_model(sc: Scenario) -> Model:
    """The scenario's robot and inertia in SI (m, kg, s), whatever its ``[output].units``:
    the unit system of programs and identification."""
    from .config.tables import FrictionTable, GravityTable, InertiaTable
    from .dynamics import Model
    from .units import SI

    inertia_t, friction_t, gravity_t = (sc.table(n) for n in ("inertia", "friction", "gravity"))
    assert isinstance(inertia_t, InertiaTable) and isinstance(friction_t, FrictionTable)
    assert isinstance(gravity_t, GravityTable)
    inertia = inertia_t.build(SI, sc.robot_mm, friction_t, gravity_t)
    return Model(sc.robot_mm.scaled(1e-3), inertia, sc.assembly, tol=sc.tolerances.type2)


def excite(config: str, out: str, *, duration: float = 20.0, harmonics: int = 5,
           base_hz: float = 0.2, seed: int = 0) -> JobResult:
    """Design an exciting trajectory for the config's robot and write it as CSV at
    ``[output].servo_rate_hz`` with the torques the config's model predicts."""
    from .config.tables import MotorsTable
    from .dynamics import inverse_dynamics
    from .identification.excite import design_excitation
    from .output.tables import csv_text
    from .units import SI

    target = out_file(out, ".csv")
    sc = load_scenario(config)
    model = si_model(sc)
    motors_t = sc.table("motors")
    assert isinstance(motors_t, MotorsTable)
    res = design_excitation(model, sc.mode, harmonics=harmonics, base_hz=base_hz,
                            duration=duration, motors=motors_t.limits(SI), seed=seed)
    rate = sc.output.servo_rate_hz
    n = int(round(res.duration * rate)) + 1
    t = np.arange(n) / rate
    q, dq, ddq = res.trajectory.evaluate(t)
    tau = inverse_dynamics(model, q, dq, ddq, t=t)
    cols = {"t_s": t, "phi_rad": q[:, 0], "psi_rad": q[:, 1], "dphi_rad_s": dq[:, 0],
            "dpsi_rad_s": dq[:, 1], "ddphi_rad_s2": ddq[:, 0], "ddpsi_rad_s2": ddq[:, 1],
            "tau1_Nm": tau[:, 0], "tau2_Nm": tau[:, 1]}
    where, data = _write(target, csv_text(cols))
    payload = {"condition_number": res.condition_number, "duration_s": res.duration,
               "periods": res.periods, "period_s": res.trajectory.period,
               "harmonics": harmonics, "base_hz": base_hz, "samples": n, "rate_hz": rate,
               "rest_pose_deg": [float(v) for v in np.degrees(res.trajectory.q0)],
               "min_type1_distance": res.min_type1_distance,
               "min_type2_distance": res.min_type2_distance,
               "peak_torque_Nm": [float(v) for v in res.peak_torque],
               "peak_speed_rad_s": [float(v) for v in res.peak_speed],
               "status": res.status, "message": res.message, "out": where}
    text = (f"exciting trajectory: condition number {res.condition_number:.4g} (base "
            f"regressor, unit-norm columns); {res.periods} period(s) of {res.trajectory.period:g} "
            f"s, {harmonics} harmonics; peak torques {res.peak_torque[0]:.4g}, "
            f"{res.peak_torque[1]:.4g} N m; min singularity distances type 1 "
            f"{res.min_type1_distance:.3g}, type 2 {res.min_type2_distance:.3g}; wrote {where} "
            f"({n} samples at {rate:g} Hz)")
    warnings = [] if res.status == 0 else [f"dextar excite: warning: {res.message}"]
    return JobResult(payload, text, warnings, data=data)


def identify(data_path: str, out: str, *, config: str | None = None,
             validate: str | None = None, cutoff_hz: float | None = None,
             force: bool = False, figures: bool = True) -> JobResult:
    """Identify the base parameters from measured motion and write ``identified.toml``,
    ``parameters.csv``, ``summary.json``, ``fit.png`` and ``report.html`` in ``out``."""
    from .dynamics.regressor import NAMES, standard_parameters
    from .identification.data import read_motion_csv
    from .identification.fit import check_working_mode, condition
    from .identification.fit import identify as fit
    from .output.identification import (
        fit_figure,
        identification_report,
        parameters_csv,
    )
    from .output.outdir import OutputDir

    if cutoff_hz is not None and not (np.isfinite(cutoff_hz) and cutoff_hz > 0):
        raise ConfigError(f"--cutoff-hz {cutoff_hz!r} must be a positive number")
    sc = load_scenario(config)
    model = si_model(sc)
    data = read_motion_csv(data_path)
    vdata = read_motion_csv(validate) if validate else None
    res = fit(data, model, mode=sc.mode, cutoff_hz=cutoff_hz)
    c = res.conditioned
    assert c is not None
    Yb = res.base.columns(c.Y)
    summary: dict[str, Any] = {
        "status": ("identified" if res.status == 0 else "poorly conditioned" if res.status == 1
                   else "not physically consistent"),
        "message": res.message, "method": res.method, "data": data_path,
        "config": config or "defaults", "n_samples": res.n_samples, "n_used": res.n_used,
        "sample_rate_hz": data.rate_hz, "cutoff_hz": res.cutoff_hz,
        "condition_number": res.condition_number,
        "rms_residual_Nm": [float(v) for v in res.rms_residual],
        "base_parameters": [{"name": n, "meaning": m, "unit": u, "value": float(v),
                             "std": float(s)}
                            for n, m, u, v, s in zip(res.base.names, res.base.meanings,
                                                     res.base.units, res.beta, res.std,
                                                     strict=True)],
        "unidentifiable": [NAMES[j] for j in res.base.unidentifiable],
        "physically_consistent": res.consistent, "warnings": list(res.warnings),
        "units": "SI: s, rad, N m; base parameters in the unit of their column"}
    panels = [("identification data", c.t, c.tau, Yb @ res.beta)]
    if vdata is not None:
        check_working_mode(vdata, model, sc.mode)
        vc = condition(vdata, model, cutoff_hz=res.cutoff_hz)
        pred = vc.Y @ res.theta
        prior = vc.Y @ standard_parameters(model.inertia)
        summary["validation_data"] = validate
        summary["validation_rms_error_Nm"] = [float(v) for v in
                                              np.sqrt(((pred - vc.tau) ** 2).mean(axis=0))]
        summary["validation_rms_error_prior_Nm"] = [float(v) for v in np.sqrt(
            ((prior - vc.tau) ** 2).mean(axis=0))]
        summary["validation_rms_torque_Nm"] = [float(v) for v in
                                               np.sqrt((vc.tau ** 2).mean(axis=0))]
        panels.append(("validation data", vc.t, vc.tau, pred))
    toml_text = _model_config(
        sc, config, sc.robot_mm, sc.mode, res.inertia,
        f"identified by dextar from {data_path} ({res.method}, condition number "
        f"{res.condition_number:.4g})\nbase parameters reproduced exactly; the split "
        "between rods, rotor and payload that the torques cannot see follows "
        f"{config or 'the defaults'}")
    csv_rows = parameters_csv(res)
    with OutputDir(out, force=force) as od:
        od.write_text("identified.toml", toml_text)
        od.write_text("parameters.csv", csv_rows)
        if figures:
            from .output.figures import png_bytes

            png = png_bytes(fit_figure(panels))
            od.write_bytes("fit.png", png)
            od.write_text("report.html", identification_report(summary, {"fit": png}))
        od.write_text("summary.json", json.dumps(summary, indent=2, allow_nan=False) + "\n")
    lines = [f"identified {res.base.size} base parameters from {res.n_samples} samples "
             f"({res.n_used} used after filtering at {res.cutoff_hz:.3g} Hz): {res.method}, "
             f"condition number {res.condition_number:.4g}, RMS residual "
             f"{res.rms_residual[0]:.4g}, {res.rms_residual[1]:.4g} N m",
             *(f"  {n:<7} = {v: .6g} +- {s:.2g} {u}  ({m})" for n, m, u, v, s in
               zip(res.base.names, res.base.meanings, res.base.units, res.beta, res.std,
                   strict=True))]
    if vdata is not None:
        e, ep = summary["validation_rms_error_Nm"], summary["validation_rms_error_prior_Nm"]
        lines.append(f"validation on {validate}: RMS error {e[0]:.4g}, {e[1]:.4g} N m "
                     f"(prior model {ep[0]:.4g}, {ep[1]:.4g} N m)")
    lines.append(f"wrote {shown(out, 'identified.toml')}, parameters.csv, summary.json"
                 + (", fit.png, report.html" if figures else ""))
    warnings = [f"dextar identify: warning: {w}" for w in res.warnings]
    return JobResult(summary, "\n".join(lines), warnings)


# ----------------------------------------------------------------------------- design sweeps
def design(config: str, out: str, *, samples: int | None = None, seed: int | None = None,
           workers: int | None = None, scheduler: str | None = None, resume: bool = False,
           force: bool = False, figures: bool = True,
           progress: Any = None) -> JobResult:
    """Sweep the geometries of ``[design]`` on the task's program (Dask), and write
    ``designs.csv``, ``pareto.csv``, ``best.toml``, ``summary.json``, figures and the report."""
    import hashlib

    from .design.evaluate import inertia_of
    from .design.pareto import closest_to_ideal, pareto_mask
    from .design.space import LENGTHS
    from .design.sweep import Cluster, require_dask, run_sweep
    from .geometry import FiveBar
    from .output.design import DesignsFile, header, row_line
    from .output.files import write_bytes, write_text

    require_dask()
    sc = load_scenario(config)
    task, space = design_task(config, samples=samples, seed=seed, scenario=sc)
    mode = task.working_mode
    designs = space.designs()
    n = len(designs)
    signature = hashlib.sha256(repr((Path(config).read_bytes(), space, sc.design.grid)).encode()
                               ).hexdigest()
    outdir = Path(out)
    store = DesignsFile(outdir, designs, signature, resume=resume, force=force,
                        label=shown(out))
    with Cluster(workers=workers, scheduler=scheduler) as cluster, store:
        stats = run_sweep(cluster, task, designs, store.missing, chunk=sc.design.chunk,
                          on_chunk=store.append, progress=progress)
    ordered = store.finish()
    feasible = [r for r in ordered if r["feasible"]]
    summary: dict[str, Any] = {
        "task": config, "task_kind": task.kind, "designs": n, "feasible": len(feasible),
        "feasible_fraction": len(feasible) / n, "objectives": list(space.objectives),
        "sampling": space.sampling, "seed": space.seed,
        "varied": [name for name, *_ in space.dims],
        "mass_per_length_kg_m": list(space.mass_per_length) if space.mass_per_length else None,
        "evaluated": stats.evaluated, "resumed": n - stats.evaluated,
        "workers": stats.workers, "wall_time_s": stats.wall_s,
        "designs_per_second": stats.evaluated / stats.wall_s if stats.wall_s > 0 else 0.0,
        "pareto": 0, "best": None,
        "reasons": _reason_counts(ordered)}
    pareto_rows: list[dict[str, Any]] = []
    pngs: dict[str, bytes] = {}
    if feasible:
        F = space.objective_values(feasible)
        mask = pareto_mask(F)
        idx = np.flatnonzero(mask)
        b = int(idx[closest_to_ideal(F[idx])])
        pareto_rows = [feasible[i] for i in idx]
        best = feasible[b]
        summary["pareto"], summary["best"] = len(pareto_rows), best
        robot_mm = FiveBar(*(best[k] for k in LENGTHS))
        write_text(outdir / "best.toml", _model_config(
            sc, config, robot_mm, mode, inertia_of(task, robot_mm.scaled(1e-3)),
            f"the Pareto design closest to the ideal point of dextar design {config} (design "
            f"{best['design']} of {n}; objectives {', '.join(space.objectives)})"))
        if figures:
            from .design.evaluate import evaluate_path
            from .output.design import pareto_figure, scatter_matrix
            from .output.figures import png_bytes, svg_bytes

            best_P = evaluate_path(task, [best[k] for k in LENGTHS])
            names = list(space.objectives)
            X = np.array([[r[k] for k in LENGTHS] for r in ordered])
            cols = sorted({c for *_, cs in space.dims for c in cs})
            for name, fig in (
                    ("pareto", pareto_figure(F, mask, b, names)),
                    ("designs", scatter_matrix(X[:, cols], np.array([r["feasible"] for r in
                                                                     ordered]),
                                               [f"{LENGTHS[c]} [mm]" for c in cols])),
                    ("best_workspace", _best_workspace(robot_mm, mode, best_P))):
                pngs[name] = png_bytes(fig)
                write_bytes(outdir / f"{name}.png", pngs[name])
                write_bytes(outdir / f"{name}.svg", svg_bytes(fig))
    write_text(outdir / "pareto.csv", header() + "".join(row_line(r) for r in pareto_rows))
    if figures:
        from .output.design import design_report

        write_text(outdir / "report.html", design_report(summary, pareto_rows, pngs))
    write_text(outdir / "summary.json", json.dumps(summary, indent=2, allow_nan=False) + "\n")
    b_ = summary["best"]
    text = (f"design sweep: {n} designs ({stats.evaluated} evaluated, {n - stats.evaluated} "
            f"resumed) on {stats.workers} workers in {stats.wall_s:.1f} s "
            f"({summary['designs_per_second']:.3g} designs/s); {len(feasible)} feasible, "
            f"{len(pareto_rows)} on the Pareto front"
            + (f"; chosen design {b_['design']}: l1 = {b_['l1']:.4g}, l2 = {b_['l2']:.4g}, "
               f"L1 = {b_['L1']:.4g}, L2 = {b_['L2']:.4g}, d = {b_['d']:.4g} mm -> "
               f"{shown(out, 'best.toml')}" if b_ else "; no feasible design"))
    return JobResult(summary, text)


def design_task(config: str, *, samples: int | None = None, seed: int | None = None,
                scenario: Scenario | None = None) -> tuple[Any, Any]:
    """The :class:`~dextar.design.evaluate.Task` and the design space of a sweep's task file:
    a program task (``[program]`` and ``[[move]]``) or a run task (``[path]`` and ``[law]``;
    a law that does not depend on the robot is computed once here)."""
    from .config.program import ProgramTable
    from .config.tables import MotorsTable
    from .design.evaluate import Task
    from .units import SI

    sc = scenario or load_scenario(config)
    prog = sc.table("program")
    assert isinstance(prog, ProgramTable)
    space = sc.design.space(sc.robot_mm, samples=samples, seed=seed)
    model = si_model(sc)
    motors_t = sc.table("motors")
    assert isinstance(motors_t, MotorsTable)
    motors = motors_t.limits(SI)
    if sc.moves:  # a program task
        if prog.start is None:
            raise ConfigError("config key [program].start is required (the start point, at "
                              "rest)")
        mode = prog.working_mode or sc.mode
        task = Task(tuple(sc.moves), prog.start, mode, sc.assembly, motors,
                    motors_t.rms_torque, model.inertia, space.mass_per_length, sc.design.grid,
                    sc.tolerances)
    else:  # a run task: one path and law
        from .laws import LawRequest

        mode = sc.mode
        path = sc.path_table.build(SI)
        kind = sc.law_table.kind
        values = sc.law_table.run_values(SI)
        law = None if kind.needs_dynamics else kind.build(LawRequest(
            path, values, model.inertia.point_mass, None, SI, motors))
        start = path.position(0.0) * 1e3
        task = Task((), (float(start[0]), float(start[1])), mode, sc.assembly, motors,
                    motors_t.rms_torque, model.inertia, space.mass_per_length, sc.design.grid,
                    sc.tolerances, path=path, law=law,
                    law_type=kind.name if law is None else None,
                    law_values=values if law is None else None)
    return task, space


def _model_config(sc: Scenario, config: str | None, robot_mm: Any, mode: str, inertia: Any,
                  comment: str) -> str:
    """A config file of ``inertia`` (SI) on ``robot_mm``, with the scenario's friction speed
    and gravity and its ``[motors]`` and ``[tolerances]`` as the file gives them."""
    from .config.tables import FrictionTable, GravityTable
    from .output.config_file import model_toml

    friction_t, gravity_t = sc.table("friction"), sc.table("gravity")
    assert isinstance(friction_t, FrictionTable) and isinstance(gravity_t, GravityTable)
    raw = load_toml(config) if config is not None else {}
    extra: dict[str, Any] = {k: raw[k] for k in ("motors", "tolerances") if k in raw}
    return model_toml(robot_mm, mode, sc.assembly, inertia,
                      coulomb_speed_deg_s=friction_t.coulomb_speed_deg_s,
                      gravity_mm_s2=gravity_t.vector, extra=extra, comment=comment)


def _reason_counts(rows: list[dict[str, Any]]) -> dict[str, int]:
    """How many designs failed for each kind of reason."""
    kinds = (("geometry", "geometry"), ("motors exceeded", "motors exceeded"),
             ("singularity", "singularity"), ("out of reach", "unreachable"),
             ("internal error", "internal error"))
    out: dict[str, int] = {}
    for r in rows:
        if not r["feasible"]:
            text = str(r["reason"])
            kind = next((name for key, name in kinds if key in text), "other")
            out[kind] = out.get(kind, 0) + 1
    return out


def _best_workspace(robot_mm: Any, mode: str, P: Any) -> Any:
    from .kinematics import workspace_map
    from .output.figures import plot_workspace

    ws = workspace_map(robot_mm, mode, resolution=241)
    fig = plot_workspace(ws, path=P, unit="mm")
    fig.axes[0].set_title(f"chosen design: l1 = {robot_mm.l1:.4g}, l2 = {robot_mm.l2:.4g}, "
                          f"L1 = {robot_mm.L1:.4g}, L2 = {robot_mm.L2:.4g}, d = "
                          f"{robot_mm.d:.4g} mm", fontsize=9)
    return fig
