"""A self-contained HTML report (figures embedded as data URIs)."""

from __future__ import annotations

import base64
import html
from typing import Any

from ..analysis import Analysis

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


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        if v == 0 or (1e-3 <= abs(v) < 1e5):
            return f"{v:.6g}"
        return f"{v:.3e}"
    if isinstance(v, list):
        return ", ".join(_fmt(x) for x in v)
    if isinstance(v, dict):
        return "; ".join(f"{k} = {_fmt(x)}" for k, x in v.items())
    return html.escape(str(v))


def _table(rows: list[tuple[str, Any]], head: tuple[str, str] = ("quantity", "value")) -> str:
    body = "".join(f"<tr><td>{html.escape(k)}</td><td>{_fmt(v)}</td></tr>" for k, v in rows)
    return f"<table><tr><th>{head[0]}</th><th>{head[1]}</th></tr>{body}</table>"


def _title(s: dict[str, Any]) -> str:
    if "claims" in s:
        return "DexTAR: the paper's example, optimal motion and motor torques"
    g = s["robot"]["geometry_mm"]
    return (f"Five-bar l1 = {g['l1']:g}, l2 = {g['l2']:g}, L1 = {g['L1']:g}, L2 = {g['L2']:g}, "
            f"d = {g['d']:g} mm: {s['path']['type']} path, {s['law']['type']} law")


def render_report(an: Analysis, s: dict[str, Any], pngs: dict[str, bytes],
                  gif: bytes | None = None) -> str:
    """The run's report as one self-contained HTML page (figures and animation inline)."""
    u = s["units"]
    title = _title(s)
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>{html.escape(title)}</title><style>",
        "body{font-family:sans-serif;max-width:960px;margin:2em auto;color:#222}",
        "table{border-collapse:collapse;margin:0.5em 0 1.5em}td,th{border:1px solid #ccc;",
        "padding:3px 8px;text-align:left;font-size:14px}th{background:#eee}",
        "figure{margin:1.5em 0}img{max-width:100%}.holds{color:#060}.fails{color:#b00}",
        ".approximate{color:#a60}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
        f"<p>Config: {html.escape(str(s['config']))}. dextar {s['dextar_version']}. Units: "
        f"length {u['length_unit']}, mass {u['mass_unit']}, time {u['time_unit']}; energies "
        f"and torques in {html.escape(u['torque_unit'])}; angles in radians in the CSV.",
        f" One length unit is {u['length_unit_in_mm']:g} mm, one mass unit "
        f"{u['mass_unit_in_kg']:g} kg, one time unit {u['time_unit_in_s']:g} s.</p>",
        "<h2>Parameters</h2>",
    ]
    g = s["robot"]["geometry_mm"]
    law = s["law"]
    M, L, T = u["mass_unit"], u["length_unit"], u["time_unit"]
    E, Q = u["energy_unit"], u["torque_unit"]
    rows = [(f"{k} [mm]", v) for k, v in g.items()]
    rows += [("working mode", s["robot"]["working_mode"]),
             ("assembly mode", s["robot"]["assembly_mode"]),
             ("path", {k: v for k, v in s["path"].items()}),
             ("law", law["type"])]
    if "eta_s2_per_kg" in law:
        rows.append(("eta, weight of the inertia forces [s^2/kg]", law["eta_s2_per_kg"]))
    if "torque_limit_Nm" in law:
        rows.append(("motor torque limits (A, D) [N m]", law["torque_limit_Nm"]))
    if "speed_limit_deg_s" in law:
        rows.append(("motor speed limits (A, D) [deg/s]", law["speed_limit_deg_s"]))
    rows += [("samples written", s["output"]["samples"]),
             (f"end-effector mass [{M}]", s["inertia"]["effector_mass"]),
             (f"payload [{M}]", s["inertia"]["payload"]),
             (f"proximal rods AB, DC (mass [{M}], com [{L}], inertia [{M} {L}^2])",
              [list(r.values()) for r in s["inertia"]["proximal"]]),
             (f"distal rods BP, CP (mass [{M}], com [{L}], inertia [{M} {L}^2])",
              [list(r.values()) for r in s["inertia"]["distal"]]),
             (f"rotor inertia (A, D) [{M} {L}^2]", s["inertia"]["rotor"]),
             (f"viscous friction (A, D) [{Q} {T}/rad]", s["inertia"]["viscous"]),
             (f"Coulomb friction (A, D) [{Q}]", s["inertia"]["coulomb"]),
             (f"gravity [{L}/{T}^2]", s["inertia"]["gravity"])]
    parts.append(_table(rows))
    parts.append("<h2>Results</h2>")
    rows = [(f"motion time [{T}]", law["duration"]), ("motion time [s]", law["duration_s"]),
            ("law solver status (0 = success)", law["status"]),
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
    rows += [(f"peak |tau| exact (motor A, D) [{Q}]", s["torques"]["exact"]["peak"]),
             (f"RMS tau exact (motor A, D) [{Q}]", s["torques"]["exact"]["rms"]),
             (f"peak |power| (motor A, D) [{E}/{T}]", s["peak_power"]),
             (f"peak passive-joint forces [{M} {L}/{T}^2]", s["peak_joint_forces"])]
    if "beta0_deg" in s.get("paper_model", {}):
        pm = s["paper_model"]
        rows += [(f"peak |tau| paper (42) [{Q}]", s["torques"]["paper"]["peak"]),
                 ("beta range along the path [deg]", s["beta_range_deg"]),
                 ("beta0 [deg]", pm["beta0_deg"]),
                 (f"C1, C2, C3, C4 of (40) [{M} {L}^2]", [pm["C1"], pm["C2"], pm["C3"],
                                                         pm["C4"]]),
                 ("paper torque error: max / RMS (fraction of the peak exact torque)",
                  [pm["error_vs_exact"]["max_relative"], pm["error_vs_exact"]["rms_relative"]])]
    if "not_applicable" in s.get("paper_model", {}):
        rows.append(("paper's simplified model", "not applicable: "
                     + s["paper_model"]["not_applicable"]))
    parts.append(_table(rows))
    if "claims" in s:
        parts.append("<h2>The paper's claims against the exact model</h2><table><tr><th>claim"
                     "</th><th>measure</th><th>value</th><th>verdict</th></tr>")
        for cl in s["claims"]:
            note = f"<br><small>{html.escape(cl['note'])}</small>" if "note" in cl else ""
            parts.append(f"<tr><td>{html.escape(cl['claim'])}{note}</td><td>"
                         f"{html.escape(cl['measure'])}<br><small>"
                         f"{html.escape(cl['criterion'])}</small></td><td>{cl['value']:.3g}</td>"
                         f"<td class='{cl['verdict']}'>{cl['verdict']}</td></tr>")
        parts.append("</table>")
    v = s["validation"]
    fw = v["forward_resimulation"]
    parts.append("<h2>Validation</h2>")
    parts.append(_table([
        ("power balance: max |tau.qdot - dT/dt| / max |tau.qdot| (dimensionless; the torques "
         "against the rate of change of the exact kinetic energy, gravity and friction off)",
         v["power_balance_relative"]),
        ("forward re-simulation under the computed torques: final angle error / angle range "
         "(dimensionless)", fw["final_error_relative_to_range"]),
        ("forward re-simulation: largest angle error [rad]", fw["max_error_rad"])]))
    parts.append("<h2>Figures</h2>")
    for name, data in pngs.items():
        b64 = base64.b64encode(data).decode("ascii")
        parts.append(f"<figure><img alt='{name}' src='data:image/png;base64,{b64}'>"
                     f"<figcaption>{html.escape(_caption(name, law['type']))}</figcaption>"
                     "</figure>")
    if gif is not None:
        b64 = base64.b64encode(gif).decode("ascii")
        parts.append(f"<figure><img alt='animation' src='data:image/gif;base64,{b64}'>"
                     f"<figcaption>The robot following the path ({html.escape(law['type'])} "
                     "law).</figcaption></figure>")
    parts.append("<h2>Assumptions</h2><ul>")
    parts += [f"<li>{html.escape(a)}</li>" for a in s["assumptions"]]
    parts.append("</ul></body></html>\n")
    return "".join(parts)


def _caption(name: str, law: str) -> str:
    return CAPTIONS.get(name, name).replace("the optimal law", f"the {law} law")
