"""The suite's order for the xdist workers: ``--dist loadfile`` (pyproject) sends whole files
to the workers in collection order (``--no-loadscope-reorder`` keeps that order), and
pytest-randomly shuffles it. The files go out by their share of tests marked ``slow``, the
largest first (a file of slow tests only, then one with some, the files without any last):
longest-processing-time scheduling with the lengths read from the marks, so that no long
file starts last while the other worker idles. Nothing here is kept by hand: marking a test
slow moves its file. Within a rank the random order stands."""

import sys
from collections import Counter
from pathlib import Path

import pytest

from .once import made_once


def _file(item: pytest.Item) -> str:
    return item.nodeid.split("::")[0]


def pytest_configure(config):
    """Where Python writes no bytecode (PYTHONDONTWRITEBYTECODE set, as on some CI machines),
    dextar's modules compiled once before the run: every xdist worker and every ``dextar``
    process a test starts (a few hundred) otherwise compiles them from source again (about
    0.1 s of CPU each; 250 -> 224 s of the suite's CPU measured). The controller only; the
    files go to __pycache__ as Python would write them itself."""
    if sys.dont_write_bytecode and not hasattr(config, "workerinput"):
        import compileall

        import dextar

        compileall.compile_dir(Path(dextar.__file__).parent, quiet=2, workers=1)


@pytest.hookimpl(trylast=True)  # after pytest-randomly's shuffle and -m's deselection
def pytest_collection_modifyitems(items):
    tests = Counter(_file(item) for item in items)
    slow = Counter(_file(item) for item in items if item.get_closest_marker("slow"))
    items.sort(key=lambda item: -slow[_file(item)] / tests[_file(item)])  # stable


@pytest.fixture(scope="session")
def pick_place_program(tmp_path_factory):
    """``dextar program examples/pick_place.toml --quiet`` with its figures and report (the
    folder), made once for the run (tests/once.py): tests/program/test_program.py and
    tests/cli/test_traps.py each read it (3.4 s of CPU each time)."""
    from dextar.cli import main

    from .program.test_program import EXAMPLES

    def make(out):
        assert main(["program", str(EXAMPLES / "pick_place.toml"), "--out", str(out),
                     "--quiet"]) == 0

    return made_once(tmp_path_factory, "pick_place_program", make)
