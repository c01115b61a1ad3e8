"""``dextar plan``: the configured law along the path, its samples to CSV, the motion time
and the solver's status (and the optimal law's cost)."""

from __future__ import annotations

import argparse
from typing import Any

from .. import jobs
from ..output.tables import csv_text, trajectory_columns
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
    """Plan (:func:`dextar.jobs.plan`), write the samples, word the law."""
    path = out_file(args.out, ".csv")
    sc = load(args, args.units)
    with noted(sc):
        res = jobs.plan(sc)
    law, tr = res.law, res.trajectory
    where, data = write_or_hand_back(path, csv_text(trajectory_columns(tr, sc.units)))
    payload: dict[str, Any] = {"out": where, "samples": int(tr.t.size), **law_payload(sc, law),
                               "units": sc.units.describe()}
    lines = [law_line(sc, law)]
    cost = law.cost_report()
    if cost is not None:
        payload.update(cost=cost["total"], cost_kinetic=cost["kinetic"],
                       cost_inertial=cost["inertial"])
        lines.append(f"cost Phi = {cost['total']:.10g} (kinetic {cost['kinetic']:.10g}, "
                     f"inertial {cost['inertial']:.10g}) [{sc.units.names['energy']} x "
                     f"{sc.units.names['time']}]")
    lines.append(f"wrote {where}: {tr.t.size} samples, working mode {tr.mode} "
                 f"({units_note(sc)})")
    return Result(payload, "\n".join(lines), note_lines("plan", sc) + law_warnings("plan", law),
                  data)
