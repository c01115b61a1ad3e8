"""``dextar fk PHI PSI``: the end-effector (mm) for the actuator angles (deg)."""

from __future__ import annotations

import argparse

from .base import Result, json_flag

NAME = "fk"
HELP = "direct kinematics: end-effector for actuator angles"


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``phi``, ``psi`` (deg), ``--assembly``, ``--robot``, ``--json``."""
    from .kinematics_args import robot_argument

    sp.add_argument("phi", type=float, help="phi in degrees (motor at A)")
    sp.add_argument("psi", type=float, help="psi in degrees (motor at D)")
    sp.add_argument("--assembly", choices=["up", "down"], help="assembly mode")
    robot_argument(sp)
    json_flag(sp)


def run(args: argparse.Namespace) -> Result:
    """Solve and word the point."""
    import numpy as np

    from ..config import load_robot_table
    from ..kinematics import direct_kinematics

    rc = load_robot_table(args.robot)
    assembly = args.assembly or rc.assembly_mode
    P = direct_kinematics(rc.geometry_mm, np.radians([args.phi, args.psi]), assembly)
    x, y = float(P[0]), float(P[1])
    return Result({"x_mm": x, "y_mm": y, "assembly": assembly},
                  f"x = {x:.6f} mm, y = {y:.6f} mm (assembly mode {assembly})")
