"""``dextar poses CONFIG.toml --count N --out poses.csv``: measurement poses for a kinematic
calibration, D-optimal (the observability index O1) over the working modes asked for, away
from both singularity types, inside the region the instrument measures (``--region`` or
``[instrument].region``), in an order the robot can visit. Exit 1 (the file written) when a
working mode asked for has no pose there, named."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from .. import jobs
from .._lazy import lazy_module
from ..calibration.poses import DEFAULT_MARGIN, checked_region
from ..config.kinematic import load_kinematic_config
from ..errors import DextarError
from ..geometry import WORKING_MODES, canonical_working_mode
from .base import (
    Result,
    config_argument,
    json_flag,
    note_lines,
    noted,
    out_file,
    write_or_hand_back,
)

if TYPE_CHECKING:  # the writers, imported when the command runs (start-up: dextar._lazy)
    from ..output import calibration as written
else:
    written = lazy_module("dextar.output.calibration")


def _modes(text: str) -> tuple[str, ...]:
    """``all`` or working modes separated by commas (names or aliases)."""
    text = text.strip()
    if text == "all":
        return WORKING_MODES
    try:
        names = tuple(dict.fromkeys(canonical_working_mode(m.strip())
                                    for m in text.split(",") if m.strip()))
    except DextarError as exc:
        raise argparse.ArgumentTypeError(f"{exc} (or all)") from None
    if not names:
        raise argparse.ArgumentTypeError("no working mode given: all, or modes such as +-,--")
    return names


def _region(text: str) -> tuple[float, float, float, float]:
    """``XMIN,XMAX,YMIN,YMAX`` in mm."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 4:
        raise argparse.ArgumentTypeError(f"--region {text!r} must be four numbers "
                                         "XMIN,XMAX,YMIN,YMAX (mm, robot frame)")
    try:
        return checked_region(values, "--region")
    except DextarError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``config``, ``--count``, ``--out``, ``--modes``, ``--region``, ``--margin``,
    ``--seed``, ``--frame``, ``--json``, ``--quiet``."""
    config_argument(sp, help="TOML config: [robot] (its encoder offsets and counts), "
                    "[instrument].sigma_mm (default: the DexTAR)")
    sp.add_argument("--count", type=int, required=True, help="number of poses")
    sp.add_argument("--out", required=True, help="CSV file (- for stdout)")
    sp.add_argument("--modes", type=_modes, default=None,
                    help="working modes to measure in: all (default) or a list such as +-,-- "
                    "(aliases pm,mm)")
    sp.add_argument("--region", type=_region, default=None, metavar="XMIN,XMAX,YMIN,YMAX",
                    help="every pose inside this box (mm, robot frame), where the instrument "
                    "measures (default [instrument].region, else the whole workspace)")
    sp.add_argument("--margin", type=float, default=None,
                    help="least normalised distance to both singularity types (default 0.2)")
    sp.add_argument("--seed", type=int, default=0, help="offset of the candidate grid")
    sp.add_argument("--frame", choices=["instrument", "robot"], default="instrument",
                    help="the frame the points will be measured in: an instrument's "
                    "anywhere (10 parameters, default) or the robot's (7)")
    json_flag(sp)
    sp.add_argument("--quiet", action="store_true", help="no summary output")


def run(args: argparse.Namespace) -> Result:
    """Choose the poses (:func:`dextar.jobs.poses`), write them, word the observability."""
    target = out_file(args.out, ".csv")
    kc = load_kinematic_config(args.config)
    with noted(kc):
        sel = jobs.poses(kc, args.count, modes=args.modes or WORKING_MODES,
                         region_mm=args.region,
                         margin=DEFAULT_MARGIN if args.margin is None else args.margin,
                         seed=args.seed, frame=args.frame)
    where, data = write_or_hand_back(target, written.poses_csv(sel))
    payload = written.poses_payload(sel, where=where, config=args.config or "",
                                    frame=args.frame,
                                    encoder_offset_deg=kc.robot.encoder_offset_deg)
    return Result(payload, written.poses_text(sel, where),
                  note_lines("poses", kc) + written.poses_warnings(sel), data,
                  code=1 if sel.missing_modes else 0)
