"""``dextar run``: the main job, the paper's example (or the configured scenario) end to end:
the law, the trajectory, exact and paper-model torques, the checks, every figure and the
report."""

from __future__ import annotations

import argparse
import time
from typing import Any

from .base import Result, config_argument, into_directory, shown, with_notes

NAME = "run"
HELP = ("reproduce the paper end to end and write a report (exit 1 when a physics check "
        "fails, the files written)")
REGISTRIES_HELP = True


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``[config]``, ``--out`` (default ``dextar-out``), ``--force``, ``--quiet``, ``--json``."""
    config_argument(sp)
    into_directory(sp, default="dextar-out")


def run(args: argparse.Namespace) -> Result:
    """The command, with the config's notes (:func:`.base.with_notes`)."""
    return with_notes(NAME, args, _run)


def _run(args: argparse.Namespace) -> Result:
    """Compute through the stages, write every file, word the law and the claims."""
    import sys

    from ..analysis import analyze, run_summary, validation
    from ..config import load_scenario
    from ..output.files import OutputDir
    from ..output.parallel import Forked
    from ..output.run import RUN_FILES, Progress, staged, write_run

    sc = load_scenario(args.config, model=args.model)
    prog = Progress(enabled=not args.quiet and sys.stderr.isatty())
    stage = staged(prog)
    inputs = sc.inputs()
    with OutputDir(args.out, force=args.force, produces=RUN_FILES) as od:
        an = stage(f"{sc.law_table.type} law, trajectory and torques",
                   lambda: analyze(inputs, sc.law()))
        uniform = stage("uniform law (Fig. 3)", lambda: inputs.trajectory(sc.law("uniform")))

        def checked() -> tuple[dict[str, Any], float]:
            t0 = time.perf_counter()
            return validation(an), time.perf_counter() - t0

        # the physics checks (scipy's import and an integration: half a second) on the other
        # core while this one loads matplotlib and draws
        with Forked(checked) as checks:
            s = run_summary(an, None, inputs.trajectory(uniform.law, samples=201))
            write_run(od, an, uniform, s, validation=checks.result, figures=sc.output.figures,
                      animation_frames=sc.output.animation_frames, stage=stage, progress=prog)
    law = s["law"]
    warnings = ([] if law["success"] else
                [f"dextar run: warning: {law['type']} law status {law['status']}: "
                 f"{law['message']}"])
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
        f"{_figure(checks['power_balance_relative'])} (at most {checks['power_balance_threshold']:g}); "
        f"forward re-simulation in {fw.get('windows', 0)} windows, largest drift "
        f"{_figure(fw.get('max_drift_rad'))} rad, {_figure(fw.get('max_drift_ratio'))} of the "
        f"peak acceleration's (at most {fw['threshold']:g})")
    return Result(s, "\n".join(lines), warnings, code=0 if checks["passed"] else 1)


def _figure(v: float | None) -> str:
    """A check's figure, or "-" where it could not be computed."""
    return "-" if v is None else f"{v:.3g}"
