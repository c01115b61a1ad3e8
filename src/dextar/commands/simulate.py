"""``dextar simulate``: computed-torque tracking of the configured motion by a perturbed
plant; the tracking, the torques against the limit and a summary."""

from __future__ import annotations

import argparse

from .base import Result, config_argument, into_directory, shown, with_notes

NAME = "simulate"
HELP = ("computed-torque tracking against a perturbed plant (exit 1 when the robot leaves "
        "[control].tolerance_mm, the files written)")
REGISTRIES_HELP = True


def add_arguments(sp: argparse.ArgumentParser) -> None:
    """``[config]``, ``--out``, ``--force``, ``--quiet``, ``--json``."""
    config_argument(sp)
    into_directory(sp, default="dextar-sim")


def run(args: argparse.Namespace) -> Result:
    """The command, with the config's notes (:func:`.base.with_notes`)."""
    return with_notes(NAME, args, _run)


def _run(args: argparse.Namespace) -> Result:
    """Simulate, write the files, word the errors and the saturation."""
    from ..config import load_scenario
    from ..dynamics import Model
    from ..output.simulation import TRACKING_FILES, write_tracking
    from ..simulation import simulate_computed_torque

    sc = load_scenario(args.config, model=args.model)
    tr = sc.trajectory()
    c = sc.control
    plant_inertia = sc.inertia.scaled_masses(1.0 + c["mass_error"])
    plant_inertia = plant_inertia.with_(payload=plant_inertia.payload + c["payload"])
    res = simulate_computed_torque(
        tr, Model(sc.robot, sc.inertia, tr.assembly), Model(sc.robot, plant_inertia,
                                                            tr.assembly),
        natural_frequency=c["natural_frequency"], damping=c["damping"],
        torque_limit=c["torque_limit"], initial_error=c["initial_error"],
        tolerance=c["tolerance"], time_s=sc.units.time_s, length_mm=sc.units.length_mm)
    report = write_tracking(args.out, tr, res, sc.units, c, force=args.force)
    warnings = []
    saturated = report["saturated_fraction"]
    if res.status == 1:
        warnings.append(f"dextar simulate: the controlled robot left the motion at "
                        f"{sc.units.time_text(res.t[-1])} of {tr.t[-1] * sc.units.time_s:.6g} "
                        f"s ({res.message}) after the torque limit saturated a motor during "
                        f"{saturated:.1%} of it; the files hold the motion up to there")
    elif res.status == 2:
        why = (f"; the torque limit {c['torque_limit_nm']:g} N m saturated a motor during "
               f"{saturated:.1%} of the motion" if saturated > 0 else "")
        warnings.append(f"dextar simulate: not followed: {res.message}{why}")
    elif saturated > 0:
        warnings.append(f"dextar simulate: warning: the torque limit {c['torque_limit_nm']:g} "
                        f"N m saturates a motor during {saturated:.1%} of the motion; it was "
                        f"followed within {report['tolerance_mm']:.4g} mm all the same")
    files = ", ".join(shown(args.out, n) for n in TRACKING_FILES)
    verdict = "followed" if res.status == 0 else "NOT FOLLOWED"
    return Result(report, f"wrote {files}: {verdict} (tolerance {report['tolerance_mm']:.4g} "
                  f"mm): max task error {report['max_task_error_mm']:.4g} mm, max joint error "
                  f"{report['max_joint_error_deg']:.4g} deg, torque saturated "
                  f"{saturated:.1%} of the time", warnings, code=0 if res.success else 1)
