"""``dextar fk PHI PSI``: the end-effector (mm) for the encoder readings (deg).

With ``[robot].encoder_offset_deg`` (a calibrated config) the geometric angles are the
readings plus the offsets; the JSON gives both. The point is in the robot frame, or with
``--frame instrument`` where the measuring instrument sees it (``[instrument]``).
"""

from __future__ import annotations

import argparse

import numpy as np

from ..config.kinematic import load_kinematic_config
from ..kinematics import direct_kinematics
from .base import Result, json_flag, note_lines, noted
from .kinematics_args import frame_argument, instrument_of, robot_argument


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``phi``, ``psi`` (deg), ``--assembly``, ``--robot``, ``--frame``, ``--json``."""
    sp.add_argument("phi", type=float, help="phi reading in degrees (motor at A)")
    sp.add_argument("psi", type=float, help="psi reading in degrees (motor at D)")
    sp.add_argument("--assembly", choices=["up", "down"], help="assembly mode")
    robot_argument(sp)
    frame_argument(sp, "the frame of the point given")
    json_flag(sp)


def run(args: argparse.Namespace) -> Result:
    """Add the encoder offsets, solve and word the point."""
    kc = load_kinematic_config(args.robot)
    rc, inst = kc.robot, (kc.instrument if kc.has_instrument else None)
    assembly = args.assembly or rc.assembly_mode
    with noted(kc):
        geo = rc.geometric_deg((args.phi, args.psi))
        P = direct_kinematics(rc.geometry_mm, np.radians(geo), assembly)
    x, y = float(P[0]), float(P[1])
    if args.frame == "instrument":
        x, y = instrument_of(inst, args.robot).to_instrument_mm((x, y))
    payload = {"x_mm": x, "y_mm": y, "assembly": assembly, "frame": args.frame,
               "angles": "readings", "phi_deg": args.phi, "psi_deg": args.psi,
               "geometric_phi_deg": geo[0], "geometric_psi_deg": geo[1],
               "encoder_offset_deg": list(rc.encoder_offset_deg)}
    where = "" if args.frame == "robot" else ", instrument frame"
    text = f"x = {x:.6f} mm, y = {y:.6f} mm (assembly mode {assembly}{where})"
    if rc.encoder_offset_deg != (0.0, 0.0):
        a, b = rc.encoder_offset_deg
        text += (f" for readings {args.phi:g}, {args.psi:g} deg (geometric angles "
                 f"{geo[0]:.6f}, {geo[1]:.6f} deg, offsets [{a:g}, {b:g}] deg)")
    return Result(payload, text, note_lines("fk", kc))
