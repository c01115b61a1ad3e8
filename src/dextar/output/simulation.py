"""Writing a control simulation: ``tracking.csv``, ``tracking.png`` and ``tracking.json``."""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from ..simulation import ControlResult
from ..trajectory import Trajectory
from ..units import Units
from .figures import png_bytes, tracking_figure
from .files import OutputDir
from .tables import csv_text, unit_tokens

#: Every file a simulation writes.
TRACKING_FILES = ("tracking.csv", "tracking.png", "tracking.json")


def write_tracking(out: str, tr: Trajectory, res: ControlResult, units: Units,
                   control: dict[str, Any], *, force: bool = False) -> dict[str, Any]:
    """Write the simulation's files into ``out``; returns the summary (``tracking.json``)."""
    mm = units.length_mm
    u = unit_tokens(units)
    n = len(res.t)  # up to where the simulation stopped
    cols = {f"t_{u['time']}": res.t, "phi_des_rad": tr.q[:n, 0], "psi_des_rad": tr.q[:n, 1],
            "phi_rad": res.q[:, 0], "psi_rad": res.q[:, 1], "err_phi_rad": res.joint_error[:, 0],
            "err_psi_rad": res.joint_error[:, 1], "task_error_mm": res.task_error * mm,
            f"tau1_{u['torque']}": res.tau[:, 0], f"tau2_{u['torque']}": res.tau[:, 1],
            "saturated": res.saturated.astype(float)}
    summ = res.summary()
    tol_mm = None if res.tolerance is None else res.tolerance * mm
    left = res.left_at
    report = {"units": units.describe(), "control": dict(control),
              "status": res.status, "message": res.message,
              "followed": res.status == 0, "complete": res.complete, "tolerance_mm": tol_mm,
              "tolerance_note": "the task error within which the motion is followed: "
                                "[control].tolerance_mm, default 3 % of the robot's reach",
              "left_tolerance_at_s": None if left is None else float(res.t[left]
                                                                     * units.time_s),
              "max_task_error_mm": summ["max_task_error"] * mm,
              "rms_task_error_mm": summ["rms_task_error"] * mm,
              "final_task_error_mm": summ["final_task_error"] * mm,
              "max_joint_error_deg": float(np.degrees(summ["max_joint_error_rad"])),
              "saturated_fraction": summ["saturated_fraction"]}
    fig = tracking_figure(res, units, control["mass_error"], control["payload_kg"])
    with OutputDir(out, force=force, produces=TRACKING_FILES) as od:
        od.write_text("tracking.csv", csv_text(cols))
        od.write_bytes("tracking.png", png_bytes(fig))
        od.write_text("tracking.json", json.dumps(report, indent=2, default=str) + "\n")
    return report
