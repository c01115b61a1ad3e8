"""Importing dextar is light and leaves no state behind (benchmarks/bench_import.py times it)."""

import ast
import os
import subprocess
import sys

import pytest


def _backend_after(code: str, mplbackend: str | None = None) -> list[str]:
    """What ``code`` prints in a fresh interpreter, then matplotlib's backend setting ("auto"
    while nothing has chosen one: matplotlib picks one at the first figure shown), with the
    environment's MPLBACKEND replaced by ``mplbackend``. (``rcParams._get`` reads the setting
    without resolving it: ``get_backend()`` would choose "agg" on a machine without a
    display, whoever asked.)"""
    probe = (f"{code}; import matplotlib; b = matplotlib.rcParams._get('backend'); "
             "print('auto' if b is matplotlib.rcsetup._auto_backend_sentinel else b)")
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    if mplbackend is not None:
        env["MPLBACKEND"] = mplbackend
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                       check=True, env=env)
    return r.stdout.splitlines()


@pytest.mark.slow
def test_import_loads_no_plotting_or_solvers_and_sets_no_backend():
    # the figures' module draws on its own canvas: the backend stays the user's to choose
    code = ("import sys, dextar; "
            "print(sorted(m for m in ('matplotlib.pyplot', 'scipy') if m in sys.modules)); "
            "import dextar.output.figures")
    mods, backend = _backend_after(code)
    assert mods == "[]"
    assert [backend] == _backend_after("pass")           # matplotlib's own default
    assert _backend_after(code, "svg") == ["[]", "svg"]  # the user's MPLBACKEND stands


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


_FORKS = """
import ast, os, sys
{prefix}
for code in ast.literal_eval(sys.argv[1]):
    sys.stdout.flush()
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # a copy of this interpreter as the prefix left it: run one probe's rest
        os.close(r)
        try:
            exec(code)
            sys.stdout.flush()
            found = repr({heavy})
        except BaseException as exc:  # noqa: BLE001 - said to the test, which then fails
            found = "error: " + repr(exc)
        os.write(w, found.encode())
        os._exit(0)
    os.close(w)
    with os.fdopen(r) as fh:
        found = fh.read()
    os.waitpid(pid, 0)
    print("found:", found)
"""


def _loaded_after(prefix: str, codes: list[str]) -> list[list[str]]:
    """``_loaded(prefix + "; " + code)`` for each code, in one fresh interpreter that runs
    ``prefix`` once and then each code in a process forked from it: a fork is an exact copy
    of the interpreter the prefix left (its modules, nothing else), so each code starts as
    it would in a fresh interpreter after ``prefix``, without paying for ``prefix`` again
    (``import dextar.cli``: 0.35 s of CPU a probe). Without fork, one interpreter each."""
    if not hasattr(os, "fork"):
        return [_loaded(f"{prefix}; {code}") for code in codes]
    heavy = ("sorted({m.split('.')[0] if not m.startswith('dextar') else m for m in sys.modules "
             "if m.split('.')[0] in ('scipy', 'matplotlib', 'PIL') or m in ('dextar.laws', "
             "'dextar.analysis', 'dextar.program', 'dextar.trajectory', "
             "'dextar.output.figures')})")
    r = subprocess.run([sys.executable, "-c", _FORKS.format(prefix=prefix, heavy=heavy),
                        repr(codes)], capture_output=True, text=True, check=True)
    found = [x[len("found: "):] for x in r.stdout.splitlines() if x.startswith("found: ")]
    assert len(found) == len(codes), r.stdout
    return [ast.literal_eval(x) for x in found]  # (an "error: ..." fails here, named)


@pytest.mark.slow
def test_the_command_line_and_its_parser_load_no_scipy_matplotlib_or_stages():
    # dextar --help lists the commands without importing their modules; a command's own
    # --help imports its module alone, whose job and writers load when it runs
    # (dextar._lazy; start-up time: benchmarks/bench_start.py)
    assert _loaded("import dextar.cli") == []
    # each probe below in a fresh interpreter after `import dextar.cli` (forked: _loaded_after)
    light = ("ik", "fk", "calibrate", "poses", "identify")
    registries = ("plan", "torques", "simulate", "export", "run", "program", "design",
                  "excite", "workspace")
    codes = ["dextar.cli.build_parser('')", "dextar.cli.main(['--help'])",
             *(f"dextar.cli.main([{name!r}, '--help'])" for name in (*light, *registries))]
    found = dict(zip(["parser", "--help", *light, *registries],
                     _loaded_after("import dextar.cli", codes), strict=True))
    assert found["parser"] == [] and found["--help"] == []
    for name in light:
        assert found[name] == [], name
    # plan, torques, export, program, design and run list the registered laws and paths: the
    # registries load, not the solvers or the plotting behind them
    for name in registries:
        loaded = set(found[name])
        assert not {"scipy", "matplotlib", "PIL", "dextar.analysis"} & loaded, (name, loaded)
    # the check can fail: a whole scenario loads the laws
    assert "dextar.laws" in _loaded("from dextar.config import load_scenario; "
                                    "load_scenario(None)")


@pytest.mark.slow
def test_reading_a_robot_table_loads_no_scipy_and_no_stage_above_the_config():
    # dextar ik / fk / workspace read [robot] only; a scenario's run objects import their
    # stages when they are built
    assert _loaded("from dextar.config import load_robot_table; load_robot_table(None)") == []
    # (the probe sees a stage when one loads: a whole scenario builds its law)
    assert "dextar.laws" in _loaded("from dextar.config import load_scenario; load_scenario(None)")
