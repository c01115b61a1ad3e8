"""Wall time of the main job, `dextar run` with no config, as a new user runs it
(floor: under 15 s on one core).

Run: python benchmarks/bench_run.py
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def main() -> None:
    times = []
    for _ in range(3):
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "out"
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "dextar", "run", "--out", str(out), "--quiet"],
                           check=True)
            times.append(time.perf_counter() - t0)
            steps = json.loads((out / "summary.json").read_text())["timing_s"]
    print(f"dextar run: best {min(times):.2f} s, worst {max(times):.2f} s over 3 runs "
          "(floor 15 s)")
    for name, sec in steps.items():
        print(f"  {name:<52} {sec:6.2f} s")


if __name__ == "__main__":
    main()
