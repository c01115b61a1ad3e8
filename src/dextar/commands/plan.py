"""``dextar plan``: the configured law along the path, its samples to CSV, the motion time
and the solver's status (and the optimal law's cost)."""

from __future__ import annotations

import argparse
from typing import Any

from .base import (
    Result,
    csv_command,
    law_line,
    law_payload,
    law_warnings,
    out_file,
    units_note,
    with_notes,
    write_or_hand_back,
)

NAME = "plan"
HELP = "law of motion along the path: samples to CSV, cost"
REGISTRIES_HELP = True


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``[config]``, ``--out``, ``--json``, ``--units``."""
    csv_command(sp)


def run(args: argparse.Namespace) -> Result:
    """The command, with the config's notes (:func:`.base.with_notes`)."""
    return with_notes(NAME, args, _run)


def _run(args: argparse.Namespace) -> Result:
    """Plan, write the samples, word the law."""
    from ..config import load_scenario
    from ..output.tables import csv_text, trajectory_columns

    path = out_file(args.out, ".csv")
    sc = load_scenario(args.config, model=args.model).in_units(args.units)
    law = sc.law()
    tr = sc.trajectory(law)
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
    return Result(payload, "\n".join(lines), law_warnings("plan", law), data)
