"""``dextar program TASK.toml``: a robot program planned under the motors: setpoints, sizing,
figures and the report (exit status 1 when a motor limit is exceeded)."""

from __future__ import annotations

import argparse

from .base import Result, config_argument, into_directory, with_notes

NAME = "program"
HELP = ("plan a robot program under the motors: setpoints and sizing (exit 1 when a motor "
        "limit is exceeded)")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``config``, ``--out``, ``--force``, ``--quiet``, ``--json``, ``--no-figures``."""
    config_argument(sp, required=True,
                    help="TOML task file with [program], [[move]] and [motors]")
    into_directory(sp)
    sp.add_argument("--no-figures", dest="figures", action="store_false",
                    help="write the setpoints, the drive's files and summary.json only (no "
                         "figures, no report.html): for batches of programs")


def run(args: argparse.Namespace) -> Result:
    """The command, with the config's notes (:func:`.base.with_notes`)."""
    return with_notes(NAME, args, _run)


def _run(args: argparse.Namespace) -> Result:
    """Plan, size, write, word (the figures unless ``--no-figures``)."""
    from dataclasses import replace

    from ..config import load_scenario
    from ..errors import ConfigError, DextarError
    from ..output.program import ProgramSummary, write_program
    from ..program import sizing
    from ..program.drive import drive_report, pvt_points, torque_checks

    sc = load_scenario(args.config, model=args.model)
    drive = sc.drive()
    if drive is not None and sc.drive_table.max_torque_permille is not None:
        drive = replace(drive, max_torque_permille=sc.drive_table.max_torque_permille)
    res = sc.program_request().plan()
    try:
        pvt = None if drive is None else pvt_points(res, drive)
    except DextarError as exc:
        raise ConfigError(f"config table [drive]: {exc}") from None
    report = None
    sized = sizing(res)
    notes: list[str] = []
    if drive is not None and pvt is not None:
        report = {**drive_report(res, drive, sc.si_model.inertia.rotor),
                  "pvt_max_error_counts": pvt.max_error_counts}
        over, notes = torque_checks(res, drive)
        sized = replace(sized, violations=(*sized.violations, *over))
    summary = ProgramSummary(args.config, res.cycle_time_s, sc.output.servo_rate_hz,
                             tuple(res.timeline()), sized, res.rms_fit, report,
                             sc.robot_table.encoder_offset_deg)
    write_program(args.out, res, summary, sc.robot_mm, sc.program_mode, force=args.force,
                  with_figures=args.figures, drive=drive, pvt=pvt)
    warnings = [f"dextar program: {v.text()}" for v in summary.sizing.violations]
    warnings += [f"dextar program: warning: {n}" for n in notes]
    return Result(summary.as_json(), "\n".join(summary.lines(args.out, res.t.size)), warnings,
                  code=0 if summary.sizing.fits else 1)
