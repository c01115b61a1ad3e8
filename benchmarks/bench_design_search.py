"""The adaptive design search (``[design] search = "nsga2"``) against the Sobol sweep, on two
tasks, printed as tables:

* a ``dextar program`` task: the pick-and-place (examples/pick_place.toml: time-optimal
  moves, blends, dwells), l, L and d varied, objectives cycle time, footprint and distance
  to parallel singularities (maximised);
* a ``dextar run`` config: examples/line_si.toml (a line under a min-jerk law, motors of
  1 N m), l1, l2, L1, L2 and d varied, objectives peak torque of motor A, footprint and
  dexterity (maximised).

For each: a dense Sobol sweep (4096 designs for the program, 8192 for the run config, or
``--dense``) gives the reference front; the hypervolume of the front found (objectives scaled
between the reference front's ideal and nadir points, reference point 1.1) is printed
against the designs evaluated, for the Sobol sweep (the first n designs of the dense one)
and for each search (``--kinds``, default nsga2 and smsemoa, steady-state, ``--seeds`` seeds:
the worst and the best), as a fraction of the reference's. The issue's floor: the search
reaches 0.95 of the reference with at most 10 % of the dense sweep's evaluations, at its
worst seed.

Then, for each search in ``--speed-kinds``, the two schemes: steady-state (batches of
``chunk`` designs, a generation's worth in flight, each told as it is back in proposal
order) and generational (a batch of a whole population in chunks, one batch in flight: the
workers wait on each generation's slowest chunk): designs per second at 1 and 2 workers
(the same designs at both: asserted), ``--repeats`` repeats interleaved, the parallel
efficiency per repeat (floor 0.8 at 2 workers), the hypervolume of each scheme at the same
evaluations over the seeds, and the share of the wall time pymoo takes in the driving
process. The load average is printed (the machine may be shared).

Run: python benchmarks/bench_design_search.py [--task program|run] [--population 20]
[--seeds 5] [--repeats 3] [--cache DIR] [--no-speed]
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
POPULATION = 20  # the shipped default ([design].population)
CHUNK = 4
DENSE = {"program": 4096, "run": 8192}


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


SCHEMES = ("steady-state", "generational")


def settings(kind: str, scheme: str, budget: int, seed: int) -> SearchSettings:
    """A search of ``kind`` in ``scheme``: steady-state (batches of ``CHUNK``, a generation's
    worth in flight) or generational (a batch of a whole population in chunks of ``CHUNK``,
    one batch in flight)."""
    if scheme == "generational":
        return SearchSettings(kind, POPULATION, budget, seed, batch=POPULATION, lag=1,
                              chunk=CHUNK)
    return SearchSettings(kind, POPULATION, budget, seed, batch=CHUNK)


def final_hv(space, rows, ideal, nadir, at: int) -> float:
    F = objectives_and_violation(space, rows)[0]
    return hypervolume_curve(F, ideal=ideal, nadir=nadir, at=[at]).at(at)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--dense", type=int, default=None,
                    help="designs of the dense sweep (default 4096 for the program task, "
                         "8192 for the run config)")
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--kinds", default="nsga2,smsemoa",
                    help="searches compared (steady-state, the shipped scheme)")
    ap.add_argument("--task", choices=[*TASKS, "both"], default="both")
    ap.add_argument("--cache", type=Path, default=None,
                    help="keep the dense sweeps here (reruns skip them)")
    ap.add_argument("--repeats", type=int, default=3, help="repeats of each timing")
    ap.add_argument("--speed-kinds", default="smsemoa", help="the searches timed")
    ap.add_argument("--no-speed", action="store_true", help="skip the 1/2 worker timings")
    ap.add_argument("--population", type=int, default=POPULATION)
    args = ap.parse_args()
    globals()["POPULATION"] = args.population
    sys.path.insert(0, str(EXAMPLES.parent))
    kinds = args.kinds.split(",")
    with tempfile.TemporaryDirectory() as tmp, Cluster(workers=2) as two:
        for name in (TASKS if args.task == "both" else [args.task]):
            n_dense = args.dense or DENSE[name]
            budget = n_dense // 10
            checkpoints = sorted({POPULATION, budget // 4, budget // 2, 3 * budget // 4,
                                  budget})
            task, space = load_scenario(task_file(Path(tmp), name)).design_task()
            run_sweep(two, task, space.designs()[:8], range(8), chunk=4,
                      on_chunk=lambda rows: None)  # workers warm
            print(f"\n== {name} task ({TASKS[name][0]}), varied "
                  f"{', '.join(d[0] for d in space.dims)}; objectives "
                  f"{', '.join(space.objectives)}")
            t0, l0 = time.perf_counter(), load()
            dense, stats = dense_sweep(two, task, space, n_dense, args.cache, name)
            Fd = objectives_and_violation(space, dense)[0]
            ok = np.isfinite(Fd).all(axis=1)
            front = Fd[ok][pareto_mask(Fd[ok])]
            ideal, nadir = front.min(axis=0), front.max(axis=0)
            ref = hypervolume(front, ideal, nadir)
            print(f"dense Sobol sweep: {n_dense} designs, {ok.sum()} feasible, "
                  f"{len(front)} on the front, hypervolume {ref:.4f}"
                  + (f" ({time.perf_counter() - t0:.0f} s on 2 workers, {l0})"
                     if stats else " (cached)"))
            sobol = hypervolume_curve(Fd, ideal=ideal, nadir=nadir, at=checkpoints)
            curves: dict = {k: {} for k in kinds}
            runs: dict = {k: {} for k in kinds}
            for kind in kinds:
                for seed in range(args.seeds):
                    rows, _ = search(two, task, space, settings(kind, "steady-state", budget,
                                                                 seed))
                    runs[kind][seed] = rows
                    F = objectives_and_violation(space, rows)[0]
                    curves[kind][seed] = hypervolume_curve(F, ideal=ideal, nadir=nadir,
                                                           at=checkpoints)
            print(f"hypervolume / reference against designs evaluated (population "
                  f"{POPULATION}, steady-state batches of {CHUNK}; {args.seeds} seeds: "
                  "worst-best)")
            print(f"  {'designs':>8} {'% dense':>8} {'sobol':>8} "
                  + " ".join(f"{k:>13}" for k in kinds))
            for c in checkpoints:
                cells = []
                for k in kinds:
                    vals = [curves[k][s].at(c) / ref for s in curves[k]] or [np.nan]
                    cells.append(f"{min(vals):.3f}-{max(vals):.3f}")
                print(f"  {c:>8d} {100 * c / n_dense:>7.1f}% {sobol.at(c) / ref:>8.3f} "
                      + " ".join(f"{x:>13}" for x in cells))
            for k in kinds:
                worst = min((curves[k][s].at(budget) / ref for s in curves[k]),
                            default=float("nan"))
                feas = [np.mean([r["feasible"] for r in runs[k][s]]) for s in runs[k]]
                print(f"  {k} at {budget} designs ({100 * budget / n_dense:.0f} % of the "
                      f"dense sweep): worst of {args.seeds} seeds {worst:.3f} of the "
                      f"reference (floor 0.95: {'met' if worst >= 0.95 else 'NOT met'}); "
                      f"feasible share {min(feas, default=np.nan):.2f}-"
                      f"{max(feas, default=np.nan):.2f} (dense sweep {ok.mean():.2f})")
            print(f"  the Sobol sweep at {budget} designs: {sobol.at(budget) / ref:.3f}")
            if args.no_speed:
                continue
            for kind in args.speed_kinds.split(","):
                speed(args, kind, task, space, two, budget, ideal, nadir, ref, runs)


def speed(args, kind, task, space, two, budget, ideal, nadir, ref, runs) -> None:
    """Designs per second at 1 and 2 workers, steady-state and generational, ``--repeats``
    times interleaved (the load of a shared machine drifts); the hypervolume of each scheme
    at the same evaluations over the seeds."""
    hv = {"steady-state": [final_hv(space, runs[kind][s], ideal, nadir, budget) / ref
                           for s in runs.get(kind, {})]}
    hv["generational"] = [final_hv(space, search(two, task, space, settings(
        kind, "generational", budget, s))[0], ideal, nadir, budget) / ref
        for s in range(args.seeds)]
    rate: dict = {}
    algo: dict = {}
    loads = []
    with Cluster(workers=1) as one:
        run_sweep(one, task, space.designs()[:4], range(4), chunk=4,
                  on_chunk=lambda rows: None)  # the worker warm
        same: dict = {}
        for _ in range(args.repeats):
            for scheme in SCHEMES:
                for workers, cluster in ((1, one), (2, two)):
                    loads.append(os.getloadavg()[0])
                    t0 = time.perf_counter()
                    rows, ran = search(cluster, task, space, settings(kind, scheme, budget, 0))
                    dt = time.perf_counter() - t0
                    loads.append(os.getloadavg()[0])
                    rate.setdefault((scheme, workers), []).append(budget / dt)
                    algo.setdefault(scheme, []).append(ran.algorithm_s / dt)
                    assert same.setdefault(scheme, rows) == rows, \
                        "the designs differ between runs or workers"
    print(f"speed on Dask ({kind}, seed 0, {budget} designs; the same designs at 1 and 2 "
          f"workers; {args.repeats} repeats interleaved, load average "
          f"{min(loads):.1f}-{max(loads):.1f} on {os.cpu_count()} cores):")
    print(f"  {'scheme':<14} {'1 worker':>15} {'2 workers':>15} {'efficiency':>17} "
          f"{'hypervolume':>13} {'pymoo':>6}")
    for scheme in SCHEMES:
        r1, r2 = rate[(scheme, 1)], rate[(scheme, 2)]
        eff = [b / (2 * a) for a, b in zip(r1, r2, strict=True)]
        h = hv[scheme] or [np.nan]
        print(f"  {scheme:<14} {np.median(r1):6.1f} ({min(r1):.1f}-{max(r1):.1f}) "
              f"{np.median(r2):6.1f} ({min(r2):.1f}-{max(r2):.1f}) "
              f"{np.median(eff):5.2f} ({min(eff):.2f}-{max(eff):.2f}) "
              f"{min(h):.3f}-{max(h):.3f} {100 * np.median(algo[scheme]):5.1f}%")
    print("  (designs/s: median (min-max) of the repeats; efficiency: designs/s at 2 workers "
          "over twice those at 1, per repeat, floor 0.8; hypervolume / reference at "
          f"{budget} designs over {len(hv['generational'])} seeds, worst-best; pymoo: the "
          "median share of the wall time spent proposing and telling in this process)")


if __name__ == "__main__":
    main()
