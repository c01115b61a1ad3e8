"""Planning the pick-and-place example (moves, setpoints, sizing; no figures), best of 5
(floor: under 1 s), and `dextar program` end to end as a user runs it.

Run: python benchmarks/bench_program.py
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from dextar.commands import program

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pick_place.toml"


def timed(figures: bool) -> tuple[float, object]:
    best, res = float("inf"), None
    for _ in range(3):
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            args = argparse.Namespace(config=str(EXAMPLE), out=str(Path(tmp) / "out"),
                                      force=False, quiet=True, json=False)
            res = program.run(args, figures=figures)
            best = min(best, time.perf_counter() - t0)
    return best, res


def main() -> None:
    t_plan, res = timed(False)
    t_all, _ = timed(True)
    print(f"pick_place: planned (moves, setpoints, sizing) in {t_plan * 1e3:.0f} ms (floor 1 s); "
          f"with figures, SVGs and the report in {t_all:.2f} s (floor 5 s); cycle time "
          f"{res.payload['cycle_time_s']:.4f} s, {res.payload['status']}")  # type: ignore[union-attr]
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "dextar", "program", str(EXAMPLE), "--out",
                        str(Path(tmp) / "out"), "--quiet"], check=True)
        print(f"dextar program (a new process, imports included): "
              f"{time.perf_counter() - t0:.2f} s (floor 5 s)")


if __name__ == "__main__":
    main()
