"""How fast the command line starts, each figure a whole new process (best of N, the median
and the worst shown), beside the interpreter's own start and ``import numpy`` (floor: every
command's start under 0.25 s).

Run: python benchmarks/bench_start.py [--runs N] [--importtime]

* ``dextar --help`` and ``dextar CMD --help`` for every command;
* start: from the process's start until the command's ``run`` is entered (parsing done,
  nothing computed yet: the wrapper stops there);
* ``dextar ik`` and ``dextar fk``, whole: the kinematics commands' answer is their first line.

Python's bytecode cache is used as after an install (``PYTHONDONTWRITEBYTECODE`` is removed
from the children's environment and a first run writes the cache). ``--importtime`` prints
``python -X importtime``'s largest entries (cumulative) for ``dextar --help``,
``dextar run --help`` and ``dextar ik``.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import time

from dextar.commands import COMMANDS

FLOOR = 0.25
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
#: Stops a command where its run starts: the time to get there is the command's start.
START = ("import sys; from dextar import cli; from dextar.commands import {mod} as m; "
         "m.run = lambda args: sys.exit(0); sys.exit(cli.main({argv!r}))")
#: The arguments that make each command parse (files need not exist: run is not entered).
ARGS = {"ik": ["0", "120"], "fk": ["60", "120"], "workspace": ["--out", "w.png"],
        "plan": ["--out", "p.csv"], "torques": ["--out", "t.csv"], "simulate": ["--out", "s"],
        "export": ["mjcf", "--out", "m.xml"], "program": ["task.toml", "--out", "p"],
        "excite": ["task.toml", "--out", "e.csv"],
        "identify": ["e.csv", "--config", "task.toml", "--out", "i"],
        "design": ["task.toml", "--out", "d"], "poses": ["task.toml", "--count", "20", "--out", "poses.csv"],
        "calibrate": ["poses.csv", "--config", "task.toml", "--out", "c"], "run": []}


def timed(argv: list[str], runs: int) -> list[float]:
    """Wall times of ``argv`` as a new process, ``runs`` times (after one untimed run)."""
    out = []
    for k in range(runs + 1):
        t0 = time.perf_counter()
        r = subprocess.run(argv, capture_output=True, env=ENV)
        dt = time.perf_counter() - t0
        if r.returncode != 0:
            raise SystemExit(f"{' '.join(argv)} failed: {r.stderr.decode()[-500:]}")
        if k:
            out.append(dt)
    return out


def line(label: str, t: list[float], floor: float | None = FLOOR) -> str:
    s = sorted(t)
    verdict = "" if floor is None else ("  ok" if s[0] < floor else "  OVER")
    return (f"  {label:<34} best {s[0] * 1e3:6.0f}  median {s[len(s) // 2] * 1e3:6.0f}  worst "
            f"{s[-1] * 1e3:6.0f} ms{verdict}")


def importtime(argv: list[str], top: int = 8) -> str:
    r = subprocess.run([sys.executable, "-X", "importtime", *argv], capture_output=True,
                       text=True, env=ENV)
    rows = []
    for ln in r.stderr.splitlines():
        m = re.match(r"import time:\s+\d+ \|\s+(\d+) \|(\s*)(\S+)", ln)
        if m:
            rows.append((int(m.group(1)), len(m.group(2)), m.group(3)))
    # the largest entries, outermost first among equals: what brings the weight in
    rows.sort(key=lambda r: (-r[0], r[1]))
    return "\n".join(f"    {us / 1e3:7.1f} ms  {name}" for us, _, name in rows[:top])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--importtime", action="store_true")
    args = ap.parse_args()
    py, n = sys.executable, args.runs
    print(f"floor: {FLOOR:.2f} s a command; {n} runs each, whole processes")
    print(line("python -c pass (the interpreter)", timed([py, "-c", "pass"], n), None))
    print(line("python -c 'import numpy'", timed([py, "-c", "import numpy"], n), None))
    print(line("dextar --help", timed([py, "-m", "dextar", "--help"], n)))
    for name in COMMANDS:
        print(line(f"dextar {name} --help", timed([py, "-m", "dextar", name, "--help"], n)))
    for name in COMMANDS:
        code = START.format(mod=name, argv=[name, *ARGS[name]])
        print(line(f"dextar {name}: start (to run)", timed([py, "-c", code], n)))
    print(line("dextar ik 0 120 (whole)", timed([py, "-m", "dextar", "ik", "0", "120"], n)))
    print(line("dextar fk 60 120 (whole)", timed([py, "-m", "dextar", "fk", "60", "120"], n)))
    if args.importtime:
        for argv in (["--help"], ["run", "--help"], ["ik", "0", "120"]):
            print(f"  python -X importtime -m dextar {' '.join(argv)}: largest (cumulative)")
            print(importtime(["-m", "dextar", *argv]))


if __name__ == "__main__":
    main()
