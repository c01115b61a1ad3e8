"""An output directory whose files appear only when complete.

Each file is written into a staging folder beside the output directory (same file system) and
renamed into place, so the output directory never holds a partial file, even when the run is
killed. The staging folder is removed at the end (also on an interruption)."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from ..errors import ConfigError


class OutputDir:
    """An output directory whose files appear only when complete (see the module doc)."""

    def __init__(self, path: str | os.PathLike[str], *, force: bool = False) -> None:
        """Open ``path``; refused when it exists, holds files and ``force`` is false."""
        self.path = Path(path)
        if self.path.exists():
            if not self.path.is_dir():
                raise ConfigError(f"output {str(self.path)!r} exists and is not a directory")
            if any(self.path.iterdir()) and not force:
                raise ConfigError(f"output directory {str(self.path)!r} exists and is not "
                                  "empty; use --force to overwrite its files")
        self.path.mkdir(parents=True, exist_ok=True)
        self.staging = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.staging-",
                                             dir=self.path.parent))
        self.written: list[str] = []

    def write_bytes(self, name: str, data: bytes) -> Path:
        """Write ``name`` in the staging folder, then rename it into place."""
        tmp = self.staging / name
        tmp.write_bytes(data)
        target = self.path / name
        os.replace(tmp, target)
        self.written.append(name)
        return target

    def write_text(self, name: str, text: str) -> Path:
        """Write ``name`` as UTF-8 text (see :meth:`write_bytes`)."""
        return self.write_bytes(name, text.encode("utf-8"))

    def close(self) -> None:
        """Remove the staging folder."""
        shutil.rmtree(self.staging, ignore_errors=True)

    def __enter__(self) -> OutputDir:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
