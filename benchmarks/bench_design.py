"""Design sweep speed: designs per second on one core (in this process, no Dask), then a
Dask local cluster of 1, 2 and 4 workers on the same designs, and the parallel efficiency
(designs/s at N workers over N times that at 1). The task is the pick-and-place example
(time-optimal moves, blended corners, dwells), with [design] ranges as in the README.

Run: python benchmarks/bench_design.py [--designs 48]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from dextar.config import load_toml
from dextar.config.scenario import scenario_from_dict
from dextar.design.evaluate import Task, evaluate_chunk
from dextar.design.sweep import Cluster, run_sweep
from dextar.jobs import si_model
from dextar.units import SI

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pick_place.toml"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--designs", type=int, default=48)
    args = ap.parse_args()
    doc = load_toml(EXAMPLE)
    doc["design"] = {"l": [50.0, 120.0], "L": [60.0, 140.0], "d": [0.0, 100.0],
                     "mass_per_length": [0.4, 0.3], "samples": args.designs}
    sc = scenario_from_dict(doc)
    space = sc.design.space(sc.robot_mm)
    designs = space.designs()
    prog, mt = sc.table("program"), sc.table("motors")
    task = Task(tuple(sc.moves), prog.start, sc.mode, sc.assembly, mt.limits(SI),
                mt.rms_torque, si_model(sc).inertia, space.mass_per_length, sc.design.grid,
                sc.tolerances)
    t0 = time.perf_counter()
    rows = evaluate_chunk(task, designs, 0)
    serial = len(rows) / (time.perf_counter() - t0)
    feasible = sum(r["feasible"] for r in rows)
    print(f"pick-and-place task, {len(rows)} designs ({feasible} feasible), time-optimal grid "
          f"{sc.design.grid}: {serial:.2f} designs/s on one core in this process "
          "(issue floor: 20)")
    base = None
    for n in (1, 2, 4):
        with Cluster(workers=n) as cl:
            stats = run_sweep(cl, task, designs, range(len(designs)), chunk=2,
                              on_chunk=lambda rows: None)
        rate = stats.evaluated / stats.wall_s
        base = base or rate
        print(f"dask, {n} worker(s): {rate:.2f} designs/s, efficiency {rate / (n * base):.2f} "
              f"({os.cpu_count()} cores here)")


if __name__ == "__main__":
    main()
