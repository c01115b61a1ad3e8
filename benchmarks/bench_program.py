"""Planning the pick-and-place example (moves, setpoints, sizing; no figures), best of 5
(floor: under 1 s), and `dextar program` end to end as a user runs it (floor: under 1.5 s
whole process on the 2-core machine).

Run: python benchmarks/bench_program.py [--runs N]

The whole-process figures are best, median and worst of new processes on every CPU allowed
(the three figures drawn on two cores when two are allowed) and pinned to one CPU, each round
beside a reference of fixed work (``_process.py``: the machine's speed at the time); then the
steps in this process (one core). Python's bytecode cache is used as after an install.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

from _process import report, timed_rounds
from dextar.commands import program

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pick_place.toml"
FLOOR = 1.5


def timed(figures: bool) -> tuple[float, object]:
    best, res = float("inf"), None
    for _ in range(5):
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            args = argparse.Namespace(config=str(EXAMPLE), out=str(Path(tmp) / "out"),
                                      force=False, quiet=True, json=False, model=None,
                                      figures=figures)
            res = program.run(args)
            best = min(best, time.perf_counter() - t0)
    return best, res


def program_argv(out) -> list[str]:
    return [sys.executable, "-m", "dextar", "program", str(EXAMPLE), "--out", str(out),
            "--quiet"]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    print(f"load average before: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    cpus = sorted(os.sched_getaffinity(0))
    print(report(f"dextar program (new processes), {len(cpus)} CPUs",
                 *timed_rounds(program_argv, args.runs)[:2], FLOOR))
    print(report("dextar program, pinned to one CPU",
                 *timed_rounds(program_argv, args.runs, {cpus[0]})[:2], None))
    t_plan, res = timed(False)
    t_all, _ = timed(True)
    print(f"in this process: planned (moves, setpoints, sizing) in {t_plan * 1e3:.0f} ms "
          f"(floor 1 s); with the figures, SVGs and the report in {t_all:.2f} s; cycle time "
          f"{res.payload['cycle_time_s']:.4f} s, {res.payload['status']}")  # type: ignore[union-attr]
    print(f"load average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
