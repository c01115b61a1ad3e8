"""``dextar torques``: exact (and paper-model) torques, powers, energy and joint forces to
CSV."""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from .. import jobs
from ..output.tables import csv_text, torque_columns
from .base import (
    Result,
    csv_command,
    law_line,
    law_payload,
    law_warnings,
    load,
    note_lines,
    noted,
    out_file,
    units_note,
    write_or_hand_back,
)


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``[config]``, ``--out``, ``--json``, ``--units``."""
    csv_command(sp)


def run(args: argparse.Namespace) -> Result:
    """Compute (:func:`dextar.jobs.torques`), write the columns, word the peaks and the
    paper model's error."""
    path = out_file(args.out, ".csv")
    sc = load(args, args.units)
    with noted(sc):
        res = jobs.torques(sc)
    an = res.analysis
    where, data = write_or_hand_back(path, csv_text(torque_columns(an)))
    peak = np.abs(an.tau).max(axis=0)
    payload: dict[str, Any] = {"out": where, "samples": int(an.trajectory.t.size),
                               **law_payload(sc, an.law),
                               "peak_torque": [float(v) for v in peak],
                               "units": sc.units.describe()}
    unit = sc.units.names["torque"]
    text = (f"{law_line(sc, an.law)}\nwrote {where}: {an.trajectory.t.size} samples; peak "
            f"|tau|: motor A {peak[0]:.6g} {unit}, motor D {peak[1]:.6g} {unit} "
            f"({units_note(sc)})")
    if an.paper is not None:
        payload["paper_model_error"] = an.paper.error
        left = an.paper.leaves_out
        text += (f"\npaper model (42) error: max {an.paper.error['max_relative']:.1%}, RMS "
                 f"{an.paper.error['rms_relative']:.1%} of the peak exact torque"
                 + (f" (against the exact torques without {' and '.join(left)}, which (42) "
                    "leaves out)" if left else ""))
    else:
        text += ("\nno paper-model columns: the paper's simplified model does not apply "
                 f"({res.paper_model_reason})")
    return Result(payload, text, note_lines("torques", sc) + law_warnings("torques", an.law),
                  data)
