"""What a run computed and claims, as one JSON-ready summary: the law used, torques, powers,
joint forces, the physics checks, and the paper's claims with their criteria and verdicts."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import __version__
from .._arrays import Array
from ..dynamics import Inertia
from ..dynamics.paper import paper_model_limits
from ..errors import DextarError
from ..geometry import DEXTAR_MM
from ..laws import LAW_TYPES, Law, law_type
from ..trajectory import Trajectory
from .core import (
    POWER_BALANCE_TOL,
    STEP_DEPENDENCE,
    Analysis,
    PaperComparison,
    RunInputs,
    forward_error,
    power_balance_residuals,
    torque_limit_ratio,
)


def validation(an: Analysis) -> dict[str, Any]:
    """The physics checks of a run, each reported with its figure, its threshold and whether
    it passed (a check that fails, or cannot run, is a result: ``passed`` false and the
    reason in ``failed``): the power balance (:data:`~.core.POWER_BALANCE_TOL`) and the
    forward re-simulation in windows anchored to the plan (:data:`~.core.REPLAY_TOL`)."""
    out: dict[str, Any] = {"forward_resimulation": forward_error(an)}
    failed = []
    if not out["forward_resimulation"]["passed"]:
        failed.append(f"forward re-simulation: {out['forward_resimulation']['message']}")
    try:
        steps = power_balance_residuals(an)
    except DextarError as exc:
        pb: float | None = None
        failed.append(f"power balance: it could not be computed: {exc}")
    else:
        pb = min(steps)
        said = (f"power balance: max |tau.qdot - dT/dt| / max |tau.qdot| = {pb:.3g} above "
                f"{POWER_BALANCE_TOL:g}")
        if not pb <= POWER_BALANCE_TOL and not (
                max(steps) <= STEP_DEPENDENCE * pb):  # (NaN: not measured either)
            failed.append(f"{said}, changing with the differences' step ("
                          + ", ".join(f"{v:.3g}" for v in steps)
                          + " at h, h/4, h/16): the motion is too fast for the check to "
                          "measure the kinetic energy's rate; the torques are not shown wrong")
        elif not pb <= POWER_BALANCE_TOL:
            failed.append(f"{said} at every step of the differences: the torques do not "
                          "match the kinetic energy's rate")
    out["power_balance_relative"] = pb if pb is None or math.isfinite(pb) else None
    out["power_balance_threshold"] = POWER_BALANCE_TOL
    out["power_balance_note"] = (
        "max |tau.qdot - dT/dt| / max |tau.qdot| (dimensionless) on interior times clear of "
        "the law's breakpoints, dT/dt by 8th-order differences of the exact kinetic energy, "
        "gravity and friction off; it checks the torques against the energy")
    out["passed"] = not failed
    out["failed"] = failed
    return out


def is_paper_example(sc: RunInputs) -> bool:
    """The paper's numerical example: the DexTAR, the semicircle R = 120 mm about O from 0 to
    180 deg, the optimal law, in working mode "+-" (the claims table is about it)."""
    return (sc.robot_mm == DEXTAR_MM and sc.mode == "+-" and sc.law_type == "optimal"
            and sc.path_spec == {"type": "arc", "radius_mm": 120.0, "center_mm": [0.0, 0.0],
                                 "start_deg": 0.0, "end_deg": 180.0})


def law_summary(sc: RunInputs, law: Law, an: Analysis | None = None) -> dict[str, Any]:
    """The law actually used: its type, its one duration (run time unit and seconds), the
    solver's status and message, its own quantities (:meth:`~dextar.laws.Law.report`) and
    its config keys as given (each named with its config unit, ``eta_s2_per_kg``)."""
    out: dict[str, Any] = {"type": law.name, "duration": law.duration,
                           "duration_s": law.duration * sc.units.time_s,
                           "status": int(law.status), "success": bool(law.success),
                           "message": law.message, **law.report(sc.units)}
    params = law_type(law.name).params if law.name in LAW_TYPES else {}
    for key, value in sc.law_values.items():
        p = params.get(key)
        if p is None or key == "duration" or value is None:
            continue
        out[_with_unit(key, p.unit)] = list(value) if isinstance(value, tuple) else value
    if an is not None and law.torque_limit is not None:
        out["max_torque_ratio"] = torque_limit_ratio(an)
    return out


#: Config units as they end a JSON key.
_UNIT_SUFFIX = {"s^2/kg": "s2_per_kg", "N m": "Nm", "mm/s": "mm_s", "mm/s^2": "mm_s2",
                "mm": "mm", "deg": "deg", "deg/s": "deg_s", "s": "s", "kg": "kg", "rpm": "rpm"}


def _with_unit(key: str, unit: str) -> str:
    """``eta`` in s^2/kg -> ``eta_s2_per_kg``; a key that already says its unit, or has
    none, as it is."""
    suffix = _UNIT_SUFFIX.get(unit, "")
    return key if not suffix or key.endswith("_" + suffix) else f"{key}_{suffix}"


def _stats(tau: Array) -> dict[str, list[float]]:
    return {"peak": [float(v) for v in np.abs(tau).max(axis=0)],
            "rms": [float(v) for v in np.sqrt(np.mean(tau**2, axis=0))]}


#: What a run assumes where the config is silent.
ASSUMPTIONS = [
    "rods are uniform unless the config says otherwise (com at mid-length, I = m L^2/12)",
    "the end-effector is a point mass at P; no rotor inertia, friction or gravity unless "
    "configured",
    "beta0 is the base angle of triangle CPB at t = T/2 (the paper's middle position)",
    "the paper's (23) and (30) are used with d/l in the bracket; the sign of the beta-dot "
    "term in (30) follows (28)",
    "T_fd uses second-order central differences of the sampled angles",
    "Coulomb friction is regularised, coulomb * tanh(qdot / coulomb_speed): zero at rest",
]


def run_summary(an: Analysis, checks: dict[str, Any] | None, uniform: Trajectory
                ) -> dict[str, Any]:
    """Everything a run computed and claims, JSON-ready: parameters, the law, torques,
    powers, joint forces, the physics checks (:func:`validation`; None: to be set by the
    caller, as ``dextar run`` does beside its figures) and, for the paper's example, its
    claims (``uniform``: the uniform law sampled for the Fig. 3 claim)."""
    sc, law, tr = an.inputs, an.law, an.trajectory
    s: dict[str, Any] = {
        "dextar_version": __version__,
        "config": sc.source,
        "units": sc.units.describe(),
        "robot": {"geometry_mm": sc.robot_mm.as_dict(), "geometry": sc.robot.as_dict(),
                  "working_mode": tr.mode, "assembly_mode": tr.assembly},
        "path": {**sc.path_spec, "length": sc.path.length},
        "law": law_summary(sc, law, an),
        "inertia": _inertia(sc.inertia),
        "output": {"samples": int(tr.t.size)},
        "torques": {"exact": _stats(an.tau)},
        "peak_power": [float(v) for v in np.abs(an.power).max(axis=0)],
        "peak_joint_forces": {k: float(v.max()) for k, v in an.reaction_magnitudes().items()},
        "validation": checks,
        "assumptions": ASSUMPTIONS,
    }
    cost = law.cost_report()
    if cost is not None:  # the paper's functional belongs to the paper's law
        s["cost"] = {**cost, "unit": f"{sc.units.names['energy']} x {sc.units.names['time']}",
                     "definition": "Phi = (m/2) Int |rdot|^2 dt + (eta m^2/2) Int |rddot|^2 dt"}
    if an.paper is None:
        s["paper_model"] = {"not_applicable": paper_model_limits(sc.robot, sc.inertia)}
    else:
        s.update(_paper(an.paper))
        s["torques"]["paper"] = _stats(an.paper.tau)
        if is_paper_example(sc):
            s["claims"] = _claims(s, uniform)
    return s


def _inertia(ine: Inertia) -> dict[str, Any]:
    out: dict[str, Any] = {
        "effector_mass": ine.effector_mass, "payload": ine.payload,
        "proximal": [vars(r) for r in ine.proximal], "distal": [vars(r) for r in ine.distal],
        "rotor": list(ine.rotor), "viscous": list(ine.viscous), "coulomb": list(ine.coulomb),
        "gravity": list(ine.gravity), "coulomb_speed": ine.coulomb_speed,
        "note": "rods: mass, com (distance from the proximal joint), inertia about the com"}
    if ine.has_counterweights:
        out["counterweights"] = [vars(c) for c in ine.counterweights]
        out["note"] += ("; the proximal rods include their counterweights (mass, distance "
                        "behind the motor axis, inertia about their centre)")
    return out


def _paper(p: PaperComparison) -> dict[str, Any]:
    """The paper's model beside the exact one: its constants, its torque error, the energy
    comparisons of Figs. 6 and 7."""
    pm = p.model
    peakT = float(p.T_exact.max())
    return {
        "paper_model": {
            "beta0_deg": math.degrees(pm.beta0), "lambda": pm.lam, "C1": pm.C1, "C2": pm.C2,
            "C3": pm.C3, "C4": pm.C4, "error_vs_exact": p.error,
            "leaves_out": list(p.leaves_out),
            "error_note": ("against the exact torques without "
                           f"{' and '.join(p.leaves_out)}, which (42) leaves out"
                           if p.leaves_out else "against the exact torques")},
        "beta_range_deg": [float(np.degrees(p.beta.min())), float(np.degrees(p.beta.max()))],
        "energies": {
            "T_fd_vs_exact_max_relative": float(np.abs(p.T_fd - p.T_exact).max() / peakT),
            "T_approx_vs_exact_max_relative": float(np.abs(p.T_approx - p.T_exact).max() / peakT),
            "fig7": {**p.fig7, "peak_T_P_plus_T_S": float((p.T_exact + p.T_S).max()),
                     "peak_T_r": float(p.T_r.max()),
                     "ratio": float(p.T_r.max() / (p.T_exact + p.T_S).max())}}}


def _verdict(value: float, holds: float, approximate: float) -> dict[str, Any]:
    verdict = "holds" if value < holds else "approximate" if value < approximate else "fails"
    return {"value": value, "verdict": verdict,
            "criterion": f"holds below {holds:g}, approximate below {approximate:g}"}


def _claims(s: dict[str, Any], uni: Trajectory) -> list[dict[str, Any]]:
    """The paper's claims against the exact model, each with its measure, the criterion and a
    verdict."""
    e = s["energies"]
    err = s["paper_model"]["error_vs_exact"]
    beta = s["beta_range_deg"]
    dev = 0.0
    for k in range(2):
        fit = np.polyval(np.polyfit(uni.t, uni.q[:, k], 1), uni.t)
        dev = max(dev, float(np.abs(uni.q[:, k] - fit).max() / np.ptp(uni.q[:, k])))
    return [
        {"claim": "Under uniform motion the leading angles are close to linear in time (Fig. 3)",
         "measure": "max deviation from the best straight line / angle range",
         **_verdict(dev, 0.05, 0.15)},
        {"claim": "Neglecting the change of beta leaves the end-effector's kinetic energy "
                  "almost unchanged (Fig. 6)",
         "measure": "max |T_approx - T_exact| / max T_exact",
         **_verdict(e["T_approx_vs_exact_max_relative"], 0.02, 0.1),
         "note": f"beta varies from {beta[0]:.1f} to {beta[1]:.1f} deg along the path"},
        {"claim": "Finite differences on (30) reproduce the exact energy (Fig. 6)",
         "measure": "max |T_fd - T_exact| / max T_exact",
         **_verdict(e["T_fd_vs_exact_max_relative"], 1e-3, 1e-2)},
        {"claim": "The rotational energy of the triangle CPB can be neglected (Fig. 7)",
         "measure": "peak T_r / peak (T_P + T_S)", **_verdict(e["fig7"]["ratio"], 0.05, 0.15)},
        {"claim": "The simplified torques (42) give the motor torques (Fig. 9)",
         "measure": "max |tau_paper - tau_exact| / peak |tau_exact|",
         **_verdict(err["max_relative"], 0.05, 0.15),
         "note": f"RMS error {err['rms_relative']:.1%} of the peak torque"},
    ]
