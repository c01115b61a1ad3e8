"""``dextar run``: the main job, the paper's example (or the configured scenario) end to end:
the law, the trajectory, exact and paper-model torques, the checks, every figure and the
report."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

from .. import jobs
from .._lazy import lazy_module
from ..output.files import OutputDir
from .base import Result, config_argument, into_directory, load, note_lines, noted, shown

if TYPE_CHECKING:  # the writers, imported when the command runs (start-up: dextar._lazy)
    from ..output import run as written
else:
    written = lazy_module("dextar.output.run")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``[config]``, ``--out`` (default ``dextar-out``), ``--force``, ``--quiet``, ``--json``."""
    config_argument(sp)
    into_directory(sp, default="dextar-out")


def run(args: argparse.Namespace) -> Result:
    """Run (:func:`dextar.jobs.run`; its physics checks on the other core while this one
    draws), write every file, word the law, the claims and the checks."""
    sc = load(args)
    prog = written.Progress(enabled=not args.quiet and sys.stderr.isatty())
    stage = written.staged(prog)
    with noted(sc), OutputDir(args.out, force=args.force, produces=written.RUN_FILES) as od:
        res = jobs.run(sc, stage=stage)
        try:
            written.write_run(od, res.analysis, res.uniform, res.summary,
                              validation=res.validation, figures=sc.output.figures,
                              animation_frames=sc.output.animation_frames, stage=stage,
                              progress=prog)
        finally:  # the checks' process ended, whatever happened to the files
            res.checks.close()
    s = res.summary
    law = s["law"]
    warnings = note_lines("run", sc)
    if not law["success"]:
        warnings.append(f"dextar run: warning: {law['type']} law status {law['status']}: "
                        f"{law['message']}")
    checks = s["validation"]
    warnings += [f"dextar run: check failed: {why}" for why in checks["failed"]]
    lines = [f"wrote {len(s['files'])} files to {shown(args.out)} (open "
             f"{shown(args.out, 'report.html')})",
             f"{law['type']} law: motion time {law['duration_s']:.6g} s; status "
             f"{law['status']}: {law['message']}"]
    if "cost" in s:
        lines.append(f"cost Phi = {s['cost']['total']:.8g} [{s['cost']['unit']}]")
    lines.append(f"peak |tau| exact = {max(s['torques']['exact']['peak']):.6g} "
                 f"{s['units']['torque_unit']}")
    lines += [f"  {c['verdict']:>11}: {c['claim']} ({c['value']:.3g})"
              for c in s.get("claims", [])]
    fw = checks["forward_resimulation"]
    lines.append(
        f"checks {'passed' if checks['passed'] else 'FAILED'}: power balance "
        f"{_figure(checks['power_balance_relative'])} (at most "
        f"{checks['power_balance_threshold']:g}); forward re-simulation in "
        f"{fw.get('windows', 0)} windows, largest drift {_figure(fw.get('max_drift_rad'))} "
        f"rad, {_figure(fw.get('max_drift_ratio'))} of the peak acceleration's (at most "
        f"{fw['threshold']:g})")
    return Result(s, "\n".join(lines), warnings, code=0 if checks["passed"] else 1)


def _figure(v: float | None) -> str:
    """A check's figure, or "-" where it could not be computed."""
    return "-" if v is None else f"{v:.3g}"
