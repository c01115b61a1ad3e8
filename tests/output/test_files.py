"""The one output mechanism: files appear whole, follow the umask, an output directory is
refused unless forced and after a forced run holds that run's files only."""

import os
import stat

import pytest

from dextar.cli import main
from dextar.errors import ConfigError
from dextar.output.files import OutputDir, write_text


@pytest.fixture
def umask022():
    old = os.umask(0o022)
    yield
    os.umask(old)


def mode(p):
    return stat.S_IMODE(p.stat().st_mode)


def test_files_follow_the_umask(tmp_path, umask022):
    write_text(tmp_path / "a.csv", "x\n")
    with OutputDir(tmp_path / "d") as od:
        od.write_text("b.csv", "y\n")
    assert mode(tmp_path / "a.csv") == 0o644 and mode(tmp_path / "d" / "b.csv") == 0o644
    os.umask(0o077)
    write_text(tmp_path / "c.csv", "x\n")
    assert mode(tmp_path / "c.csv") == 0o600


@pytest.mark.slow
@pytest.mark.parametrize("argv, name", [
    (["plan", "--out", "{d}/plan.csv"], "plan.csv"),
    (["workspace", "--out", "{d}/ws.png", "--resolution", "41"], "ws.png"),
    (["export", "mjcf", "--out", "{d}/dextar.xml"], "dextar.xml"),
])
def test_commands_write_with_the_umask(tmp_path, umask022, argv, name):
    assert main([a.format(d=tmp_path) for a in argv]) == 0
    assert mode(tmp_path / name) == 0o644


def test_a_directory_is_refused_unless_forced_and_made_on_first_write(tmp_path):
    d = tmp_path / "out"
    od = OutputDir(d)
    assert not d.exists()  # nothing yet: a command that fails first leaves nothing
    od.close()
    d.mkdir()
    (d / "x").write_text("mine")
    with pytest.raises(ConfigError, match="exists and is not empty; use --force"):
        OutputDir(d)
    (tmp_path / "f").write_text("")
    with pytest.raises(ConfigError, match="is not a directory"):
        OutputDir(tmp_path / "f", force=True)


def test_a_forced_run_removes_its_own_earlier_files_only(tmp_path):
    d = tmp_path / "out"
    with OutputDir(d, produces=("a.png", "b.png", "s.json")) as od:
        od.write_text("a.png", "1")
        od.write_text("b.png", "1")
    (d / "notes.txt").write_text("the user's")
    with OutputDir(d, force=True, produces=("a.png", "b.png", "s.json")) as od:
        od.write_text("a.png", "2")
        od.write_text("s.json", "2")
    assert sorted(p.name for p in d.iterdir()) == ["a.png", "notes.txt", "s.json"]
    with pytest.raises(RuntimeError), OutputDir(d, force=True, produces=("a.png",)) as od:
        od.write_text("s.json", "3")
        raise RuntimeError  # an interrupted run removes nothing
    assert (d / "a.png").exists() and not [p for p in tmp_path.iterdir()
                                           if p.name.startswith(".")]
