"""Time of ``import dextar`` in a fresh interpreter (floor: under 0.3 s), best of 5.

Run: python benchmarks/bench_import.py
"""

from __future__ import annotations

import subprocess
import sys


def main() -> None:
    code = "import time; t = time.perf_counter(); import dextar; print(time.perf_counter() - t)"
    times = [float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                  check=True).stdout) for _ in range(5)]
    print(f"import dextar: best {min(times) * 1e3:.0f} ms, worst {max(times) * 1e3:.0f} ms "
          "(floor 300 ms)")


if __name__ == "__main__":
    main()
