"""``dextar calibrate MEASURED.csv --config CONFIG.toml --out DIR``: the robot's lengths, its
encoder offsets and the instrument frame identified from measured poses, and a config with
them (``calibrated.toml``) loadable by every command.

Exit 0 calibrated; 1 for a fit computed that does not fit its data (not converged,
residuals above the stated noise, outliers: the files are written, a fit with outliers
without ``calibrated.toml``); 2 with one line for bad input.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from .. import jobs
from .._lazy import lazy_module
from ..config.kinematic import load_kinematic_config
from ..output.files import OutputDir
from .base import (
    Result,
    into_directory,
    no_figures_argument,
    note_lines,
    noted,
    shown,
    wants_figures,
)

if TYPE_CHECKING:  # the writers, imported when the command runs (start-up: dextar._lazy)
    from ..output import calibration as written
else:
    written = lazy_module("dextar.output.calibration")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``data``, ``--config``, ``--validate``, ``--frame``, ``--robust``,
    ``--outlier-factor``, ``--out``, ``--force``, ``--quiet``, ``--json``, ``--no-figures``."""
    sp.add_argument("data", help="CSV with phi_deg, psi_deg (encoder readings), x_mm, y_mm "
                    "(measured point) [, mode, assembly, sigma_mm]")
    sp.add_argument("--config", help="TOML config: the nominal [robot] (its encoder offsets "
                    "and counts) and [instrument].sigma_mm (default: the DexTAR)")
    sp.add_argument("--validate", metavar="HELD.csv",
                    help="poses not used in the fit: errors before and after on them")
    sp.add_argument("--frame", choices=["instrument", "robot"], default="instrument",
                    help="frame of the measured points: an instrument's anywhere (default; "
                    "its pose is identified) or the robot's")
    sp.add_argument("--robust", metavar="LOSS", default=None,
                    help="robust loss: soft_l1, huber, cauchy or arctan (outliers rejected "
                    "and listed)")
    sp.add_argument("--outlier-factor", type=float, default=None, metavar="F",
                    help="a row farther from its prediction than this many residual scales "
                    "is an outlier (default 5)")
    into_directory(sp)
    no_figures_argument(sp, "calibrated.toml, the residuals and summary.json")


def run(args: argparse.Namespace, *, figures: bool = True) -> Result:
    """Calibrate (:func:`dextar.jobs.calibrate`: outliers diagnosed), write, word (the
    figures unless ``figures`` is False or the command line said ``--no-figures``)."""
    figures = figures and wants_figures(args)
    od = OutputDir(args.out, force=args.force, produces=written.CALIBRATION_FILES)  # checked
    kc = load_kinematic_config(args.config)
    rt, inst = kc.robot, kc.instrument
    with noted(kc):
        job = jobs.calibrate(args.data, kc, validate=args.validate, frame=args.frame,
                             robust=args.robust, outlier_factor=args.outlier_factor)
    d = job.diagnosis
    files = written.calibration_files(
        d.result, data=args.data, config=args.config or "", working_mode=rt.working_mode,
        assembly_mode=rt.assembly_mode, encoder_counts=rt.encoder_counts,
        extra=kc.other_tables(), validation=job.held, figures=figures, outliers=d.outliers,
        outlier_message=d.message, sigma_mm=inst.sigma_mm, region_mm=inst.region_mm)
    said = written.CalibrationRun(d.result, shown(args.out),
                                  written.write_calibration(od, files), outliers=d.outliers,
                                  problem=d.message, robust=args.robust,
                                  sigma_mm=inst.sigma_mm, working_mode=rt.working_mode,
                                  default_robot=rt.geometry_mm if args.config is None else None)
    return Result(said.payload(files), said.text(),
                  note_lines("calibrate", kc) + said.warnings(), code=said.code)
