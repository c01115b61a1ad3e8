"""The long robustness run: random configs and command lines through the real command line.

Run: python benchmarks/fuzz.py --cases 10000 [--seed 0]

Each case is classified by ``tests/robustness/harness.py``: ``ok`` (exit 0, finite outputs),
``exceeds`` (a program planned beyond its motors: exit 1, its files written), ``refused``
(exit 2, one line on stderr) or a defect (traceback, nan, hang, partial,
bad-exit). Prints the counts, the slowest case and the first few defects; exits 1 if there
is any defect.
"""

from __future__ import annotations

import argparse
import collections
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from tests.robustness.harness import (  # noqa: E402
    DEFECTS,
    run_argv_case,
    run_config_case,
    run_identify_case,
    run_program_case,
    run_robot_config_case,
    run_run_case,
    toml_text,
)
from tests.robustness.strategies import (  # noqa: E402
    COMMANDS,
    configs,
    counterweight_configs,
    dry_friction_runs,
    falling_simulations,
    kinematics_argv,
    long_animated_runs,
    metre_configs,
    motion_files,
    programs,
    time_scaled_motion_files,
)

PICK_PLACE = ROOT / "examples" / "pick_place.toml"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    counts: collections.Counter[str] = collections.Counter()
    defects: list[str] = []
    slowest = (0.0, "")
    t_start = time.perf_counter()

    def record(outcome: str, detail: str, label: str, dt: float) -> None:
        nonlocal slowest
        counts[outcome] += 1
        if outcome in DEFECTS:
            print(f"DEFECT {outcome}: {detail}\n    {label}", file=sys.stderr, flush=True)
            if len(defects) < 20:
                defects.append(f"{outcome}: {detail}\n    {label}")
        if dt > slowest[0]:
            slowest = (dt, label)
        done = sum(counts.values())
        if done % 500 == 0:
            print(f"  {done} cases, {dict(counts)}", file=sys.stderr, flush=True)

    n_prog = int(args.cases * 0.1)
    n_id = int(args.cases * 0.05)
    # issue 28's shapes: metre-sized lengths, falling simulations, long runs with dry friction
    n_metres = int(args.cases * 0.03)
    n_falling = int(args.cases * 0.03)
    n_dry = int(args.cases * 0.01)
    n_long = int(args.cases * 0.01)  # review 28: long motions with the animation drawn
    n_time = int(args.cases * 0.02)  # issue 28's time scales
    n_cw = int(args.cases * 0.02)  # issue 32: counterweights on the proximal rods
    n_cfg = (int(args.cases * 0.65) - n_metres - n_falling - n_dry - n_long - n_time
             - n_cw)

    @settings(max_examples=n_cfg, deadline=None, database=None, derandomize=False,
              suppress_health_check=list(HealthCheck))
    @given(doc=configs(), command=COMMANDS)
    def fuzz_configs(doc: dict, command: str) -> None:
        t0 = time.perf_counter()
        outcome, detail = run_config_case(doc, command)
        record(outcome, detail, f"{command} with\n{toml_text(doc)}", time.perf_counter() - t0)

    @settings(max_examples=n_prog, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(doc=programs())
    def fuzz_programs(doc: dict) -> None:
        t0 = time.perf_counter()
        outcome, detail = run_program_case(doc)
        record(outcome, detail, f"program with\n{toml_text(doc)}", time.perf_counter() - t0)

    @settings(max_examples=n_id, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(case=motion_files(), config=st.sampled_from([None, str(PICK_PLACE)]))
    def fuzz_identify(case: tuple[str, list[str]], config: str | None) -> None:
        t0 = time.perf_counter()
        outcome, detail = run_identify_case(case[0], case[1], config)
        record(outcome, detail, f"identify {case[1]} config {config} on\n{case[0][:300]}",
               time.perf_counter() - t0)

    @settings(max_examples=args.cases - n_cfg - n_prog - n_id, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(argv=kinematics_argv())
    def fuzz_argv(argv: list[str]) -> None:
        t0 = time.perf_counter()
        outcome, detail = run_argv_case(argv)
        record(outcome, detail, " ".join(argv), time.perf_counter() - t0)

    @settings(max_examples=n_metres, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(doc=metre_configs(),
           command=st.sampled_from(["plan", "torques", "simulate", "export", "ik", "fk",
                                    "workspace", "poses", "excite"]))
    def fuzz_metres(doc: dict, command: str) -> None:
        t0 = time.perf_counter()
        if command in ("ik", "fk", "workspace", "poses", "excite"):
            outcome, detail = run_robot_config_case(doc, command)
        else:
            outcome, detail = run_config_case(doc, command)
        record(outcome, detail, f"{command} with\n{toml_text(doc)}", time.perf_counter() - t0)

    @settings(max_examples=n_falling, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(doc=falling_simulations())
    def fuzz_falling(doc: dict) -> None:
        t0 = time.perf_counter()
        outcome, detail = run_config_case(doc, "simulate")
        record(outcome, detail, f"simulate with\n{toml_text(doc)}", time.perf_counter() - t0)

    @settings(max_examples=n_dry, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(doc=dry_friction_runs())
    def fuzz_dry_runs(doc: dict) -> None:
        t0 = time.perf_counter()
        outcome, detail = run_run_case(doc)
        record(outcome, detail, f"run with\n{toml_text(doc)}", time.perf_counter() - t0)

    @settings(max_examples=n_long, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(doc=long_animated_runs())
    def fuzz_long_runs(doc: dict) -> None:
        t0 = time.perf_counter()
        outcome, detail = run_run_case(doc)
        record(outcome, detail, f"run with\n{toml_text(doc)}", time.perf_counter() - t0)

    @settings(max_examples=n_time, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(case=time_scaled_motion_files(), config=st.sampled_from([None, str(PICK_PLACE)]))
    def fuzz_time_scales(case: tuple[str, list[str], float], config: str | None) -> None:
        text, options, factor = case
        t0 = time.perf_counter()
        outcome, detail = run_identify_case(text, options, config)
        unit = {1e3: "milliseconds", 1e6: "microseconds"}.get(factor)
        if unit is not None and outcome not in DEFECTS and (
                outcome != "refused" or f"Is the time in {unit}?" not in detail):
            outcome, detail = "bad-exit", f"time in {unit} not named: {outcome}: {detail}"
        record(outcome, detail, f"identify {options} config {config}, t_s x {factor:g}, on\n"
               f"{text[:300]}", time.perf_counter() - t0)

    @settings(max_examples=n_cw, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(doc=counterweight_configs(),
           command=st.sampled_from(["torques", "simulate", "export", "plan"]))
    def fuzz_counterweights(doc: dict, command: str) -> None:
        t0 = time.perf_counter()
        outcome, detail = run_config_case(doc, command)
        record(outcome, detail, f"{command} with\n{toml_text(doc)}", time.perf_counter() - t0)

    import random

    random.seed(args.seed)
    st.random_module()
    fuzz_programs()
    fuzz_identify()
    fuzz_configs()
    fuzz_metres()
    fuzz_falling()
    fuzz_dry_runs()
    fuzz_long_runs()
    fuzz_time_scales()
    fuzz_counterweights()
    fuzz_argv()
    total = sum(counts.values())
    print(f"{total} cases in {time.perf_counter() - t_start:.0f} s: " + ", ".join(
        f"{k} {counts.get(k, 0)}" for k in ("ok", "exceeds", "refused", *DEFECTS)))
    print(f"tracebacks {counts.get('traceback', 0)}, NaN outputs {counts.get('nan', 0)}, "
          f"hangs {counts.get('hang', 0)}, partial files {counts.get('partial', 0)}")
    print(f"slowest case {slowest[0]:.2f} s: {slowest[1][:300]}")
    for d in defects:
        print(d)
    return 1 if any(counts.get(k, 0) for k in DEFECTS) else 0


if __name__ == "__main__":
    raise SystemExit(main())
