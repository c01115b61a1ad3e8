"""``dextar identify DATA.csv``: the base parameters identified from measured motion, and a
config with them (``identified.toml``) loadable by every command."""

from __future__ import annotations

import argparse

from .base import Result, into_directory, model_argument, shown

NAME = "identify"
HELP = ("identify the base parameters from measured motion and write a config with them "
        "(exit 1 when poorly determined, not physical or a poor fit)")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``data``, ``--config``, ``--task``, ``--validate``, ``--cutoff-hz``, ``--out``,
    ``--force``."""
    sp.add_argument("data", help="CSV with t_s, phi_rad, psi_rad, tau1_Nm, tau2_Nm (SI)")
    sp.add_argument("--config", help="TOML config: the robot and the prior masses")
    model_argument(sp)
    sp.add_argument("--task", metavar="TASK.toml",
                    help="a program or run config the model is for (its robot must be the "
                    "config's): the predicted-torque uncertainty is measured along it "
                    "(default: along the data's own envelope)")
    sp.add_argument("--validate", metavar="DATA2.csv",
                    help="data not used in the fit: predicted against measured torques")
    sp.add_argument("--cutoff-hz", type=float, default=None,
                    help="low-pass cut-off, Hz (default: from the data's bandwidth)")
    into_directory(sp)


def run(args: argparse.Namespace, *, figures: bool = True) -> Result:
    """Read, identify, validate, write."""
    import numpy as np

    from ..config import load_scenario
    from ..errors import ConfigError
    from ..identification.data import read_motion_csv
    from ..identification.fit import identify
    from ..output.identification import IdentificationReport, write_identification
    from .excite import task_motion

    cutoff = args.cutoff_hz
    if cutoff is not None and not (np.isfinite(cutoff) and cutoff > 0):
        raise ConfigError(f"--cutoff-hz {cutoff!r} must be a positive number")
    sc = load_scenario(args.config, model=args.model)
    model = sc.si_model
    data = read_motion_csv(args.data)
    vdata = read_motion_csv(args.validate) if args.validate else None
    reference = None if args.task is None else task_motion(args.task, sc)
    res = identify(data, model, mode=sc.mode, cutoff_hz=cutoff, reference=reference,
                   reference_name=f"the task {args.task}")
    rep = IdentificationReport.of(res, data, model, sc.mode, args.data, args.config, vdata,
                                  args.validate)
    comment = (f"identified by dextar from {args.data} ({res.method}, condition number "
               f"{res.condition_number:.4g})\nbase parameters reproduced exactly; the split "
               "between rods, rotor and payload that the torques cannot see follows "
               f"{args.config or 'the defaults'}")
    write_identification(args.out, rep, sc.model_file(sc.robot_mm, sc.mode, res.inertia,
                                                      comment),
                         force=args.force, with_figures=figures)
    lines = rep.lines()
    lines.append(f"wrote {shown(args.out, 'identified.toml')}, parameters.csv, summary.json"
                 + (", fit.png, report.html" if figures else ""))
    # each reason the status is not "identified" names itself; the rest are warnings
    warnings = [f"dextar identify: {w}" if w in res.reasons else f"dextar identify: warning: {w}"
                for w in rep.summary["warnings"]]
    if args.config is None and args.model is None:
        g = sc.robot_mm
        warnings.insert(0, f"dextar identify: note: no --config: the robot is assumed to be "
                        f"the DexTAR (l1 = {g.l1:g}, l2 = {g.l2:g}, L1 = {g.L1:g}, L2 = "
                        f"{g.L2:g}, d = {g.d:g} mm, working mode {sc.mode}) without gravity; "
                        "give the robot's config with --config")
    return Result(rep.summary, "\n".join(lines), warnings, code=0 if res.success else 1)
