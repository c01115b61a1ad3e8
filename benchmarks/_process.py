"""Whole-process timing for the benchmarks: new processes, interleaved with a reference of
fixed work, so that a figure can be read against the machine's speed at the time.

These machines are shared: the same process takes from 1x to 1.5x its best time from one
minute to the next. Each round runs the command, then the reference (a new interpreter
importing numpy and matplotlib's Figure and Agg canvas: about a quarter of dextar run's CPU
work, all of it Python), so that both meet the same machine; the rounds' ratios
command / reference are printed beside the times.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
REFERENCE = [sys.executable, "-c",
             "import numpy, matplotlib.figure, matplotlib.backends.backend_agg"]


def spread(t: list[float]) -> str:
    s = sorted(t)
    return f"best {s[0]:5.2f} s, median {s[len(s) // 2]:5.2f} s, worst {s[-1]:5.2f} s"


def timed_rounds(argv: Callable[[Path], list[str]], runs: int, cpus: set[int] | None = None
                 ) -> tuple[list[float], list[float], Path]:
    """``runs`` rounds (after an untimed one) of the command ``argv(out_dir)`` and of the
    reference, each a new process (pinned to ``cpus`` when given). Returns the command's
    wall times, the reference's and the last round's output folder (kept until the next
    call)."""
    def pin() -> None:
        if cpus is not None:
            os.sched_setaffinity(0, cpus)

    ours, ref = [], []
    keep = Path(tempfile.mkdtemp(prefix="dextar-bench-"))
    for k in range(runs + 1):
        out = keep / f"out{k}"
        t0 = time.perf_counter()
        subprocess.run(argv(out), check=True, env=ENV, preexec_fn=pin)
        t1 = time.perf_counter()
        subprocess.run(REFERENCE, check=True, env=ENV, preexec_fn=pin)
        t2 = time.perf_counter()
        if k:
            ours.append(t1 - t0)
            ref.append(t2 - t1)
    return ours, ref, keep / f"out{runs}"


def report(label: str, ours: list[float], ref: list[float], floor: float | None) -> str:
    ratio = sorted(a / b for a, b in zip(ours, ref, strict=True))
    verdict = "" if floor is None else (f" (floor {floor} s: "
                                        f"{'met' if min(ours) < floor else 'NOT met'})")
    return (f"{label}: {spread(ours)} over {len(ours)} runs{verdict}\n"
            f"  reference (import numpy and matplotlib, new process) in the same rounds: "
            f"{spread(ref)}; ratio best {ratio[0]:.2f}, median {ratio[len(ratio) // 2]:.2f}")
