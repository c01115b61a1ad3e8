"""Importing dextar is light and leaves no state behind (benchmarks/bench_import.py times it)."""

import ast
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


def _loaded(code: str) -> list[str]:
    """The heavy modules (scipy, matplotlib, PIL and dextar's stages that bring them) that
    ``code`` leaves imported, in a fresh interpreter."""
    probe = (f"import sys; {code}; print(sorted({{m.split('.')[0] if not m.startswith('dextar') "
             "else m for m in sys.modules if m.split('.')[0] in ('scipy', 'matplotlib', 'PIL') "
             "or m in ('dextar.laws', 'dextar.analysis', 'dextar.program', 'dextar.trajectory', "
             "'dextar.output.figures')}))")
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return ast.literal_eval(r.stdout.splitlines()[-1])  # (after what code printed)


def test_the_command_line_and_its_parser_load_no_scipy_matplotlib_or_stages():
    # dextar --help lists the commands without importing their modules; a command's own
    # --help imports its module alone, whose job and writers load when it runs
    # (dextar._lazy; start-up time: benchmarks/bench_start.py)
    assert _loaded("import dextar.cli") == []
    assert _loaded("import dextar.cli; dextar.cli.build_parser('')") == []
    assert _loaded("import dextar.cli; dextar.cli.main(['--help'])") == []
    for name in ("ik", "fk", "calibrate", "poses", "program", "identify", "design"):
        assert _loaded(f"import dextar.cli; dextar.cli.main([{name!r}, '--help'])") == [], name
    # plan, torques, export and run list the registered laws and paths: the registries load,
    # not the solvers or the plotting behind them
    for name in ("plan", "torques", "simulate", "export", "run", "excite", "workspace"):
        loaded = set(_loaded(f"import dextar.cli; dextar.cli.main([{name!r}, '--help'])"))
        assert not {"scipy", "matplotlib", "PIL", "dextar.analysis"} & loaded, (name, loaded)
    # the check can fail: a whole scenario loads the laws
    assert "dextar.laws" in _loaded("from dextar.config import load_scenario; "
                                    "load_scenario(None)")


def test_reading_a_robot_table_loads_no_scipy_and_no_stage_above_the_config():
    # dextar ik / fk / workspace read [robot] only; a scenario's run objects import their
    # stages when they are built
    assert _loaded("from dextar.config import load_robot_table; load_robot_table(None)") == []
    # (the probe sees a stage when one loads: a whole scenario builds its law)
    assert "dextar.laws" in _loaded("from dextar.config import load_scenario; load_scenario(None)")
