"""``dextar calibrate MEASURED.csv --config CONFIG.toml --out DIR``: the robot's lengths, its
encoder offsets and the instrument frame identified from measured poses, and a config with
them (``calibrated.toml``) loadable by every command.

Exit 0 calibrated; 1 for a fit computed that does not fit its data (not converged,
residuals above the stated noise, outliers: the files are written, a fit with outliers
without ``calibrated.toml``); 2 with one line for bad input.
"""

from __future__ import annotations

import argparse

from .base import Result, into_directory, shown

NAME = "calibrate"
HELP = ("calibrate the kinematics from measured poses and write a config with the identified "
        "lengths, encoder offsets and instrument frame (exit 1 when the fit does not fit)")
#: The measured points of a nominal robot's own predictions (m): a poses.csv, not data.
NOMINAL_ECHO = 1e-9


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
    import json

    import numpy as np

    from ..calibration import CalibrationResult, OutlierError, calibrate, read_poses_csv
    from ..calibration.data import rows_text
    from ..calibration.fit import OUTLIER_FACTOR, encoder_std
    from ..config import load_scenario
    from ..output.calibration import (
        CALIBRATION_FILES,
        OUTLIERS,
        STATUS_WORDS,
        calibration_files,
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

    def fit(factor: float) -> CalibrationResult:
        return calibrate(data, nominal, frame=args.frame, robust=args.robust,
                         outlier_factor=factor, point_std=point_std, reading_std=reading_std,
                         validation=held)

    outliers: tuple[int, ...] = ()
    problem = ""
    try:
        res = fit(OUTLIER_FACTOR if args.outlier_factor is None else args.outlier_factor)
    except OutlierError as exc:
        # a diagnosis: the fit with the outliers kept (their arrows in residuals.png)
        outliers, problem = exc.rows, str(exc)
        res = fit(1e300)
    extra = {k: v for k, v in sc.doc.items() if k not in ("robot", "instrument")}
    files = calibration_files(res, data=args.data, config=args.config or "",
                              working_mode=rt.working_mode, assembly_mode=rt.assembly_mode,
                              encoder_counts=rt.encoder_counts, extra=extra,
                              validation=held, figures=figures, outliers=outliers,
                              outlier_message=problem, sigma_mm=inst.sigma_mm)
    with od:
        for name in CALIBRATION_FILES:
            content = files.get(name)
            if isinstance(content, bytes):
                od.write_bytes(name, content)
            elif content is not None:
                od.write_text(name, content)
    written = [n for n in CALIBRATION_FILES if n in files]
    e = res.errors
    lines = [f"{STATUS_WORDS[OUTLIERS]}: {problem}" if outliers else res.message,
             f"  {len(e.rows)} poses: RMS error {1e3 * e.rms_before:.4g} -> "
             f"{1e3 * e.rms_after:.4g} mm, max {1e3 * e.max_before:.4g} -> "
             f"{1e3 * e.max_after:.4g} mm (nominal robot -> calibrated)"]
    if res.validation is not None:
        v = res.validation
        lines.append(f"  {len(v.rows)} held-out poses: RMS error {1e3 * v.rms_before:.4g} -> "
                     f"{1e3 * v.rms_after:.4g} mm, max {1e3 * v.max_before:.4g} -> "
                     f"{1e3 * v.max_after:.4g} mm")
    for p in res.parameters:
        unit, nom, val, std = p.in_file_units()
        spread = f" +- {std:.3g}" if std is not None else " (not identifiable: nominal)"
        lines.append(f"  {p.name:<10} {nom:12.6g} -> {val:12.6g}{spread} {unit}")
    lines.append(f"wrote {shown(args.out, written[0])}, {', '.join(written[1:])}")
    warnings: list[str] = []
    if outliers:  # one line: the rows, what to do, where the diagnosis is
        warnings.append(f"dextar calibrate: {problem} (--robust soft_l1); the fit with them "
                        f"kept is in {shown(args.out)} (no calibrated.toml)")
    else:
        if res.status != 0:
            stated = (f"; or [instrument].sigma_mm = {inst.sigma_mm:g} mm understates the "
                      "instrument's noise" if res.status == 2 and data.sigma is None
                      and inst.sigma_mm is not None else "")
            warnings.append(f"dextar calibrate: {STATUS_WORDS.get(res.status)}: "
                            f"{res.message}{stated}")
        if res.rejected:
            warnings.append(f"dextar calibrate: note: the robust loss {args.robust} rejected "
                            f"row{'s' if len(res.rejected) > 1 else ''} "
                            f"{rows_text(np.asarray(res.rejected))}")
        warnings += [f"dextar calibrate: warning: {w}" for w in res.warnings]
        if res.rms_error_before < NOMINAL_ECHO:
            warnings.append("dextar calibrate: warning: the measured points are the nominal "
                            "robot's own predictions (RMS error "
                            f"{1e3 * res.rms_error_before:.2g} mm): is this the file of dextar "
                            "poses rather than the measurements?")
        if args.config is None:
            g = rt.geometry_mm
            warnings.insert(0, f"dextar calibrate: note: no --config: the nominal robot is "
                            f"the DexTAR (l1 = {g.l1:g}, l2 = {g.l2:g}, L1 = {g.L1:g}, L2 = "
                            f"{g.L2:g}, d = {g.d:g} mm, encoder offsets 0, working mode "
                            f"{rt.working_mode})")
    payload = {**json.loads(files["summary.json"]), "out": shown(args.out),
               "files": written}
    code = 0 if res.status == 0 and not outliers else 1
    return Result(payload, "\n".join(lines), warnings, code=code)
