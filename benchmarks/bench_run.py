"""Wall time of the main job, `dextar run` with no config, as a new user runs it (floor:
under 2 s on the 2-core machine), with every file it writes; and where the time goes.

Run: python benchmarks/bench_run.py [--runs N]

* whole process, as many runs as asked (best, median and worst), on every CPU the process
  may use (the validation, the figures and the animation on two cores when two are allowed)
  and pinned to one CPU (in turn: the same files), each round beside a reference of fixed
  work (``_process.py``: the machine's speed at the time);
* the run's own steps (``summary.json``'s ``timing_s``) of the last unpinned run;
* step by step in this process, one core: imports, the numerics, each figure (built and
  laid out, PNG, SVG), the animation, the report.

Python's bytecode cache is used as after an install; the load average is printed before and
after (the machine is shared: a busy second core takes the two-core gain away).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

from _process import report, timed_rounds

FLOOR = 2.0


def run_argv(out) -> list[str]:
    return [sys.executable, "-m", "dextar", "run", "--out", str(out), "--quiet"]


def steps_here() -> None:
    """The run's work step by step in this process (one core), in the order it runs."""
    t0 = time.perf_counter()
    from dextar.analysis import analyze, run_summary, validation
    from dextar.config import load_scenario
    from dextar.output import figures as fg
    from dextar.output.report import render_report
    from dextar.output.tables import csv_text, run_columns

    print(f"  imports (numpy, scipy, matplotlib, dextar)    {time.perf_counter() - t0:6.3f} s")
    t = time.perf_counter()
    sc = load_scenario(None)
    inputs = sc.inputs()
    an = analyze(inputs, sc.law())
    uniform = inputs.trajectory(sc.law("uniform"))
    s = run_summary(an, validation(an), inputs.trajectory(uniform.law, samples=201))
    csv_text(run_columns(an))
    print(f"  numerics (law, torques, checks) and the CSV   {time.perf_counter() - t:6.3f} s")
    makers = {"fig3": lambda: fg.fig3(an, uniform), "fig4": lambda: fg.fig4(an),
              "fig5": lambda: fg.fig5(an), "fig6": lambda: fg.fig6(an),
              "fig7": lambda: fg.fig7(an), "fig8": lambda: fg.fig8(an),
              "fig9": lambda: fg.fig9(an), "workspace": lambda: fg.workspace_figure(an)}
    total, pngs = 0.0, {}
    t = time.perf_counter()
    fg.warm_up()
    print(f"  fonts and mathtext parser (once a process)    {time.perf_counter() - t:6.3f} s")
    for name, make in makers.items():
        t = time.perf_counter()
        fig = make()
        a = time.perf_counter()
        pngs[name] = fg.png_bytes(fig)
        b = time.perf_counter()
        if name != "workspace":
            fg.svg_bytes(fig)
        c = time.perf_counter()
        total += c - t
        print(f"  {name:<10} built and laid out {a - t:6.3f} s, PNG {b - a:6.3f} s, SVG "
              f"{c - b:6.3f} s")
    t = time.perf_counter()
    gif = fg.animation_gif(an, sc.output.animation_frames)
    g = time.perf_counter() - t
    t = time.perf_counter()
    render_report(an, s, pngs, gif)
    print(f"  figures {total:6.3f} s, animation {g:6.3f} s, report "
          f"{time.perf_counter() - t:6.3f} s")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    print(f"load average before: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    cpus = sorted(os.sched_getaffinity(0))
    two, ref, last = timed_rounds(run_argv, args.runs)
    print(f"  ({len(list(last.iterdir()))} files each run)")
    print(report(f"dextar run, {len(cpus)} CPUs", two, ref, FLOOR))
    one, ref1, _ = timed_rounds(run_argv, args.runs, {cpus[0]})
    print(report("dextar run, pinned to one CPU", one, ref1, None))
    print("the run's own steps (last run on every CPU):")
    for name, sec in json.loads((last / "summary.json").read_text())["timing_s"].items():
        print(f"  {name:<52} {sec:6.3f} s")
    print("step by step in this process (one core):")
    steps_here()
    print(f"load average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
