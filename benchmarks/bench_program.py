"""Planning the pick-and-place example (moves, setpoints, sizing; no figures), best of 5
(floor: under 1 s), and `dextar program` end to end as a user runs it (floor: under 1.5 s
whole process on the 2-core machine).

Run: python benchmarks/bench_program.py [--runs N]

The whole-process figures are best, median and worst of new processes on every CPU allowed
(the three figures drawn on two cores when two are allowed) and pinned to one CPU; then the
steps in this process (one core). Python's bytecode cache is used as after an install.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from dextar.commands import program

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pick_place.toml"
FLOOR = 1.5
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


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


def whole(runs: int, cpus: set[int] | None) -> list[float]:
    def pin() -> None:
        if cpus is not None:
            os.sched_setaffinity(0, cpus)

    out = []
    for k in range(runs + 1):
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "dextar", "program", str(EXAMPLE), "--out",
                            str(Path(tmp) / "out"), "--quiet"], check=True, env=ENV,
                           preexec_fn=pin)
            if k:
                out.append(time.perf_counter() - t0)
    return out


def spread(t: list[float]) -> str:
    s = sorted(t)
    return f"best {s[0]:5.2f} s, median {s[len(s) // 2]:5.2f} s, worst {s[-1]:5.2f} s"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    print(f"load average before: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    cpus = sorted(os.sched_getaffinity(0))
    print(f"dextar program (new processes), {len(cpus)} CPUs: {spread(whole(args.runs, None))} "
          f"over {args.runs} runs (floor {FLOOR} s)")
    print(f"dextar program, pinned to one CPU: {spread(whole(args.runs, {cpus[0]}))}")
    t_plan, res = timed(False)
    t_all, _ = timed(True)
    print(f"in this process: planned (moves, setpoints, sizing) in {t_plan * 1e3:.0f} ms "
          f"(floor 1 s); with the figures, SVGs and the report in {t_all:.2f} s; cycle time "
          f"{res.payload['cycle_time_s']:.4f} s, {res.payload['status']}")  # type: ignore[union-attr]
    print(f"load average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
