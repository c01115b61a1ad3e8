"""Measured motion: reading and checking the samples an identification starts from."""

from __future__ import annotations

import csv
import io
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._arrays import Array
from ..errors import ConfigError, ParameterError

#: Columns a data file must have.
REQUIRED = ("t_s", "phi_rad", "psi_rad", "tau1_Nm", "tau2_Nm")
#: Columns used when present.
OPTIONAL = ("dphi_rad_s", "dpsi_rad_s", "ddphi_rad_s2", "ddpsi_rad_s2")
#: Largest relative deviation of a time step from the median step.
UNIFORM_TOL = 0.01
#: Largest angle magnitude accepted (rad): beyond it the column is not in radians.
MAX_ANGLE = 1000.0
#: Largest magnitude accepted for times, rates, accelerations and torques (SI).
MAX_VALUE = 1e9


@dataclass(frozen=True)
class MotionData:
    """Samples of a measured motion (SI: s, rad, N m).

    Attributes
    ----------
    t : ndarray, shape (n,)
    q : ndarray, shape (n, 2)
        Motor angles ``(phi, psi)``.
    tau : ndarray, shape (n, 2)
        Measured motor torques.
    dq, ddq : ndarray, shape (n, 2), or None
        Measured rates and accelerations, when the data have them.
    source : str
        Where the samples come from (to name it in errors).
    """

    t: Array
    q: Array
    tau: Array
    dq: Array | None = None
    ddq: Array | None = None
    source: str = "data"

    def __post_init__(self) -> None:
        check_motion(self)

    @property
    def rate_hz(self) -> float:
        """Sample rate (1 / the median time step)."""
        return float(1.0 / np.median(np.diff(self.t)))


def _rows(mask: Array) -> str:
    """The data rows (1-based, after the header) of the True entries, at most 5 named."""
    rows = np.flatnonzero(mask) + 2
    shown = ", ".join(str(int(r)) for r in rows[:5])
    return shown + (f" and {len(rows) - 5} more" if len(rows) > 5 else "")


def check_motion(d: MotionData) -> None:
    """Raise :class:`ParameterError` naming the column and the rows of the first problem:
    shapes, non-finite values, time not increasing or not uniform within 1 %."""
    n = len(d.t)
    named = {"t_s": d.t[:, None], "phi_rad, psi_rad": d.q, "tau1_Nm, tau2_Nm": d.tau,
             "dphi_rad_s, dpsi_rad_s": d.dq, "ddphi_rad_s2, ddpsi_rad_s2": d.ddq}
    for name, arr in named.items():
        if arr is None:
            continue
        if arr.shape[0] != n:
            raise ParameterError(f"{d.source}: column {name} has {arr.shape[0]} samples, "
                                 f"t_s has {n}")
        bad = np.asarray(~np.isfinite(arr).all(axis=1))
        if bad.any():
            raise ParameterError(f"{d.source}: column {name} is NaN or infinite at row "
                                 f"{_rows(bad)}")
    big = np.asarray((np.abs(d.q) > MAX_ANGLE).any(axis=1))
    if big.any():
        raise ParameterError(f"{d.source}: phi_rad, psi_rad beyond {MAX_ANGLE:g} rad at row "
                             f"{_rows(big)}: not angles in radians")
    for name, arr in named.items():
        if arr is None or name.startswith("phi"):
            continue
        huge = np.asarray((np.abs(arr) > MAX_VALUE).any(axis=1))
        if huge.any():
            raise ParameterError(f"{d.source}: column {name} beyond {MAX_VALUE:g} at row "
                                 f"{_rows(huge)}: not a measurement in SI units")
    if n < 3:
        raise ParameterError(f"{d.source}: {n} samples; an identification needs many more")
    dt = np.diff(d.t)
    if not (dt > 0).all():
        raise ParameterError(f"{d.source}: t_s does not increase at row {_rows(np.asarray(np.r_[False, dt <= 0]))}")
    step = float(np.median(dt))
    off = np.abs(dt - step) > UNIFORM_TOL * step
    if off.any():
        i = int(np.flatnonzero(off)[0])
        raise ParameterError(
            f"{d.source}: t_s is not uniform within {100 * UNIFORM_TOL:g} %: step "
            f"{dt[i]:.6g} s at row {i + 3} against the median {step:.6g} s")


def _fast_table(p: Path, raw: bytes, width: int) -> Array | None:
    """Every column of the data rows of ``p`` as floats (n, width) by ``np.loadtxt``, or None
    when the file is not a plain table of numbers with one row per line (a blank line, a
    short row, a quote, a bad value): then :func:`read_motion_csv` reads it row by row and
    names the problem."""
    lines = raw.count(b"\n") + (0 if raw.endswith(b"\n") else 1)
    if lines < 2:
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with p.open(newline="") as fh:
                fh.readline()
                values = np.loadtxt(fh, delimiter=",", comments=None, ndmin=2, dtype=float)
    except (ValueError, Warning, OSError, UnicodeDecodeError):
        return None
    # loadtxt skips blank lines, which would shift the rows named in errors
    if values.shape != (lines - 1, width):
        return None
    return np.asarray(values)


def read_motion_csv(path: str | Path) -> MotionData:
    """Read a data file (CSV with a header; see :data:`REQUIRED` and :data:`OPTIONAL`).

    A plain table of numbers is read by ``np.loadtxt`` (60,001 rows in about 1.2x its own
    time); anything else row by row, naming the first bad row and column.

    Raises
    ------
    ConfigError
        The file is missing, unreadable, or lacks a required column (named).
    ParameterError
        A value is not a number, or the samples fail :func:`check_motion`.
    """
    p = Path(path)
    try:
        raw = p.read_bytes()
        text_head = raw.split(b"\n", 1)[0].decode()
    except OSError as exc:
        raise ConfigError(f"data file {str(p)!r} cannot be read: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise ConfigError(f"data file {str(p)!r} is not a text (CSV) file") from None
    if not raw:
        raise ConfigError(f"data file {str(p)!r} is empty")
    head = [h.strip() for h in next(csv.reader([text_head.rstrip("\r")]), [])]
    missing = [c for c in REQUIRED if c not in head]
    if missing:
        raise ConfigError(f"data file {str(p)!r} lacks the column{'s' if len(missing) > 1 else ''} "
                          f"{', '.join(missing)} (it has {', '.join(head) or 'none'})")
    wanted = [c for c in REQUIRED + OPTIONAL if c in head]
    cols = {c: head.index(c) for c in wanted}
    idx = [cols[c] for c in wanted]
    table = _fast_table(p, raw, len(head))
    if table is not None:
        values = table[:, idx]
    else:
        values = _slow_values(p, raw, head, wanted, cols, idx)
    v = {c: values[:, k] for k, c in enumerate(wanted)}

    def pair(a: str, b: str) -> Array | None:
        if a in v and b in v:
            return np.stack([v[a], v[b]], axis=-1)
        if a in v or b in v:
            raise ConfigError(f"data file {str(p)!r} has {a if a in v else b} without "
                              f"{b if a in v else a}")
        return None

    q, tau = pair("phi_rad", "psi_rad"), pair("tau1_Nm", "tau2_Nm")
    assert q is not None and tau is not None
    return MotionData(v["t_s"], q, tau, pair("dphi_rad_s", "dpsi_rad_s"),
                      pair("ddphi_rad_s2", "ddpsi_rad_s2"), source=str(p))


def _slow_values(p: Path, raw: bytes, head: list[str], wanted: list[str],
                 cols: dict[str, int], idx: list[int]) -> Array:
    """The wanted columns (n, len(wanted)) read row by row with :mod:`csv`, raising
    :class:`ParameterError` at the first row of the wrong width or value that is not a
    number."""
    try:
        rows = list(csv.reader(io.StringIO(raw.decode(), newline="")))
    except UnicodeDecodeError:
        raise ConfigError(f"data file {str(p)!r} is not a text (CSV) file") from None
    body = rows[1:]
    short = [r for r, row in enumerate(body) if len(row) != len(head)]
    if short:
        r = short[0]
        raise ParameterError(f"{p}: row {r + 2} has {len(body[r])} fields, the header "
                             f"{len(head)}")
    try:
        values = np.array([[row[i] for i in idx] for row in body], dtype=float)
    except ValueError:
        for r, row in enumerate(body):
            for c in wanted:
                text = row[cols[c]].strip()
                try:
                    float(text)
                except ValueError:
                    raise ParameterError(f"{p}: row {r + 2}, column {c}: {text!r} is not "
                                         "a number") from None
        raise
    return np.asarray(values.reshape(len(body), len(wanted)))
