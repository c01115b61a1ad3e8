"""Planning the pick-and-place example (moves, setpoints, sizing; no figures), best of 5
(floor: under 1 s), and `dextar program` end to end as a user runs it.

Run: python benchmarks/bench_program.py
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from dextar import jobs

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pick_place.toml"


def main() -> None:
    best = float("inf")
    for _ in range(5):
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            res = jobs.program(str(EXAMPLE), str(Path(tmp) / "out"))
            best = min(best, time.perf_counter() - t0)
    print(f"pick_place: planned and written in {best * 1e3:.0f} ms (floor 1 s for the plan); "
          f"cycle time {res.payload['cycle_time_s']:.4f} s, {res.payload['status']}")
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "dextar", "program", str(EXAMPLE), "--out",
                        str(Path(tmp) / "out"), "--quiet"], check=True)
        print(f"dextar program (a new process, imports included): "
              f"{time.perf_counter() - t0:.2f} s (floor 5 s)")


if __name__ == "__main__":
    main()
