"""A self-contained HTML report (figures embedded as data URIs)."""

from __future__ import annotations

import html
from typing import Any

from ..analysis import Analysis
from .html_page import image, page, table

CAPTIONS = {
    "fig3": "Leading angles for uniform motion along the path (the paper's Fig. 3). The paper "
            "notes that the dependence is close to linear; the claims table measures how close.",
    "fig4": "The robot every eighth of the motion time under the optimal law (Fig. 4).",
    "fig5": "Leading angles under the optimal law (Fig. 5).",
    "fig6": "Kinetic energy of the end-effector (Fig. 6): exact, from (30) with finite "
            "differences, and from (32) with beta frozen at its mid-motion value.",
    "fig7": "Translational against rotational energy of the triangle CPB with the paper's Fig. 7 "
            "masses (Fig. 7).",
    "fig8": "Angular velocities of the driven rods under the optimal law (Fig. 8), computed "
            "analytically through the Jacobian.",
    "fig9": "Motor torques (Fig. 9): the exact closed-chain inverse dynamics (solid) against the "
            "paper's simplified formula (42) (dashed), same masses.",
    "workspace": "Workspace of the working mode: dexterity, singularity curves and the path.",
}


def _title(s: dict[str, Any]) -> str:
    if "claims" in s:
        return "DexTAR: the paper's example, optimal motion and motor torques"
    g = s["robot"]["geometry_mm"]
    return (f"Five-bar l1 = {g['l1']:g}, l2 = {g['l2']:g}, L1 = {g['L1']:g}, L2 = {g['L2']:g}, "
            f"d = {g['d']:g} mm: {s['path']['type']} path, {s['law']['type']} law")


def render_report(an: Analysis, s: dict[str, Any], pngs: dict[str, bytes],
                  gif: bytes | None = None, pace: str = "in real time") -> str:
    """The run's report as one self-contained HTML page (figures and animation inline;
    ``pace``: how the animation plays, in words)."""
    u = s["units"]
    intro = (f"<p>Config: {html.escape(str(s['config']))}. dextar {s['dextar_version']}. "
             f"Units: length {u['length_unit']}, mass {u['mass_unit']}, time "
             f"{u['time_unit']}; energies and torques in {html.escape(u['torque_unit'])}; "
             f"angles in radians in the CSV. One length unit is {u['length_unit_in_mm']:g} "
             f"mm, one mass unit {u['mass_unit_in_kg']:g} kg, one time unit "
             f"{u['time_unit_in_s']:g} s.</p>")
    body = [intro, "<h2>Parameters</h2>", table(_parameters(s)), "<h2>Results</h2>",
            table(_results(s)), _claims(s), "<h2>Validation</h2>", table(_validation(s)),
            "<h2>Figures</h2>", _figures(s, pngs, gif, pace), "<h2>Assumptions</h2><ul>",
            *(f"<li>{html.escape(a)}</li>" for a in s["assumptions"]), "</ul>"]
    return page(_title(s), "".join(body))


def _parameters(s: dict[str, Any]) -> list[tuple[str, Any]]:
    u, law, ine = s["units"], s["law"], s["inertia"]
    M, L, T, Q = u["mass_unit"], u["length_unit"], u["time_unit"], u["torque_unit"]
    rows: list[tuple[str, Any]] = [(f"{k} [mm]", v) for k, v in s["robot"]["geometry_mm"].items()]
    rows += [("working mode", s["robot"]["working_mode"]),
             ("assembly mode", s["robot"]["assembly_mode"]),
             ("path", {k: v for k, v in s["path"].items()}),
             ("law", law["type"])]
    for key, label in (("eta_s2_per_kg", "eta, weight of the inertia forces [s^2/kg]"),
                       ("torque_limit_Nm", "motor torque limits (A, D) [N m]"),
                       ("speed_limit_deg_s", "motor speed limits (A, D) [deg/s]")):
        if key in law:
            rows.append((label, law[key]))
    rows += [("samples written", s["output"]["samples"]),
             (f"end-effector mass [{M}]", ine["effector_mass"]),
             (f"payload [{M}]", ine["payload"]),
             (f"proximal rods AB, DC (mass [{M}], com [{L}], inertia [{M} {L}^2])",
              [list(r.values()) for r in ine["proximal"]]),
             (f"distal rods BP, CP (mass [{M}], com [{L}], inertia [{M} {L}^2])",
              [list(r.values()) for r in ine["distal"]]),
             (f"rotor inertia (A, D) [{M} {L}^2]", ine["rotor"]),
             (f"viscous friction (A, D) [{Q} {T}/rad]", ine["viscous"]),
             (f"Coulomb friction (A, D) [{Q}]", ine["coulomb"]),
             (f"gravity [{L}/{T}^2]", ine["gravity"])]
    return rows


def _results(s: dict[str, Any]) -> list[tuple[str, Any]]:
    u, law = s["units"], s["law"]
    M, L, T = u["mass_unit"], u["length_unit"], u["time_unit"]
    E, Q = u["energy_unit"], u["torque_unit"]
    rows: list[tuple[str, Any]] = [(f"motion time [{T}]", law["duration"])]
    if T != "s":
        rows.append(("motion time [s]", law["duration_s"]))
    rows += [("law solver status (0 = success)", law["status"]),
             ("law solver message", law["message"])]
    if "max_torque_ratio" in law:
        rows.append(("largest |torque| / limit over the written samples",
                     law["max_torque_ratio"]))
    if "cost" in s:
        c = s["cost"]
        rows += [(f"cost Phi of the optimal law (total) [{E} {T}]", c["total"]),
                 (f"kinetic part (m/2) Int |rdot|^2 dt [{E} {T}]", c["kinetic"]),
                 (f"inertial part (eta m^2/2) Int |rddot|^2 dt [{E} {T}]", c["inertial"]),
                 ("optimal-law ODE residual (relative, dimensionless)", law["ode_residual"])]
    power, force = ("W", "N") if T == "s" else (f"{E}/{T}", f"{M} {L}/{T}^2")
    rows += [(f"peak |tau| exact (motor A, D) [{Q}]", s["torques"]["exact"]["peak"]),
             (f"RMS tau exact (motor A, D) [{Q}]", s["torques"]["exact"]["rms"]),
             (f"peak |power| (motor A, D) [{power}]", s["peak_power"]),
             (f"peak passive-joint forces [{force}]", s["peak_joint_forces"])]
    pm = s.get("paper_model", {})
    if "beta0_deg" in pm:
        rows += [(f"peak |tau| paper (42) [{Q}]", s["torques"]["paper"]["peak"]),
                 ("beta range along the path [deg]", s["beta_range_deg"]),
                 ("beta0 [deg]", pm["beta0_deg"]),
                 (f"C1, C2, C3, C4 of (40) [{M} {L}^2]", [pm["C1"], pm["C2"], pm["C3"],
                                                         pm["C4"]]),
                 ("paper torque error: max / RMS (fraction of the peak exact torque; "
                  f"{pm['error_note']})",
                  [pm["error_vs_exact"]["max_relative"], pm["error_vs_exact"]["rms_relative"]])]
    if "not_applicable" in pm:
        rows.append(("paper's simplified model", "not applicable: " + pm["not_applicable"]))
    return rows


def _claims(s: dict[str, Any]) -> str:
    if "claims" not in s:
        return ""
    parts = ["<h2>The paper's claims against the exact model</h2><table><tr><th>claim</th>"
             "<th>measure</th><th>value</th><th>verdict</th></tr>"]
    for cl in s["claims"]:
        note = f"<br><small>{html.escape(cl['note'])}</small>" if "note" in cl else ""
        parts.append(f"<tr><td>{html.escape(cl['claim'])}{note}</td><td>"
                     f"{html.escape(cl['measure'])}<br><small>{html.escape(cl['criterion'])}"
                     f"</small></td><td>{cl['value']:.3g}</td><td class='{cl['verdict']}'>"
                     f"{cl['verdict']}</td></tr>")
    return "".join(parts) + "</table>"


def _validation(s: dict[str, Any]) -> list[tuple[str, Any]]:
    v = s["validation"]
    fw = v["forward_resimulation"]
    rows: list[tuple[str, Any]] = [
        ("checks", "passed" if v["passed"] else "FAILED: " + "; ".join(v["failed"])),
        ("power balance: max |tau.qdot - dT/dt| / max |tau.qdot| (dimensionless; the torques "
         "against the rate of change of the exact kinetic energy, gravity and friction off; "
         f"at most {v['power_balance_threshold']:g})", _num(v["power_balance_relative"]))]
    if "windows" in fw:
        u = s["units"]
        rows += [
            (f"forward re-simulation in {fw['windows']} windows anchored to the plan (each "
             "starts at the planned state and runs under the planned torques): largest drift "
             "at a window's end [rad]", _num(fw["max_drift_rad"])),
            (f"drift / (a_peak w^2 / 2): the accelerations' error as a fraction of the peak "
             f"joint acceleration {fw['peak_acceleration']:.4g} rad/{u['time_unit']}^2 "
             f"(at most {fw['threshold']:g}), worst window {fw['worst_window']}",
             _num(fw["max_drift_ratio"])),
            ("drift per window [rad]", " ".join(_num(d) for d in fw["drift_rad"]))]
    rows.append(("forward re-simulation", fw["message"]))
    return rows


def _num(v: float | None) -> str:
    """A figure in three digits, or "-" where it could not be computed."""
    return "-" if v is None else f"{v:.3g}"


def _figures(s: dict[str, Any], pngs: dict[str, bytes], gif: bytes | None, pace: str
             ) -> str:
    law = s["law"]["type"]
    parts = [image(data, name, _caption(name, law)) for name, data in pngs.items()]
    if gif is not None:
        parts.append(image(gif, "animation",
                           f"The robot following the path ({law} law), {html.escape(pace)}.",
                           mime="image/gif"))
    return "".join(parts)


def _caption(name: str, law: str) -> str:
    return CAPTIONS.get(name, name).replace("the optimal law", f"the {law} law")
