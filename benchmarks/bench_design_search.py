"""The adaptive design search (``[design] search = "nsga2"``) against the Sobol sweep, on two
tasks, printed as tables:

* a ``dextar program`` task: the pick-and-place (examples/pick_place.toml: time-optimal
  moves, blends, dwells), l, L and d varied, objectives cycle time, footprint and distance
  to parallel singularities (maximised);
* a ``dextar run`` config: examples/line_si.toml (a line under a min-jerk law, motors of
  1 N m), l1, l2, L1, L2 and d varied, objectives peak torque of motor A, footprint and
  dexterity (maximised).

For each: a dense Sobol sweep (``--dense`` designs) gives the reference front; the
hypervolume of the front found (objectives scaled between the reference front's ideal and
nadir points, reference point 1.1) is printed against the designs evaluated, for the Sobol
sweep (the first n designs of the dense one) and for the search (``--seeds`` seeds, the
worst and the best), as a fraction of the reference's. The issue's floor: the search reaches
0.95 of the reference with at most 10 % of the dense sweep's evaluations.

Then the search's speed on Dask: designs per second at 1 and 2 workers (the same designs:
the proposals do not depend on the workers) and the parallel efficiency (floor 0.8 at 2);
and the generational NSGA-II (a batch of a whole population, told at once: the workers wait
on each generation's slowest chunk) beside the steady-state scheme the search uses (batches
of ``chunk`` designs, a generation's worth in flight), in hypervolume and wall time.

The machine's load average is printed with each timing (the machine may be shared).

Run: python benchmarks/bench_design_search.py [--dense 4096] [--seeds 3] [--task program|run]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from dextar.config import load_scenario, load_toml
from dextar.design.pareto import pareto_mask
from dextar.design.search import (
    SearchSettings,
    hypervolume,
    hypervolume_curve,
    objectives_and_violation,
    run_search,
)
from dextar.design.sweep import Cluster, run_sweep

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
TASKS = {
    "program": ("pick_place.toml", {},
                {"l": [50.0, 120.0], "L": [60.0, 140.0], "d": [0.0, 100.0],
                 "mass_per_length": [0.4, 0.3],
                 "objectives": ["cycle_time_s", "footprint_mm", "-min_type2_distance"]}),
    "run": ("line_si.toml", {"motors": {"peak_torque": 1.0}},
            {"l1": [50.0, 120.0], "l2": [50.0, 120.0], "L1": [60.0, 140.0],
             "L2": [60.0, 140.0], "d": [0.0, 100.0], "mass_per_length": [0.4, 0.3],
             "objectives": ["peak_torque_A_Nm", "footprint_mm", "-gci"]}),
}
POPULATION = 40
CHUNK = 8


def load() -> str:
    """The load average over the last minute, and the cores."""
    return f"load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores"


def task_file(folder: Path, name: str) -> Path:
    from tests.robustness.harness import toml_text

    example, extra, design = TASKS[name]
    doc = load_toml(EXAMPLES / example)
    doc.update(extra)
    doc["design"] = {**design, "chunk": CHUNK}
    path = folder / f"{name}.toml"
    path.write_text(toml_text(doc))
    return path


def collect(rows: list, into: dict) -> None:
    into.update((r["design"], r) for r in rows)


def dense_sweep(cluster: Cluster, task, space, n: int, cache: Path | None, name: str):
    """The dense sweep's rows (cached by task name and size when ``cache`` is given)."""
    import pickle

    f = cache / f"dense-{name}-{n}.pickle" if cache else None
    if f is not None and f.exists():
        return pickle.loads(f.read_bytes()), None
    sp = replace(space, samples=n)
    got: dict = {}
    stats = run_sweep(cluster, task, sp.designs(), range(n), chunk=64,
                      on_chunk=lambda rows: collect(rows, got))
    rows = [got[i] for i in range(n)]
    if f is not None:
        f.write_bytes(pickle.dumps(rows))
    return rows, stats


def search(cluster: Cluster, task, space, settings: SearchSettings):
    got: dict = {}
    ran = run_search(cluster, task, replace(space, seed=settings.seed), settings,
                     resumed={}, on_chunk=lambda rows: collect(rows, got))
    return [got[i] for i in range(ran.designs)], ran


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--dense", type=int, default=4096)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--task", choices=[*TASKS, "both"], default="both")
    ap.add_argument("--cache", type=Path, default=None,
                    help="keep the dense sweeps here (reruns skip them)")
    ap.add_argument("--no-speed", action="store_true", help="skip the 1/2 worker timings")
    args = ap.parse_args()
    sys.path.insert(0, str(EXAMPLES.parent))
    budget = args.dense // 10
    checkpoints = sorted({POPULATION, budget // 4, budget // 2, 3 * budget // 4, budget})
    with tempfile.TemporaryDirectory() as tmp, Cluster(workers=2) as two:
        for name in (TASKS if args.task == "both" else [args.task]):
            task, space = load_scenario(task_file(Path(tmp), name)).design_task()
            run_sweep(two, task, space.designs()[:8], range(8), chunk=4,
                      on_chunk=lambda rows: None)  # workers warm
            print(f"\n== {name} task ({TASKS[name][0]}), varied "
                  f"{', '.join(d[0] for d in space.dims)}; objectives "
                  f"{', '.join(space.objectives)}")
            t0, l0 = time.perf_counter(), load()
            dense, stats = dense_sweep(two, task, space, args.dense, args.cache, name)
            Fd = objectives_and_violation(space, dense)[0]
            ok = np.isfinite(Fd).all(axis=1)
            front = Fd[ok][pareto_mask(Fd[ok])]
            ideal, nadir = front.min(axis=0), front.max(axis=0)
            ref = hypervolume(front, ideal, nadir)
            print(f"dense Sobol sweep: {args.dense} designs, {ok.sum()} feasible, "
                  f"{len(front)} on the front, hypervolume {ref:.4f}"
                  + (f" ({time.perf_counter() - t0:.0f} s on 2 workers, {l0})"
                     if stats else " (cached)"))
            sobol = hypervolume_curve(Fd, ideal=ideal, nadir=nadir, at=checkpoints)
            curves = {}
            runs = {}
            for seed in range(args.seeds):
                st = SearchSettings("nsga2", POPULATION, budget, seed, batch=CHUNK)
                t0, l0 = time.perf_counter(), load()
                rows, ran = search(two, task, space, st)
                runs[seed] = (rows, time.perf_counter() - t0, l0, load())
                F = objectives_and_violation(space, rows)[0]
                curves[seed] = hypervolume_curve(F, ideal=ideal, nadir=nadir, at=checkpoints)
            print(f"hypervolume / reference against designs evaluated (search: nsga2, "
                  f"population {POPULATION}, batches of {CHUNK}, {args.seeds} seeds)")
            print(f"  {'designs':>8} {'% dense':>8} {'sobol':>8} {'search min':>11} "
                  f"{'search max':>11}")
            for c in checkpoints:
                vals = [curves[s].at(c) / ref for s in curves]
                print(f"  {c:>8d} {100 * c / args.dense:>7.1f}% {sobol.at(c) / ref:>8.3f} "
                      f"{min(vals):>11.3f} {max(vals):>11.3f}")
            if not curves:
                print("  (no seed searched: --seeds 0)")
            worst = min((curves[s].at(budget) / ref for s in curves), default=float("nan"))
            print(f"  search at {budget} designs ({100 * budget / args.dense:.0f} % of the "
                  f"dense sweep): worst seed {worst:.3f} of the reference (floor 0.95: "
                  f"{'met' if worst >= 0.95 else 'NOT met'}); the sweep at as many: "
                  f"{sobol.at(budget) / ref:.3f}")
            feas = [np.mean([r["feasible"] for r in runs[s][0]]) for s in runs] or [np.nan]
            uniq = [len(np.unique([[r[k] for k in ("l1", "l2", "L1", "L2", "d")]
                                   for r in runs[s][0]], axis=0)) for s in runs] or [0]
            print(f"  search: feasible share {min(feas):.2f}-{max(feas):.2f} "
                  f"(dense sweep {ok.mean():.2f}); distinct designs {min(uniq)}-{max(uniq)} "
                  f"of {budget}")
            if args.no_speed:
                continue
            st = SearchSettings("nsga2", POPULATION, budget, 0, batch=CHUNK)
            gen = SearchSettings("nsga2", POPULATION, budget, 0, batch=POPULATION, lag=1,
                                 chunk=CHUNK)
            timing = {}
            with Cluster(workers=1) as one:
                run_sweep(one, task, space.designs()[:4], range(4), chunk=4,
                          on_chunk=lambda rows: None)  # the worker warm
                t0, l0 = time.perf_counter(), load()
                rows1, _ = search(one, task, space, st)
                timing["1"] = (time.perf_counter() - t0, l0, load())
            t0, l0 = time.perf_counter(), load()
            rows2, ran2 = search(two, task, space, st)
            timing["2"] = (time.perf_counter() - t0, l0, load())
            assert rows1 == rows2, "the designs differ between 1 and 2 workers"
            t0, l0 = time.perf_counter(), load()
            rowsg, _ = search(two, task, space, gen)
            timing["gen"] = (time.perf_counter() - t0, l0, load())
            Fg = objectives_and_violation(space, rowsg)[0]
            hv_gen = hypervolume_curve(Fg, ideal=ideal, nadir=nadir, at=[budget]).at(budget)
            r1, r2 = budget / timing["1"][0], budget / timing["2"][0]
            print(f"speed on Dask (seed 0, {budget} designs; the same designs at 1 and 2 "
                  "workers):")
            print(f"  1 worker:  {r1:.1f} designs/s ({timing['1'][1]} -> {timing['1'][2]})")
            print(f"  2 workers: {r2:.1f} designs/s ({timing['2'][1]} -> {timing['2'][2]}); "
                  f"efficiency {r2 / (2 * r1):.2f} (floor 0.8); the algorithm (pymoo, in "
                  f"this process) {ran2.algorithm_s:.2f} s of {timing['2'][0]:.1f} s")
            print(f"  generational (batches of {POPULATION} in chunks of {CHUNK}, one batch in "
                  "flight): "
                  f"{budget / timing['gen'][0]:.1f} designs/s on 2 workers "
                  f"({timing['gen'][1]} -> {timing['gen'][2]}), hypervolume "
                  f"{hv_gen / ref:.3f} of the reference (steady-state, seed 0: "
                  f"{hypervolume_curve(objectives_and_violation(space, rows2)[0], ideal=ideal, nadir=nadir, at=[budget]).at(budget) / ref:.3f})")


if __name__ == "__main__":
    main()
