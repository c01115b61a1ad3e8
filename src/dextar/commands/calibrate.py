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

from .base import Result, into_directory, shown

if TYPE_CHECKING:
    from ..calibration import CalibrationResult, KinematicModel, PoseData

NAME = "calibrate"
HELP = ("calibrate the kinematics from measured poses and write a config with the identified "
        "lengths, encoder offsets and instrument frame (exit 1 when the fit does not fit)")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``data``, ``--config``, ``--validate``, ``--frame``, ``--robust``,
    ``--outlier-factor``, ``--out``, ``--force``, ``--quiet``, ``--json``."""
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


def run(args: argparse.Namespace, *, figures: bool = True) -> Result:
    """Read, calibrate, write, word."""
    from ..calibration import read_poses_csv
    from ..calibration.fit import encoder_std
    from ..config import load_scenario
    from ..output.calibration import (
        CALIBRATION_FILES,
        CalibrationRun,
        calibration_files,
        write_calibration,
    )
    from ..output.files import OutputDir

    od = OutputDir(args.out, force=args.force, produces=CALIBRATION_FILES)  # checked now
    sc = load_scenario(args.config)
    rt, inst = sc.robot_table, sc.instrument_table
    nominal = sc.kinematic_model
    data = read_poses_csv(args.data, working_mode=rt.working_mode)
    held = (read_poses_csv(args.validate, working_mode=rt.working_mode)
            if args.validate else None)
    point_std = None if inst.sigma_mm is None else 1e-3 * inst.sigma_mm
    reading_std = None if rt.encoder_counts is None else encoder_std(rt.encoder_counts)
    res, outliers, problem = _fit_or_diagnose(args, data, nominal, point_std=point_std,
                                              reading_std=reading_std, validation=held)
    extra = {k: v for k, v in sc.doc.items() if k not in ("robot", "instrument")}
    files = calibration_files(res, data=args.data, config=args.config or "",
                              working_mode=rt.working_mode, assembly_mode=rt.assembly_mode,
                              encoder_counts=rt.encoder_counts, extra=extra,
                              validation=held, figures=figures, outliers=outliers,
                              outlier_message=problem, sigma_mm=inst.sigma_mm,
                              region_mm=inst.region_mm)
    said = CalibrationRun(res, shown(args.out), write_calibration(od, files),
                          outliers=outliers, problem=problem, robust=args.robust,
                          sigma_mm=inst.sigma_mm, working_mode=rt.working_mode,
                          default_robot=rt.geometry_mm if args.config is None else None)
    return Result(said.payload(files), said.text(), said.warnings(), code=said.code)


def _fit_or_diagnose(args: argparse.Namespace, data: PoseData, nominal: KinematicModel, *,
                     point_std: float | None, reading_std: float | None,
                     validation: PoseData | None
                     ) -> tuple[CalibrationResult, tuple[int, ...], str]:
    """The calibration the options ask for; when it finds outliers, the fit that keeps
    them (a diagnosis: their arrows in residuals.png) with their rows and the error's
    words; when that fit fails its own checks (rows that wreck it), the outliers' error."""
    from ..calibration import OutlierError, calibrate
    from ..calibration.fit import OUTLIER_FACTOR
    from ..errors import DextarError

    def fit(factor: float) -> CalibrationResult:
        return calibrate(data, nominal, frame=args.frame, robust=args.robust,
                         outlier_factor=factor, point_std=point_std, reading_std=reading_std,
                         validation=validation)

    factor = OUTLIER_FACTOR if args.outlier_factor is None else args.outlier_factor
    try:
        return fit(factor), (), ""
    except OutlierError as exc:
        try:
            return fit(1e300), exc.rows, str(exc)
        except DextarError:
            raise OutlierError(f"{exc} (--robust soft_l1)", exc.rows) from None
