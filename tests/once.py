"""An expensive deterministic input made once for the whole test run, not once per xdist
worker: ``--dist loadfile`` may send two files that need it to both workers, and each
worker's session fixture would make it again (the ``excite_csv`` of tests/cli: 7 s of CPU
each time on a quiet core). The first worker to need it makes it under the run's shared
temporary folder while holding a lock; the other waits for the lock and finds the file.
The file is the same bytes either way: the checks on it do not change."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import pytest


def made_once(tmp_path_factory: pytest.TempPathFactory, name: str,
              make: Callable[[Path], None]) -> Path:
    """The path of ``name`` in the run's shared folder, made by ``make(path)`` by the first
    worker that asks (``make`` must write ``path`` completely or raise). Without xdist (or
    without ``fcntl``) the folder is this session's and ``make`` runs here."""
    try:
        import fcntl
    except ImportError:  # (not POSIX: once per worker, as a session fixture would)
        fcntl = None
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER") and fcntl is not None:
        base = base.parent  # the run's folder, shared by its workers
    folder = base / f"once-{name}"
    folder.mkdir(exist_ok=True)
    path = folder / name
    with open(folder / "lock", "w") as lock:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        if not path.exists():
            staging = folder / f"staging-{name}"
            make(staging)
            staging.replace(path)  # only a complete file is ever seen under its name
    return path
