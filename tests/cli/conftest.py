import pytest

from dextar.cli import main

from ..program.test_program import EXAMPLES


@pytest.fixture(scope="session")
def excite_csv(tmp_path_factory):
    """``dextar excite`` of the pick-and-place robot, 10 s (shared by the CLI tests)."""
    path = tmp_path_factory.mktemp("ex") / "excite.csv"
    assert main(["excite", str(EXAMPLES / "pick_place.toml"), "--out", str(path),
                 "--duration", "10", "--quiet"]) == 0
    return path
