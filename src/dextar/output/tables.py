"""CSV text from named columns (full precision)."""

from __future__ import annotations

import io

import numpy as np


def csv_text(columns: dict[str, np.ndarray]) -> str:
    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    if not np.isfinite(data).all():
        bad = np.argwhere(~np.isfinite(data))[0]
        raise ValueError(f"column {names[bad[1]]} is not finite at row {bad[0]}")
    buf = io.StringIO()
    buf.write(",".join(names) + "\n")
    np.savetxt(buf, data, delimiter=",", fmt="%.17g")
    return buf.getvalue()
