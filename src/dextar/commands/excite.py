"""``dextar excite CONFIG.toml``: an exciting trajectory for identification (a Fourier series
per motor, the base regressor's condition number minimised), written as CSV at the servo
rate with the torques the config's model predicts."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from .. import jobs
from .._lazy import lazy_module
from ..output.tables import csv_text
from .base import Result, config_argument, json_flag, load, note_lines, out_file, write_or_hand_back

if TYPE_CHECKING:  # the writers, imported when the command runs (start-up: dextar._lazy)
    from ..output import identification as written
else:
    written = lazy_module("dextar.output.identification")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``config``, ``--out``, ``--duration``, ``--harmonics``, ``--base-hz``, ``--seed``."""
    config_argument(sp, required=True, help="TOML config: the robot, its prior masses, "
                    "[motors]")
    json_flag(sp)
    sp.add_argument("--out", required=True, help="CSV file (- for stdout)")
    sp.add_argument("--duration", type=float, default=20.0,
                    help="seconds, rounded up to whole periods (default 20)")
    sp.add_argument("--harmonics", type=int, default=5, help="harmonics per motor (default 5)")
    sp.add_argument("--base-hz", type=float, default=0.2,
                    help="base frequency, Hz (default 0.2: a 5 s period)")
    sp.add_argument("--seed", type=int, default=0, help="seed of the optimiser's starts")
    sp.add_argument("--task", metavar="TASK.toml",
                    help="a program or run config whose joint region and speeds to cover "
                    "(its robot must be the config's)")
    sp.add_argument("--quiet", action="store_true", help="no summary output")


def run(args: argparse.Namespace) -> Result:
    """Design the motion (:func:`dextar.jobs.excite`), sample it at the servo rate, write
    it."""
    target = out_file(args.out, ".csv")
    sc = load(args)
    job = jobs.excite(sc, harmonics=args.harmonics, base_hz=args.base_hz,
                      duration=args.duration, seed=args.seed, task=args.task)
    res, region = job.result, job.region
    rate = sc.output.servo_rate_hz
    cols = written.excitation_columns(sc.si_model, res, rate)
    where, data = write_or_hand_back(target, csv_text(cols))
    payload = written.excitation_payload(res, args.harmonics, args.base_hz, len(cols["t_s"]),
                                         rate, where)
    text = (f"exciting trajectory: condition number {res.condition_number:.4g} (base "
            f"regressor, unit-norm columns); {res.periods} period(s) of "
            f"{res.trajectory.period:g} s, {args.harmonics} harmonics; peak torques "
            f"{res.peak_torque[0]:.4g}, {res.peak_torque[1]:.4g} N m; min singularity "
            f"distances type 1 {res.min_type1_distance:.3g}, type 2 "
            f"{res.min_type2_distance:.3g}; wrote {where} ({payload['samples']} samples at "
            f"{rate:g} Hz)")
    if res.coverage is not None:
        text += "; " + written.coverage_text(res, region is not None)
    # below the advisory floors: written, exit 0, a warning (see identification.excite)
    warnings = [] if res.status == 0 else [f"dextar excite: warning: {res.message}"]
    if region is not None:
        text += (f"; covers {res.region_coverage:.1%} of the task's poses, at "
                 f"{res.region_speed_ratio[0]:.2f} and {res.region_speed_ratio[1]:.2f} of its "
                 "peak speeds")
        if res.region_coverage < 1.0 or (res.region_speed_ratio < 1.0).any():
            warnings.append(f"dextar excite: warning: the motion covers "
                            f"{res.region_coverage:.1%} of the task's poses and reaches "
                            f"{res.region_speed_ratio.min():.2f} of its peak speed: an "
                            "identification from it extrapolates on the rest")
    warnings[:0] = note_lines("excite", sc)  # the config's notes (a robot in metres), first
    return Result(payload, text, warnings, data=data)

