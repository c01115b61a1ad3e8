"""Design sweep speed, printed: designs per second on one core in this process (no Dask) for

* a ``dextar run`` task (examples/line_si.toml: one line, a min-jerk law, motors added):
  geometry and torque metrics, no time-optimal law (issue floor: 200 designs/s per core);
* the pick-and-place program (time-optimal moves, blended corners, dwells, a fitted law)
  (issue floor: 20 designs/s per core),

each the best of three runs (all three are printed: this machine's speed wanders), then each
task on a Dask local cluster of 1, 2 and 4 workers (chunks of 64 and of 8 designs, the
``[design]`` default), with the parallel efficiency (designs/s at N workers over N times that
at 1; this machine's core count is printed).

Run: python benchmarks/bench_design.py [--designs 96]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from dextar.config import load_scenario, load_toml
from dextar.design.evaluate import evaluate_chunk
from dextar.design.sweep import Cluster, run_sweep

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
REPEATS = 3
RANGES = {"l": [50.0, 120.0], "L": [60.0, 140.0], "d": [0.0, 100.0],
          "mass_per_length": [0.4, 0.3]}


def task_file(folder: Path, example: str, samples: int, extra: dict) -> Path:
    from tests.robustness.harness import toml_text

    doc = load_toml(EXAMPLES / example)
    doc.update(extra)
    doc["design"] = {**RANGES, "samples": samples}
    path = folder / example
    path.write_text(toml_text(doc))
    return path


def measure(name: str, path: Path, chunk: int) -> None:
    task, space = load_scenario(path).design_task()
    designs = space.designs()
    evaluate_chunk(task, designs[:2], 0)  # warm caches
    times = []
    for _ in range(REPEATS):  # the best of a few runs: the machine's own noise is large
        t0 = time.perf_counter()
        rows = evaluate_chunk(task, designs, 0)
        times.append(time.perf_counter() - t0)
    rates = sorted(len(rows) / t for t in times)
    print(f"{name}: {len(rows)} designs ({sum(r['feasible'] for r in rows)} feasible), "
          f"{rates[-1]:.1f} designs/s on one core in this process (best of {REPEATS}; "
          f"all: {', '.join(f'{r:.1f}' for r in rates)})")
    base = None
    for n in (1, 2, 4):
        with Cluster(workers=n) as cl:
            run_sweep(cl, task, designs, range(min(8, len(designs))), chunk=chunk,
                      on_chunk=lambda rows: None)  # workers warm
            stats = run_sweep(cl, task, designs, range(len(designs)), chunk=chunk,
                              on_chunk=lambda rows: None)
        rate = stats.evaluated / stats.wall_s
        base = base or rate
        print(f"  dask, {n} worker(s): {rate:.1f} designs/s, efficiency "
              f"{rate / (n * base):.2f} ({os.cpu_count()} cores here)")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--designs", type=int, default=96)
    args = ap.parse_args()
    import sys

    sys.path.insert(0, str(EXAMPLES.parent))
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        run = task_file(folder, "line_si.toml", 20 * args.designs,
                        {"motors": {"peak_torque": 1.0}})
        measure("run task (line, min-jerk; floor 200/s per core)", run, 64)
        prog = task_file(folder, "pick_place.toml", args.designs, {})
        measure("pick-and-place program (time-optimal; floor 20/s per core)", prog, 8)


if __name__ == "__main__":
    main()
