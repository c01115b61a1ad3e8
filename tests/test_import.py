"""Importing dextar is light and leaves no state behind (benchmarks/bench_import.py times it)."""

import subprocess
import sys


def test_import_loads_no_plotting_or_solvers_and_sets_no_backend():
    code = ("import sys, dextar; import matplotlib; "
            "print(sorted(m for m in ('matplotlib.pyplot', 'scipy') if m in sys.modules)); "
            "print(matplotlib.get_backend() != 'agg' or 'MPLBACKEND' in __import__('os').environ)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    mods, _ = r.stdout.splitlines()
    assert mods == "[]"


def test_library_never_selects_a_matplotlib_backend():
    from pathlib import Path

    src = Path(__file__).resolve().parents[1] / "src" / "dextar"
    offenders = [p.name for p in src.rglob("*.py")
                 if "matplotlib.use(" in p.read_text() or "import matplotlib.pyplot" in p.read_text()]
    assert offenders == []
