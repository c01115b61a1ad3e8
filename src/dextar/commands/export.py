"""``dextar export mjcf``: the MuJoCo model of the configured robot, with a keyframe at the
motion's start, in SI (m, kg, s) whatever ``[output].units`` says; the paper's dimensionless
units only with ``--units paper``."""

from __future__ import annotations

import argparse

from .. import jobs
from .base import (
    Result,
    config_argument,
    json_flag,
    load,
    note_lines,
    noted,
    out_file,
    units_note,
    write_or_hand_back,
)


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``format``, ``[config]``, ``--out``, ``--units``, ``--json``."""
    sp.add_argument("format", choices=["mjcf"])
    config_argument(sp)
    json_flag(sp)
    sp.add_argument("--out", required=True, help="XML file (- for stdout)")
    sp.add_argument("--units", choices=["si", "paper"], default="si",
                    help="unit system of the model: si (default, what MuJoCo users expect: m, "
                    "kg, s, N m) or the paper's dimensionless units (not [output].units)")


def run(args: argparse.Namespace) -> Result:
    """Build the model at the motion's first sample (:func:`dextar.jobs.mjcf`), write it."""
    sc = load(args, args.units)
    path = out_file(args.out, ".xml")
    with noted(sc):
        xml = jobs.mjcf(sc, units_note(sc))
    where, data = write_or_hand_back(path, xml)
    return Result({"out": where, "units": sc.units.describe()},
                  f"wrote {where} (MuJoCo model in {units_note(sc)}; keyframe 'start' at the "
                  "motion's start)", note_lines("export", sc), data=data)
