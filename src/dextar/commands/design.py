"""``dextar design TASK.toml``: sweep five-bar geometries for a task on Dask: every design's
row, the Pareto front, the chosen robot as a config, the figures and the report."""

from __future__ import annotations

import argparse
from typing import Any

from .base import Result, config_argument, into_directory, shown

NAME = "design"
HELP = "sweep five-bar geometries for a task on Dask: designs, Pareto front, the chosen robot"


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


def _progress(args: argparse.Namespace) -> Any:
    import sys

    if not (sys.stderr.isatty() and not args.quiet):
        return None

    def progress(done: int, total: int) -> None:
        sys.stderr.write(f"\rdesigns {done}/{total}" + ("\n" if done == total else ""))
        sys.stderr.flush()

    return progress


def run(args: argparse.Namespace, *, figures: bool = True) -> Result:
    """Sweep, choose, write, word."""
    import hashlib

    from ..config import load_scenario
    from ..design.evaluate import evaluate_path, inertia_of
    from ..design.pareto import choose
    from ..design.space import LENGTHS
    from ..design.sweep import Cluster, require_dask, run_sweep
    from ..geometry import FiveBar
    from ..output.design import (
        DESIGN_FILES,
        DesignsFile,
        best_workspace_figure,
        sweep_summary,
        write_sweep_outputs,
    )
    from ..output.files import OutputDir

    require_dask()
    sc = load_scenario(args.config, model=args.model)
    task, space = sc.design_task(samples=args.samples, seed=args.seed)
    designs = space.designs()
    n = len(designs)
    signature = hashlib.sha256(repr((sc.text, space, sc.design.grid)).encode()).hexdigest()
    with OutputDir(args.out, force=args.force, keep=args.resume, produces=DESIGN_FILES,
                   hint="use --force to overwrite it or --resume to complete its sweep") as od:
        store = DesignsFile(od, designs, signature, resume=args.resume, label=shown(args.out))
        with Cluster(workers=args.workers, scheduler=args.scheduler) as cluster, store:
            stats = run_sweep(cluster, task, designs, store.missing, chunk=sc.design.chunk,
                              on_chunk=store.append, progress=_progress(args))
        rows = store.finish()
        choice = choose(rows, space)
        best = choice.best_row
        summary = sweep_summary(args.config, task.kind, space, stats, choice, rows)
        best_toml = best_fig = None
        if best is not None:
            robot_mm = FiveBar(*(best[k] for k in LENGTHS))
            rods = (f"uniform rods of {space.mass_per_length[0]:g} and "
                    f"{space.mass_per_length[1]:g} kg/m" if space.mass_per_length else
                    "each rod of the task's robot keeps its linear density and shape on its "
                    "new length (mass and centre of mass scale with the length, the inertia "
                    "about the centre with its cube); the effector, payload and rotors as "
                    "given")
            best_toml = sc.model_file(
                robot_mm, task.working_mode, inertia_of(task, robot_mm.scaled(1e-3)),
                f"the Pareto design closest to the ideal point of dextar design {args.config} "
                f"(design {best['design']} of {n}; objectives {', '.join(space.objectives)})\n"
                f"rods: {rods}")
            if figures:
                best_fig = best_workspace_figure(robot_mm, task.working_mode,
                                                 evaluate_path(task, [best[k]
                                                                      for k in LENGTHS]))
        write_sweep_outputs(od, summary, choice, rows, space.varied_axes, best_toml,
                            best_fig, with_figures=figures)
    text = (f"design sweep: {n} designs ({stats.evaluated} evaluated, {n - stats.evaluated} "
            f"resumed) on {stats.workers} workers in {stats.wall_s:.1f} s "
            f"({summary['designs_per_second']:.3g} designs/s); {len(choice.feasible)} "
            f"feasible, {len(choice.pareto_rows)} on the Pareto front"
            + (f"; chosen design {best['design']}: l1 = {best['l1']:.4g}, l2 = "
               f"{best['l2']:.4g}, L1 = {best['L1']:.4g}, L2 = {best['L2']:.4g}, d = "
               f"{best['d']:.4g} mm -> {shown(args.out, 'best.toml')}" if best
               else "; no feasible design"))
    return Result(summary, text)
