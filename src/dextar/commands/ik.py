"""``dextar ik X Y``: the encoder readings (deg) that put the end-effector at a point (mm).

With ``[robot].encoder_offset_deg`` (a calibrated config) the readings are the geometric
angles of the inverse kinematics minus the offsets (geometric angle = reading + offset); the
JSON gives both. The point is in the robot frame, or with ``--frame instrument`` a point of
the measuring instrument's frame (``[instrument]``) converted to the robot frame first.
"""

from __future__ import annotations

import argparse

import numpy as np

from ..config.kinematic import load_kinematic_config
from ..kinematics import inverse_kinematics, singularity_distances
from ..kinematics.checker import check_reach
from .base import Result, json_flag, note_lines, noted
from .kinematics_args import frame_argument, instrument_of, mode_argument, robot_argument

#: Normalised distance to a singularity below which the answer carries a warning.
NEAR_SINGULARITY = 0.05


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``x``, ``y`` (mm), ``--mode``, ``--robot``, ``--frame``, ``--json``."""
    sp.add_argument("x", type=float, help="x in mm")
    sp.add_argument("y", type=float, help="y in mm")
    mode_argument(sp)
    robot_argument(sp)
    frame_argument(sp, "the frame of the point")
    json_flag(sp)


def run(args: argparse.Namespace) -> Result:
    """Solve, take the encoder offsets off and word the readings; warn near a singularity."""
    kc = load_kinematic_config(args.robot)
    rc, inst = kc.robot, (kc.instrument if kc.has_instrument else None)
    mode = args.mode or rc.working_mode
    given = (args.x, args.y)
    frame = args.frame
    point = instrument_of(inst, args.robot).to_robot_mm(given) if frame == "instrument" else given
    P = np.array(point, float)
    where = ("" if frame == "robot" else
             f" in the robot frame (({args.x:.6g}, {args.y:.6g}) mm in the instrument's)")
    with noted(kc):
        check_reach(rc.geometry_mm, P[None, :], lambda i: "the target",
                    lambda p: f"({p[0]:.6g}, {p[1]:.6g}) mm{where}", lambda v: f"{v:.6g} mm")
        q = inverse_kinematics(rc.geometry_mm, P, mode)
    d1, d2 = (float(v) for v in singularity_distances(rc.geometry_mm, q, P))
    geo = np.degrees(q)
    # readings = geometric - offset, in (-180, 180] like the inverse kinematics' angles
    r = 180.0 - np.mod(180.0 - (geo - np.array(rc.encoder_offset_deg)), 360.0)
    phi, psi = (float(v) for v in r)
    warnings = note_lines("ik", kc)
    warnings += [f"dextar ik: warning: the pose is near a {kind} singularity (normalised "
                 f"distance {d:.3g} below {NEAR_SINGULARITY:g}): small errors in the angles "
                 "move the end-effector far" for kind, d in (("serial (type 1)", d1),
                                                             ("parallel (type 2)", d2))
                 if d < NEAR_SINGULARITY]
    payload = {"phi_deg": phi, "psi_deg": psi, "angles": "readings", "mode": mode,
               "geometric_phi_deg": float(geo[0]), "geometric_psi_deg": float(geo[1]),
               "encoder_offset_deg": list(rc.encoder_offset_deg), "frame": frame,
               "x_mm": float(P[0]), "y_mm": float(P[1]),
               "type1_distance": d1, "type2_distance": d2}
    counts = ""
    if rc.encoder_counts is not None:
        n = [int(round(v / 360.0 * rc.encoder_counts)) for v in (phi, psi)]
        payload.update(phi_counts=n[0], psi_counts=n[1], encoder_counts=rc.encoder_counts)
        counts = f"; {n[0]}, {n[1]} counts of {rc.encoder_counts:g} per turn"
    text = f"phi = {phi:.6f} deg, psi = {psi:.6f} deg (working mode {mode})"
    if rc.encoder_offset_deg != (0.0, 0.0) or counts:
        a, b = rc.encoder_offset_deg
        text = (f"phi = {phi:.6f} deg, psi = {psi:.6f} deg: encoder readings (geometric "
                f"angles {geo[0]:.6f}, {geo[1]:.6f} deg, offsets [{a:g}, {b:g}] deg{counts}) "
                f"(working mode {mode})")
    if frame == "instrument":
        text += f"; the point is ({P[0]:.6f}, {P[1]:.6f}) mm in the robot frame"
    return Result(payload, text, warnings)
