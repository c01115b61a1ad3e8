"""``dextar design TASK.toml``: sweep five-bar geometries for a task on Dask: every design's
row, the Pareto front, the chosen robot as a config, the figures and the report."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

from .. import jobs
from .._lazy import lazy_module
from ..output.files import OutputDir
from .base import Result, config_argument, into_directory, load, note_lines, noted, shown

if TYPE_CHECKING:  # the writers, imported when the command runs (start-up: dextar._lazy)
    from ..output import design as written
else:
    written = lazy_module("dextar.output.design")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``config``, ``--out``, ``--samples``, ``--seed``, ``--workers`` | ``--scheduler``,
    ``--resume``, ``--force``, ``--quiet``, ``--json``."""
    config_argument(sp, required=True, help="TOML task file (a program task or a run config) "
                    "with [design]")
    into_directory(sp, force="overwrite a non-empty --out")
    sp.add_argument("--samples", type=int, default=None, help="designs (default [design])")
    sp.add_argument("--seed", type=int, default=None, help="sampling seed (default [design])")
    where = sp.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None,
                       help="processes of a local Dask cluster (default: the cores)")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="a running Dask scheduler, e.g. tcp://host:8786")
    sp.add_argument("--resume", action="store_true",
                    help="complete the sweep in --out (evaluate only what is missing)")


def _progress(args: argparse.Namespace) -> Callable[[int, int], None] | None:
    if not (sys.stderr.isatty() and not args.quiet):
        return None

    def progress(done: int, total: int) -> None:
        sys.stderr.write(f"\rdesigns {done}/{total}" + ("\n" if done == total else ""))
        sys.stderr.flush()

    return progress


def run(args: argparse.Namespace, *, figures: bool = True) -> Result:
    """Sweep and choose (:func:`dextar.jobs.design`), write, word."""
    sc = load(args)
    with noted(sc):
        sweep = jobs.design_sweep(sc, samples=args.samples, seed=args.seed)
    n = len(sweep.designs)
    with OutputDir(args.out, force=args.force, keep=args.resume, produces=written.DESIGN_FILES,
                   hint="use --force to overwrite it or --resume to complete its sweep") as od:
        store = written.DesignsFile(od, sweep.designs, sweep.signature, resume=args.resume,
                                    label=shown(args.out))
        res = jobs.design(sweep, workers=args.workers, scheduler=args.scheduler, store=store,
                          progress=_progress(args), label=args.config)
        summary = written.sweep_summary(args.config, sweep.task.kind, sweep.space, res.stats,
                                        res.choice, res.rows)
        best_fig = None
        if figures and res.best_robot_mm is not None and res.best_path_mm is not None:
            best_fig = written.best_workspace_figure(res.best_robot_mm, sweep.task.working_mode,
                                                     res.best_path_mm)
        written.write_sweep_outputs(od, summary, res.choice, res.rows,
                                    sweep.space.varied_axes, res.best_toml, best_fig,
                                    with_figures=figures)
    stats, best = res.stats, res.best
    text = (f"design sweep: {n} designs ({stats.evaluated} evaluated, {n - stats.evaluated} "
            f"resumed) on {stats.workers} workers in {stats.wall_s:.1f} s "
            f"({summary['designs_per_second']:.3g} designs/s); {len(res.choice.feasible)} "
            f"feasible, {len(res.choice.pareto_rows)} on the Pareto front"
            + (f"; chosen design {best['design']}: l1 = {best['l1']:.4g}, l2 = "
               f"{best['l2']:.4g}, L1 = {best['L1']:.4g}, L2 = {best['L2']:.4g}, d = "
               f"{best['d']:.4g} mm -> {shown(args.out, 'best.toml')}" if best
               else "; no feasible design"))
    return Result(summary, text, note_lines("design", sc))
