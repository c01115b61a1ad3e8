"""Wall time of the main job, `dextar run` with no config, as a new user runs it (floor:
under 2 s on the 2-core machine), with every file it writes; and where the time goes.

Run: python benchmarks/bench_run.py [--runs N]

* whole process, as many runs as asked (best, median and worst), on every CPU the process
  may use (the figures and the animation are drawn on two cores when two are allowed) and
  pinned to one CPU (drawn in turn: the same files);
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
import subprocess
import sys
import tempfile
import time
from pathlib import Path

FLOOR = 2.0
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def whole(runs: int, cpus: set[int] | None) -> tuple[list[float], dict[str, float]]:
    """Wall times of ``dextar run`` (new processes, after one untimed run) and its steps."""
    times: list[float] = []
    steps: dict[str, float] = {}

    def pin() -> None:
        if cpus is not None:
            os.sched_setaffinity(0, cpus)

    for k in range(runs + 1):
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "out"
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "dextar", "run", "--out", str(out),
                            "--quiet"], check=True, env=ENV, preexec_fn=pin)
            if k:
                times.append(time.perf_counter() - t0)
            steps = json.loads((out / "summary.json").read_text())["timing_s"]
            n_files = len(list(out.iterdir()))
    print(f"  ({n_files} files each run)")
    return times, steps


def spread(t: list[float]) -> str:
    s = sorted(t)
    return f"best {s[0]:5.2f} s, median {s[len(s) // 2]:5.2f} s, worst {s[-1]:5.2f} s"


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
    two, steps = whole(args.runs, None)
    print(f"dextar run, {len(cpus)} CPUs: {spread(two)} over {args.runs} runs (floor {FLOOR} s)")
    one, _ = whole(args.runs, {cpus[0]})
    print(f"dextar run, pinned to one CPU: {spread(one)}")
    print("the run's own steps (last run on every CPU):")
    for name, sec in steps.items():
        print(f"  {name:<52} {sec:6.3f} s")
    print("step by step in this process (one core):")
    steps_here()
    print(f"load average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
