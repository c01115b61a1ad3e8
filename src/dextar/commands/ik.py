"""``dextar ik X Y``: the actuator angles (deg) that put the end-effector at a point (mm)."""

from __future__ import annotations

import argparse

from .base import Result, json_flag

NAME = "ik"
HELP = "inverse kinematics: actuator angles for a point"
#: Normalised distance to a singularity below which the answer carries a warning.
NEAR_SINGULARITY = 0.05


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``x``, ``y`` (mm), ``--mode``, ``--robot``, ``--json``."""
    from .kinematics_args import mode_argument, robot_argument

    sp.add_argument("x", type=float, help="x in mm")
    sp.add_argument("y", type=float, help="y in mm")
    mode_argument(sp)
    robot_argument(sp)
    json_flag(sp)


def run(args: argparse.Namespace) -> Result:
    """Solve and word the angles; warn near a singularity."""
    import numpy as np

    from ..config import load_robot_table
    from ..kinematics import inverse_kinematics, singularity_distances
    from ..kinematics.checker import check_reach

    rc = load_robot_table(args.robot)
    mode = args.mode or rc.working_mode
    P = np.array([args.x, args.y], float)
    check_reach(rc.geometry_mm, P[None, :], lambda i: "the target",
                lambda p: f"({p[0]:.6g}, {p[1]:.6g}) mm", lambda v: f"{v:.6g} mm")
    q = inverse_kinematics(rc.geometry_mm, P, mode)
    d1, d2 = (float(v) for v in singularity_distances(rc.geometry_mm, q, P))
    phi, psi = (float(v) for v in np.degrees(q))
    warnings = [f"dextar ik: warning: the pose is near a {kind} singularity (normalised "
                f"distance {d:.3g} below {NEAR_SINGULARITY:g}): small errors in the angles "
                "move the end-effector far" for kind, d in (("serial (type 1)", d1),
                                                            ("parallel (type 2)", d2))
                if d < NEAR_SINGULARITY]
    return Result({"phi_deg": phi, "psi_deg": psi, "mode": mode, "type1_distance": d1,
                   "type2_distance": d2},
                  f"phi = {phi:.6f} deg, psi = {psi:.6f} deg (working mode {mode})", warnings)
