"""``dextar program TASK.toml``: a robot program planned under the motors: setpoints, sizing,
figures and the report (exit status 1 when a motor limit is exceeded)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from .. import jobs
from .._lazy import lazy_module
from .base import Result, config_argument, into_directory, load, note_lines, noted

if TYPE_CHECKING:  # the writers, imported when the command runs (start-up: dextar._lazy)
    from ..output import program as written
else:
    written = lazy_module("dextar.output.program")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``config``, ``--out``, ``--force``, ``--quiet``, ``--json``, ``--no-figures``."""
    config_argument(sp, required=True,
                    help="TOML task file with [program], [[move]] and [motors]")
    into_directory(sp)
    sp.add_argument("--no-figures", dest="figures", action="store_false",
                    help="write the setpoints, the drive's files and summary.json only (no "
                         "figures, no report.html): for batches of programs")


def run(args: argparse.Namespace) -> Result:
    """Plan and size (:func:`dextar.jobs.program`), write, word (the figures unless
    ``--no-figures``)."""
    sc = load(args)
    with noted(sc):
        job = jobs.program(sc)
    res, summary = job.result, job.summary
    written.write_program(args.out, res, summary, sc.robot_mm,
                          job.start_mode or sc.program_mode,
                          force=args.force, with_figures=args.figures, drive=job.drive,
                          pvt=job.pvt)
    warnings = note_lines("program", sc)
    warnings += [f"dextar program: {v.text()}" for v in summary.sizing.violations]
    warnings += [f"dextar program: warning: {n}" for n in job.warnings]
    words = summary.lines(args.out, res.t.size, args.figures)
    return Result(summary.as_json(), "\n".join(words), warnings, code=0 if job.fits else 1)
