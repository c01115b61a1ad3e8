"""``dextar export mjcf``: the MuJoCo model of the configured robot, with a keyframe at the
motion's start."""

from __future__ import annotations

import argparse

from .base import Result, config_argument, json_flag, out_file, units_note, write_or_hand_back

NAME = "export"
HELP = "export the robot model (mjcf: MuJoCo XML)"
REGISTRIES_HELP = True


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``format``, ``[config]``, ``--out``, ``--json``."""
    sp.add_argument("format", choices=["mjcf"])
    config_argument(sp)
    json_flag(sp)
    sp.add_argument("--out", required=True, help="XML file (- for stdout)")


def run(args: argparse.Namespace) -> Result:
    """Build the model at the motion's first sample and write it."""
    from ..config import load_scenario
    from ..output.mjcf import to_mjcf

    sc = load_scenario(args.config, model=args.model)
    path = out_file(args.out, ".xml")
    tr = sc.trajectory(samples=2)
    where, data = write_or_hand_back(path, to_mjcf(sc.model(tr.assembly),
                                                   start=(tr.q[0], tr.dq[0])))
    return Result({"out": where, "units": sc.units.describe()},
                  f"wrote {where} (MuJoCo model in {units_note(sc)}; keyframe 'start' at the "
                  "motion's start)", data=data)
