import pytest

from dextar.cli import main

from ..once import made_once
from ..program.test_program import EXAMPLES


@pytest.fixture(scope="session")
def excite_csv(tmp_path_factory):
    """``dextar excite`` of the pick-and-place robot, 10 s (shared by the CLI tests, and made
    once for the run: tests/once.py)."""
    def make(path):
        assert main(["excite", str(EXAMPLES / "pick_place.toml"), "--out", str(path),
                     "--duration", "10", "--quiet"]) == 0

    return made_once(tmp_path_factory, "excite.csv", make)
