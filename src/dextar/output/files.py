"""Writing files: each output appears only when complete and follows the user's umask.

One mechanism for every command: a file is written to a temporary name in its target folder
(or in a staging folder beside an output directory) and renamed into place, so an interrupted
run never leaves a half-written file. :class:`OutputDir` is an output directory: refused when
it holds files unless forced (or resumed), and written all at once: its files wait in the
staging folder until the run completes, then all are renamed into place with the
interrupting signals held (a run interrupted or failed before that leaves nothing, not even
the directory; after a forced run the directory holds that run's files only: the files of
the command's own names, ``produces``, that this run did not write are removed; files of
other names are left alone). A resumable command (a design sweep, whose rows are its
checkpoints) writes straight into the directory instead (``staged=False``).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Collection, Iterator
from pathlib import Path
from typing import Any

from ..errors import ConfigError


def _file_mode() -> int:
    """The mode of a new file under the current umask (read without changing it for long)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return 0o666 & ~mask


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success it gets the umask's mode and is
    renamed onto ``path``."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, _file_mode())
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    write_bytes(path, text.encode("utf-8"))


def save_figure(fig: Any, path: str | os.PathLike[str], **kwargs: Any) -> None:
    """Save a matplotlib figure atomically; the format follows the file's suffix."""
    fmt = Path(path).suffix.lstrip(".").lower() or "png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, **kwargs)


def check_output_dir(path: Path, *, force: bool, hint: str = "use --force to overwrite its "
                     "files") -> None:
    """Refuse ``path`` when it is not a directory, or holds files and ``force`` is false."""
    if path.exists():
        if not path.is_dir():
            raise ConfigError(f"output {str(path)!r} exists and is not a directory")
        if not force and any(path.iterdir()):
            raise ConfigError(f"output directory {str(path)!r} exists and is not empty; {hint}")


#: The signals held while a run's files are renamed into place (those that end a run).
_HELD = frozenset(getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP")
                  if hasattr(signal, n))


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """Hold the interrupting signals: their handlers replaced by a note of them, then put
    back and each signal noted raised again, once (a mask would not do: another thread,
    such as a BLAS worker, takes a signal the main thread masks, and Python then runs its
    handler at once). Only on the main thread and for the signals whose handlers Python set
    (a handler set from C reads as None and cannot be put back); elsewhere nothing."""
    pending: list[int] = []

    def note(signum: int, frame: object) -> None:
        if signum not in pending:
            pending.append(signum)

    old: dict[int, Any] = {}
    if threading.current_thread() is threading.main_thread():
        for sig in _HELD:
            handler = signal.getsignal(sig)
            if handler is None:
                continue
            try:
                signal.signal(sig, note)
            except (ValueError, OSError):  # (a sub-interpreter: no handlers to set)
                continue
            old[sig] = handler
    try:
        yield
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)
        for sig in pending:
            signal.raise_signal(sig)


class OutputDir:
    """An output directory whose files appear only when complete (see the module doc).

    ``produces``: the names the command may write (removed after a forced run when this run
    did not write them); ``keep``: a resumed run, the files already there are its own (no
    check, nothing removed); ``staged``: the files wait in the staging folder until the run
    completes (:meth:`finish`), else each is renamed into place when written."""

    def __init__(self, path: str | os.PathLike[str], *, force: bool = False,
                 keep: bool = False, produces: Collection[str] = (),
                 hint: str = "use --force to overwrite its files", staged: bool = True
                 ) -> None:
        """Check ``path``: refused when it exists, holds files and neither ``force`` nor
        ``keep`` is set. Nothing is created yet."""
        self.path = Path(path)
        if not keep:
            check_output_dir(self.path, force=force, hint=hint)
        self.keep = keep
        self.staged = staged
        self.produces = frozenset(produces)
        self._staging: Path | None = None
        self._waiting: list[str] = []  # (the names waiting in the staging folder)
        self.written: list[str] = []

    @property
    def staging(self) -> Path:
        """The staging folder beside the directory (created on first use, with the
        directory itself unless the files are staged)."""
        if self._staging is None:
            if self.staged:
                self.path.parent.mkdir(parents=True, exist_ok=True)
            else:
                self.path.mkdir(parents=True, exist_ok=True)
            self._staging = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.staging-",
                                                  dir=self.path.parent))
        return self._staging

    def write_bytes(self, name: str, data: bytes) -> Path:
        """Write ``name`` in the staging folder, then rename it into place (when the run
        completes if staged); its final path."""
        tmp = self.staging / name
        tmp.write_bytes(data)
        target = self.path / name
        if not self.staged:
            os.replace(tmp, target)
        elif name not in self._waiting:
            self._waiting.append(name)
        self.record(name)
        return target

    def write_text(self, name: str, text: str) -> Path:
        """Write ``name`` as UTF-8 text (see :meth:`write_bytes`)."""
        return self.write_bytes(name, text.encode("utf-8"))

    def record(self, name: str) -> None:
        """Count ``name`` as this run's (a file written into the folder some other way)."""
        if name not in self.written:
            self.written.append(name)

    def finish(self) -> None:
        """The run completed: its staged files renamed into place and the files of the
        command's names that this run did not write (an earlier run's) removed (with the
        interrupting signals held when called by the ``with`` block's end: an interrupt
        then acts after all of it; an error of the file system midway, a target name that
        is a folder, still leaves it part done)."""
        if self._waiting:
            self.path.mkdir(parents=True, exist_ok=True)
            assert self._staging is not None
            for name in self._waiting:
                os.replace(self._staging / name, self.path / name)
        if self.keep or not self.path.is_dir():
            return
        for name in self.produces - set(self.written):
            stale = self.path / name
            if stale.is_file():
                stale.unlink()

    def close(self) -> None:
        """Remove the staging folder."""
        if self._staging is not None:
            shutil.rmtree(self._staging, ignore_errors=True)

    def __enter__(self) -> OutputDir:
        return self

    def __exit__(self, exc_type: object, *exc: object) -> None:
        with _signals_held():  # (the renames and the staging folder's removal, whole)
            try:
                if exc_type is None:
                    self.finish()
            finally:
                self.close()
