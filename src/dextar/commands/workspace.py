"""``dextar workspace``: the workspace map of a working mode (reach, singularity curves,
dexterity), drawn to a PNG or SVG file."""

from __future__ import annotations

import argparse

from ..config.kinematic import load_kinematic_config
from ..errors import ConfigError
from ..kinematics import workspace_map
from ..output.figures import plot_workspace
from ..output.files import save_figure
from .base import Result, json_flag, note_lines, noted, out_file
from .kinematics_args import mode_argument, robot_argument


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``--mode``, ``--out``, ``--resolution``, ``--robot``, ``--json``."""
    mode_argument(sp)
    sp.add_argument("--out", default="workspace.png", help="PNG or SVG file")
    sp.add_argument("--resolution", type=int, default=301, help="grid points on the long side")
    robot_argument(sp)
    json_flag(sp)


def run(args: argparse.Namespace) -> Result:
    """Map, draw, summarise."""
    kc = load_kinematic_config(args.robot)
    rc = kc.robot
    mode = args.mode or rc.working_mode
    path = out_file(args.out, ".png", ".svg")
    if path is None:
        raise ConfigError("--out - is for CSV and JSON; a workspace map is a PNG or SVG file")
    with noted(kc):
        ws = workspace_map(rc.geometry_mm, mode, resolution=args.resolution)
    save_figure(plot_workspace(ws), path, dpi=150)
    area = ws.reachable_area
    reach = ws.dexterity[ws.reachable]
    payload = {"out": str(path), "mode": mode, "robot_mm": rc.geometry_mm.as_dict(),
               "resolution": [int(ws.x.size), int(ws.y.size)], "reachable_area_mm2": area,
               "dexterity_mean": float(reach.mean()) if reach.size else 0.0,
               "dexterity_max": float(reach.max()) if reach.size else 0.0,
               "type2_curve_in_workspace": bool((ws.type2[ws.reachable] > 0).any()
                                                and (ws.type2[ws.reachable] < 0).any())}
    shown_area = f"{area:.0f}" if area >= 100 else f"{area:.3g}"  # a robot in metres: not 0
    return Result(payload, f"wrote {path} (working mode {mode}, reachable area {shown_area} "
                  "mm^2)", note_lines("workspace", kc))
