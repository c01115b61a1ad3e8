"""``dextar simulate``: computed-torque tracking of the configured motion by a perturbed
plant; the tracking, the torques against the limit and a summary."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from .. import jobs
from .._lazy import lazy_module
from ..simulation.control import FOLLOWED, INCOMPLETE, LEFT_TOLERANCE, SINGULARITY_MET
from .base import Result, config_argument, into_directory, load, note_lines, noted, shown

if TYPE_CHECKING:  # the writers, imported when the command runs (start-up: dextar._lazy)
    from ..output import simulation as written
else:
    written = lazy_module("dextar.output.simulation")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``[config]``, ``--out``, ``--force``, ``--quiet``, ``--json``."""
    config_argument(sp)
    into_directory(sp, default="dextar-sim")


def run(args: argparse.Namespace) -> Result:
    """Simulate (:func:`dextar.jobs.simulate`), write the files, word the errors and the
    saturation."""
    sc = load(args)
    with noted(sc):
        job = jobs.simulate(sc)
    tr, res, c = job.trajectory, job.result, job.control
    report = written.write_tracking(args.out, tr, res, sc.units, c, force=args.force)
    warnings = note_lines("simulate", sc)
    saturated = report["saturated_fraction"]
    why = (f"; the torque limit {c['torque_limit_nm']:g} N m saturated a motor during "
           f"{saturated:.1%} of the motion simulated" if saturated > 0 else "")
    if res.status == SINGULARITY_MET:
        warnings.append(f"dextar simulate: the controlled robot left the motion at "
                        f"{sc.units.time_text(res.t[-1])} of {tr.t[-1] * sc.units.time_s:.6g} "
                        f"s ({res.message}){why}; the files hold the motion up to there")
    elif res.status == LEFT_TOLERANCE:
        warnings.append(f"dextar simulate: not followed: {res.message}{why}")
    elif res.status == INCOMPLETE:
        warnings.append(f"dextar simulate: simulation incomplete: {res.message}{why}; the "
                        "files hold the motion up to there")
    elif saturated > 0:
        warnings.append(f"dextar simulate: warning: the torque limit {c['torque_limit_nm']:g} "
                        f"N m saturates a motor during {saturated:.1%} of the motion; it was "
                        f"followed within {report['tolerance_mm']:.4g} mm all the same")
    files = ", ".join(shown(args.out, n) for n in written.TRACKING_FILES)
    verdict = {FOLLOWED: "followed", INCOMPLETE: "INCOMPLETE (stopped by its step budget)"
               }.get(res.status, "NOT FOLLOWED")
    return Result(report, f"wrote {files}: {verdict} (tolerance {report['tolerance_mm']:.4g} "
                  f"mm): max task error {report['max_task_error_mm']:.4g} mm, max joint error "
                  f"{report['max_joint_error_deg']:.4g} deg, torque saturated "
                  f"{saturated:.1%} of the time", warnings, code=0 if res.success else 1)
