"""The one output mechanism: files appear whole, follow the umask, an output directory is
refused unless forced, is written all at once (an interrupted run leaves nothing and an
earlier run's files as they were) and after a forced run holds that run's files only."""

import os
import signal
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


def test_an_interrupted_run_leaves_nothing_and_an_earlier_run_as_it_was(tmp_path):
    """A run interrupted while writing (the drive's files written, the figures not yet)
    leaves no directory, and forced into an earlier run's directory leaves that run's files
    as they were: a new user's interrupted ``dextar program --force`` had left a new
    setpoints.csv beside the earlier run's summary.json and drive files."""
    names = ("setpoints.csv", "csp.csv", "summary.json")
    d = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt), OutputDir(d, produces=names) as od:
        od.write_text("setpoints.csv", "new")
        od.write_text("csp.csv", "new")
        raise KeyboardInterrupt
    assert not d.exists() and list(tmp_path.iterdir()) == []
    with OutputDir(d, produces=names) as od:
        for name in names:
            od.write_text(name, "old")
    with pytest.raises(KeyboardInterrupt), OutputDir(d, force=True, produces=names) as od:
        od.write_text("setpoints.csv", "new")
        assert (d / "setpoints.csv").read_text() == "old"  # (staged until the run ends)
        raise KeyboardInterrupt
    assert {p.name: p.read_text() for p in d.iterdir()} == dict.fromkeys(names, "old")
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # (no staging folder left)


def test_a_signal_while_the_files_are_renamed_into_place_waits_for_all_of_them(
        tmp_path, monkeypatch):
    """An interrupt that arrives as a completed run's files are renamed into place is
    delivered after the last one (its handler finds them all, the earlier run's stale file
    gone)."""
    names = ("a.csv", "b.csv", "c.csv", "d.json")
    d = tmp_path / "out"
    with OutputDir(d, produces=names) as od:
        od.write_text("d.json", "old")
    seen, sent = [], []
    real = os.replace

    def replace(src, dst):
        if not sent:
            sent.append(os.kill(os.getpid(), signal.SIGINT))
        real(src, dst)

    def handler(signum, frame):
        seen.append(sorted(p.name for p in d.iterdir()))

    monkeypatch.setattr(os, "replace", replace)
    old = signal.signal(signal.SIGINT, handler)
    try:
        with OutputDir(d, force=True, produces=names) as od:
            for name in names[:3]:
                od.write_text(name, "new")
        seen.append("finished")
    finally:
        signal.signal(signal.SIGINT, old)
    assert seen == [["a.csv", "b.csv", "c.csv"], "finished"]


def test_signals_held_are_raised_once_and_recorded_names_are_not_moved(tmp_path, monkeypatch):
    """A signal sent at every rename reaches its handler once, after the last; a name
    counted with ``record`` (a file written into the folder some other way) is not looked
    for in the staging folder."""
    d = tmp_path / "out"
    calls = []
    real = os.replace

    def replace(src, dst):
        os.kill(os.getpid(), signal.SIGINT)
        real(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    old = signal.signal(signal.SIGINT, lambda *_: calls.append(sorted(os.listdir(d))))
    try:
        with OutputDir(d, produces=("a.csv", "b.csv", "c.csv")) as od:
            for name in ("a.csv", "b.csv"):
                od.write_text(name, "new")
            od.record("c.csv")
    finally:
        signal.signal(signal.SIGINT, old)
    assert calls == [["a.csv", "b.csv"]]
