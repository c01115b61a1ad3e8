"""``dextar identify DATA.csv``: the base parameters identified from measured motion, and a
config with them (``identified.toml``) loadable by every command."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from .. import jobs
from .._lazy import lazy_module
from .base import (
    Result,
    into_directory,
    load,
    model_argument,
    no_figures_argument,
    note_lines,
    shown,
    wants_figures,
)

if TYPE_CHECKING:  # the writers, imported when the command runs (start-up: dextar._lazy)
    from ..output import identification as written
else:
    written = lazy_module("dextar.output.identification")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``data``, ``--config``, ``--task``, ``--validate``, ``--cutoff-hz``, ``--out``,
    ``--force``."""
    sp.add_argument("data", help="CSV with t_s, phi_rad, psi_rad, tau1_Nm, tau2_Nm (SI)")
    sp.add_argument("--config", help="TOML config: the robot and the prior masses")
    model_argument(sp)
    sp.add_argument("--task", metavar="TASK.toml",
                    help="a program or run config the model is for (its robot must be the "
                    "config's): the predicted-torque uncertainty is measured along it "
                    "(default: along the recorded motion: the verdict then covers motions "
                    "like it)")
    sp.add_argument("--validate", metavar="DATA2.csv",
                    help="data not used in the fit: predicted against measured torques")
    sp.add_argument("--cutoff-hz", type=float, default=None,
                    help="low-pass cut-off, Hz (default: from the data's bandwidth)")
    into_directory(sp)
    no_figures_argument(sp, "identified.toml, parameters.csv and summary.json")


def run(args: argparse.Namespace, *, figures: bool = True) -> Result:
    """Identify and validate (:func:`dextar.jobs.identify_model`), write, word (the figures
    unless ``figures`` is False or the command line said ``--no-figures``)."""
    figures = figures and wants_figures(args)
    sc = load(args)
    job = jobs.identify_model(args.data, sc, config=args.config, cutoff_hz=args.cutoff_hz,
                              task=args.task, validate=args.validate)
    res, rep = job.result, job.report
    written.write_identification(args.out, rep, job.model_toml, force=args.force,
                                 with_figures=figures)
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
    warnings[:0] = note_lines("identify", sc)  # the config's notes (a robot in metres), first
    return Result(rep.summary, "\n".join(lines), warnings, code=0 if res.success else 1)
