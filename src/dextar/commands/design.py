"""``dextar design TASK.toml``: sweep or search five-bar geometries for a task on Dask: every
design's row, the Pareto front, the chosen robot as a config, the figures and the report."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

from .. import jobs
from .._lazy import lazy_module
from ..output.files import OutputDir
from .base import (
    Result,
    config_argument,
    into_directory,
    load,
    no_figures_argument,
    note_lines,
    noted,
    shown,
    wants_figures,
)

if TYPE_CHECKING:  # the writers, imported when the command runs (start-up: dextar._lazy)
    import dextar.design.search  # (named in full: the docs' references find its Progress)

    from ..output import design as written
else:
    written = lazy_module("dextar.output.design")


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``config``, ``--out``, ``--samples``, ``--seed``, ``--workers`` | ``--scheduler``,
    ``--resume``, ``--force``, ``--quiet``, ``--json``, ``--no-figures``."""
    config_argument(sp, required=True, help="TOML task file (a program task or a run config) "
                    "with [design]")
    into_directory(sp, force="overwrite a non-empty --out")
    sp.add_argument("--samples", type=int, default=None,
                    help="designs: a sweep's samples or a search's evaluations (default "
                    "[design])")
    sp.add_argument("--seed", type=int, default=None,
                    help="seed of the sampling or search (default [design])")
    where = sp.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None,
                       help="processes of a local Dask cluster (default: the cores)")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="a running Dask scheduler, e.g. tcp://host:8786")
    sp.add_argument("--resume", action="store_true",
                    help="complete the sweep or search in --out (evaluate only what is "
                    "missing)")
    no_figures_argument(sp, "designs.csv, pareto.csv, best.toml and summary.json")


def duration_text(seconds: float) -> str:
    """A time left in words: ``"45 s"``, ``"2 min 10 s"``, ``"1 h 05 min"``."""
    s = max(0, math.ceil(seconds))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"


def progress_line(p: dextar.design.search.Progress) -> str:
    """One line of progress: designs done, feasible share, the front's hypervolume, time
    left."""
    parts = [f"designs {p.done}/{p.total}" + (f" ({p.resumed} resumed)" if p.resumed else ""),
             f"feasible {100 * p.feasible_share:.0f} %"]
    if p.hypervolume is not None:
        parts.append(f"hypervolume {p.hypervolume:.4g}")
    if p.left_s is not None and p.done < p.total:
        parts.append(f"about {duration_text(p.left_s)} left")
    return ", ".join(parts)


def _terminal(args: argparse.Namespace) -> bool:
    return sys.stderr.isatty() and not args.quiet


def _progress(args: argparse.Namespace) -> Callable[[dextar.design.search.Progress], None] | None:
    """Progress on stderr, one line rewritten in place, at a terminal only."""
    if not _terminal(args):
        return None
    width = [0]

    def progress(p: dextar.design.search.Progress) -> None:
        line = progress_line(p)
        pad = max(0, width[0] - len(line))
        width[0] = len(line)
        sys.stderr.write("\r" + line + " " * pad + ("\n" if p.done >= p.total else ""))
        sys.stderr.flush()

    return progress


def _dashboard(args: argparse.Namespace) -> Callable[[str], None] | None:
    if not _terminal(args):
        return None

    def say(link: str) -> None:
        sys.stderr.write(f"Dask dashboard: {link} (tasks dextar-design; Fine Performance "
                         "Metrics, unit designs: feasible and not)\n")

    return say


def run(args: argparse.Namespace, *, figures: bool = True) -> Result:
    """Sweep and choose (:func:`dextar.jobs.design`), write, word (the figures unless
    ``figures`` is False or the command line said ``--no-figures``)."""
    figures = figures and wants_figures(args)
    sc = load(args)
    with noted(sc):
        sweep = jobs.design_sweep(sc, samples=args.samples, seed=args.seed)
    what = "sweep" if sweep.search is None else "search"
    with OutputDir(args.out, force=args.force, keep=args.resume, produces=written.DESIGN_FILES,
                   staged=False,
                   hint=f"use --force to overwrite it or --resume to complete its {what}") as od:
        store = written.DesignsFile(od, sweep.designs if sweep.search is None else None,
                                    sweep.signature, resume=args.resume, label=shown(args.out),
                                    variables=sweep.space.columns)
        res = jobs.design(sweep, workers=args.workers, scheduler=args.scheduler, store=store,
                          progress=_progress(args), dashboard=_dashboard(args),
                          label=args.config, store_label=shown(args.out, "designs.csv"))
        summary = written.sweep_summary(args.config, sweep.task.kind, sweep.space, res.stats,
                                        res.choice, res.rows, sweep.search, res.hypervolume)
        best_fig = None
        if figures and res.best_robot_mm is not None and res.best_path_mm is not None:
            best_fig = written.best_workspace_figure(res.best_robot_mm, sweep.task.working_mode,
                                                     res.best_path_mm)
        written.write_sweep_outputs(od, summary, res.choice, res.rows,
                                    sweep.space.varied_axes, res.best_toml, best_fig,
                                    with_figures=figures, hypervolume=res.hypervolume)
    stats, best, n = res.stats, res.best, len(res.rows)
    text = (f"design {what} ({sweep.kind}): {n} designs ({stats.evaluated} evaluated, "
            f"{n - stats.evaluated} "
            f"resumed) on {stats.workers} workers in {stats.wall_s:.1f} s "
            f"({summary['designs_per_second']:.3g} designs/s); {len(res.choice.feasible)} "
            f"feasible, {len(res.choice.pareto_rows)} on the Pareto front"
            + (f"; chosen design {best['design']}: l1 = {best['l1']:.4g}, l2 = "
               f"{best['l2']:.4g}, L1 = {best['L1']:.4g}, L2 = {best['L2']:.4g}, d = "
               f"{best['d']:.4g} mm -> {shown(args.out, 'best.toml')}" if best
               else "; no feasible design"))
    return Result(summary, text, note_lines("design", sc))
