"""Measured poses: the encoder readings and the measured end-effector point of each pose,
read from CSV and checked.

A file has the columns ``phi_deg, psi_deg`` (encoder readings), ``x_mm, y_mm`` (the point
the instrument measured) and optionally ``mode`` (the working mode the robot was in: ``++``,
``+-``, ``-+``, ``--`` or the aliases ``pp``, ``pm``, ``mp``, ``mm``), ``assembly`` (``up`` or
``down``; a blank cell or a missing column means: the assembly whose nominal prediction is
nearer the measured point) and ``sigma_mm`` (the standard deviation of that point per axis).
Rows are numbered as lines of the file, the header being row 1.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._arrays import Array
from ..errors import ConfigError, ParameterError
from ..geometry import canonical_working_mode, parse_assembly_mode

#: Columns a measured-poses file must have.
REQUIRED = ("phi_deg", "psi_deg", "x_mm", "y_mm")
#: Columns used when present.
OPTIONAL = ("mode", "assembly", "sigma_mm")
#: Largest magnitude accepted for a reading (deg) or a coordinate (mm): beyond it the column
#: is not in those units.
MAX_DEG = 1e4
MAX_MM = 1e6


def check_readings_deg(readings_deg: tuple[float, float]) -> None:
    """Raise :class:`ParameterError` for encoder readings ``(phi, psi)`` (deg) that are no
    readings: NaN, infinite, or beyond :data:`MAX_DEG` (the bound of a measured-poses file:
    a value past it is not an angle in degrees; ``dextar fk 1e300 30`` had answered a
    point)."""
    for name, v in zip(("phi", "psi"), readings_deg, strict=True):
        if math.isnan(v):
            raise ParameterError(f"encoder reading {name} = NaN deg is not a number")
        if not math.isfinite(v):
            raise ParameterError(f"encoder reading {name} = {v:g} deg is infinite")
        if abs(v) > MAX_DEG:
            raise ParameterError(f"encoder reading {name} = {v:.6g} deg is beyond "
                                 f"{MAX_DEG:g} deg: not a reading in degrees")


def rows_text(rows: Array, limit: int = 5) -> str:
    """Row numbers as words: ``"3, 7 and 12"``, at most ``limit`` named."""
    r = [str(int(v)) for v in np.asarray(rows).reshape(-1)]
    if len(r) > limit:
        return ", ".join(r[:limit]) + f" and {len(r) - limit} more"
    return r[0] if len(r) == 1 else ", ".join(r[:-1]) + " and " + r[-1]


@dataclass(frozen=True)
class PoseData:
    """Measured poses (SI: rad, m).

    Attributes
    ----------
    readings : ndarray, shape (n, 2)
        Encoder readings ``(phi, psi)`` (rad).
    points : ndarray, shape (n, 2)
        Measured end-effector points (m), in the instrument's frame (or the robot frame).
    modes : tuple of str, length n
        Working mode of each pose (canonical names, ``"+-"``).
    assembly : ndarray of int, shape (n,)
        +1 (up), -1 (down), 0 (not given: chosen by the calibration).
    sigma : ndarray, shape (n,), optional
        Standard deviation of each measured point per axis (m).
    rows : ndarray of int, shape (n,)
        Row number of each pose in its file (the header is row 1; default 2, 3, ...).
    source : str
        Where the poses come from, to name it in errors.
    """

    readings: Array
    points: Array
    modes: tuple[str, ...]
    assembly: Array
    sigma: Array | None = None
    rows: Array = field(default_factory=lambda: np.zeros(0, int))
    source: str = "poses"

    def __post_init__(self) -> None:
        r = np.asarray(self.readings, dtype=float)
        P = np.asarray(self.points, dtype=float)
        n = len(r)
        if r.shape != (n, 2) or P.shape != (n, 2):
            raise ParameterError(f"{self.source}: readings and points must both have shape "
                                 f"(n, 2), got {r.shape} and {P.shape}")
        object.__setattr__(self, "readings", r)
        object.__setattr__(self, "points", P)
        object.__setattr__(self, "modes", tuple(canonical_working_mode(m) for m in self.modes))
        if len(self.modes) != n:
            raise ParameterError(f"{self.source}: {len(self.modes)} working modes for {n} poses")
        a = np.broadcast_to(np.asarray(self.assembly, dtype=int), (n,)).copy()
        if not np.isin(a, (-1, 0, 1)).all():
            raise ParameterError(f"{self.source}: assembly modes must be +1, -1 or 0")
        object.__setattr__(self, "assembly", a)
        rows = np.asarray(self.rows, dtype=int)
        if rows.size == 0:
            rows = np.arange(n) + 2
        if rows.shape != (n,):
            raise ParameterError(f"{self.source}: {rows.size} row numbers for {n} poses")
        object.__setattr__(self, "rows", rows)
        if self.sigma is not None:
            s = np.broadcast_to(np.asarray(self.sigma, dtype=float), (n,)).copy()
            object.__setattr__(self, "sigma", s)
        check_poses(self)

    def __len__(self) -> int:
        return len(self.readings)

    def subset(self, keep: Array) -> PoseData:
        """The poses where ``keep`` (n,) is True (or at the indices ``keep``)."""
        idx = np.arange(len(self))[keep]
        return PoseData(self.readings[idx], self.points[idx],
                        tuple(self.modes[i] for i in idx), self.assembly[idx],
                        None if self.sigma is None else self.sigma[idx], self.rows[idx],
                        self.source)

    @property
    def working_modes(self) -> tuple[str, ...]:
        """The distinct working modes of the poses, in first-seen order."""
        return tuple(dict.fromkeys(self.modes))


def check_poses(d: PoseData) -> None:
    """Raise :class:`ParameterError` naming the rows of the first problem: non-finite
    values, readings not in degrees' range, sigma not positive."""
    for name, arr in (("phi_deg, psi_deg", d.readings), ("x_mm, y_mm", d.points)):
        bad = ~np.isfinite(arr).all(axis=1)
        if bad.any():
            raise ParameterError(f"{d.source}: {name} is NaN or infinite at row "
                                 f"{rows_text(d.rows[bad])}")
    big = (np.abs(np.degrees(d.readings)) > MAX_DEG).any(axis=1)
    if big.any():
        raise ParameterError(f"{d.source}: phi_deg, psi_deg beyond {MAX_DEG:g} deg at row "
                             f"{rows_text(d.rows[big])}: not readings in degrees")
    far = (np.abs(1e3 * d.points) > MAX_MM).any(axis=1)
    if far.any():
        raise ParameterError(f"{d.source}: x_mm, y_mm beyond {MAX_MM:g} mm at row "
                             f"{rows_text(d.rows[far])}: not points in millimetres")
    if d.sigma is not None:
        bad = ~(np.isfinite(d.sigma) & (d.sigma > 0))
        if bad.any():
            raise ParameterError(f"{d.source}: sigma_mm must be positive and finite; it is "
                                 f"not at row {rows_text(d.rows[bad])}")


def poses_from_arrays(readings_deg: object, points_mm: object, modes: Sequence[str] | str, *,
                      assembly: object = 0, sigma_mm: object = None,
                      source: str = "poses") -> PoseData:
    """:class:`PoseData` from values in file units (deg, mm); ``modes`` one name for all
    poses or one per pose; ``assembly`` +1/-1/0 or ``"up"``/``"down"`` per pose or for all."""
    r = np.radians(np.asarray(readings_deg, dtype=float))
    P = 1e-3 * np.asarray(points_mm, dtype=float)
    n = len(r)
    m = (modes,) * n if isinstance(modes, str) else tuple(modes)
    a = np.asarray(assembly)
    if a.dtype.kind in "US":
        a = np.array([parse_assembly_mode(str(v)) for v in np.broadcast_to(a, (n,))])
    sig = None if sigma_mm is None else 1e-3 * np.asarray(sigma_mm, dtype=float)
    return PoseData(r, P, m, a, sig, source=source)


def read_poses_csv(path: str | Path, *, working_mode: str | None = None) -> PoseData:
    """Read a measured-poses file (see the module doc).

    Parameters
    ----------
    path : str or Path
    working_mode : str, optional
        The working mode of every row when the file has no ``mode`` column (the config's
        ``[robot].working_mode``).

    Returns
    -------
    PoseData
        Readings in rad, points in m, sigma in m.

    Raises
    ------
    ConfigError
        The file is missing, unreadable, empty or lacks a required column (named), or has
        no ``mode`` column and no ``working_mode`` is given.
    ParameterError
        A value that is not a number, a mode or an assembly (row and column named), NaN or
        infinite values (the rows), sigma not positive.
    """
    p = Path(path)
    t = _table(p, working_mode)
    readings = np.radians(np.stack([t.numbers("phi_deg"), t.numbers("psi_deg")], axis=-1))
    points = 1e-3 * np.stack([t.numbers("x_mm"), t.numbers("y_mm")], axis=-1)
    modes, assembly = t.modes_and_assembly(working_mode)
    sigma = 1e-3 * t.numbers("sigma_mm") if "sigma_mm" in t.col else None
    return PoseData(readings, points, modes, assembly, sigma, t.rows, str(p))


@dataclass(frozen=True)
class _Table:
    """The poses of a file as text: its lines after the header (``body``), the index of
    each known column present (``col``) and the lines' row numbers (``rows``)."""

    path: Path
    body: list[list[str]]
    col: dict[str, int]
    rows: Array

    def cell(self, i: int, name: str) -> str:
        """The stripped text of line ``i`` in column ``name``."""
        return self.body[i][self.col[name]].strip()

    def numbers(self, name: str) -> Array:
        """Column ``name`` as numbers (n,); :class:`ParameterError` at the first that is
        not one."""
        out = np.empty(len(self.body))
        for i in range(len(self.body)):
            text = self.cell(i, name)
            try:
                out[i] = float(text)
            except ValueError:
                raise ParameterError(f"{self.path}: row {self.rows[i]}, column {name}: "
                                     f"{text!r} is not a number") from None
        return out

    def modes_and_assembly(self, working_mode: str | None) -> tuple[tuple[str, ...], Array]:
        """The working mode (column ``mode``, else ``working_mode``) and the assembly (+1/-1,
        0 where not given) of each line, checked line by line."""
        default = None
        if "mode" not in self.col:
            assert working_mode is not None
            default = canonical_working_mode(working_mode)
        modes: list[str] = []
        assembly = np.zeros(len(self.body), int)
        for i in range(len(self.body)):
            modes.append(self._mode(i) if default is None else default)
            if "assembly" in self.col:
                assembly[i] = self._assembly(i)
        return tuple(modes), assembly

    def _mode(self, i: int) -> str:
        text = self.cell(i, "mode")
        try:
            return canonical_working_mode(text)
        except ParameterError:
            raise ParameterError(f"{self.path}: row {self.rows[i]}, column mode: {text!r} is "
                                 "not a working mode (++, +-, -+, -- or pp, pm, mp, mm)"
                                 ) from None

    def _assembly(self, i: int) -> int:
        text = self.cell(i, "assembly")
        if not text:
            return 0
        try:
            return parse_assembly_mode(text)
        except ParameterError:
            raise ParameterError(f"{self.path}: row {self.rows[i]}, column assembly: {text!r} "
                                 "is not up or down") from None


def _table(p: Path, working_mode: str | None) -> _Table:
    """The file ``p`` read and its layout checked: readable text, not empty, the required
    columns (and ``mode`` unless ``working_mode``), poses after the header, as many fields
    in every line as in the header."""
    try:
        with p.open(newline="") as fh:
            lines = [row for row in csv.reader(fh) if row and any(c.strip() for c in row)]
    except OSError as exc:
        raise ConfigError(f"poses file {str(p)!r} cannot be read: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise ConfigError(f"poses file {str(p)!r} is not a text (CSV) file") from None
    if not lines:
        raise ConfigError(f"poses file {str(p)!r} is empty")
    head = [h.strip() for h in lines[0]]
    missing = [c for c in REQUIRED if c not in head]
    if missing:
        raise ConfigError(f"poses file {str(p)!r} lacks the column"
                          f"{'s' if len(missing) > 1 else ''} {', '.join(missing)} (it has "
                          f"{', '.join(h for h in head if h) or 'none'})")
    if "mode" not in head and working_mode is None:
        raise ConfigError(f"poses file {str(p)!r} has no mode column and no working mode is "
                          "given for its rows ([robot].working_mode)")
    body = lines[1:]
    if not body:
        raise ParameterError(f"{p}: no poses after the header")
    rows = np.arange(len(body)) + 2
    for r, line in zip(rows, body, strict=True):
        if len(line) != len(head):
            raise ParameterError(f"{p}: row {r} has {len(line)} fields, the header {len(head)}")
    return _Table(p, body, {c: head.index(c) for c in REQUIRED + OPTIONAL if c in head}, rows)
