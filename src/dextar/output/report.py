"""A self-contained HTML report (figures embedded as data URIs)."""

from __future__ import annotations

import base64
import html
from typing import Any

from ..analysis import Analysis

CAPTIONS = {
    "fig3": "Leading angles for uniform motion along the path (the paper's Fig. 3). The paper "
            "notes that the dependence is close to linear; the claims table measures how close.",
    "fig4": "The robot every T/8 under the optimal law (Fig. 4): the end-effector slows down at "
            "both ends.",
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


def render_report(an: Analysis, s: dict[str, Any], pngs: dict[str, bytes]) -> str:
    u = s["units"]
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        "<title>dextar report</title><style>",
        "body{font-family:sans-serif;max-width:960px;margin:2em auto;color:#222}",
        "table{border-collapse:collapse;margin:0.5em 0 1.5em}td,th{border:1px solid #ccc;",
        "padding:3px 8px;text-align:left;font-size:14px}th{background:#eee}",
        "figure{margin:1.5em 0}img{max-width:100%}.holds{color:#060}.fails{color:#b00}",
        ".approximate{color:#a60}</style></head><body>",
        "<h1>DexTAR: optimal motion and motor torques</h1>",
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
             ("law", law["type"]), (f"duration [{T}]", law["duration"]),
             ("eta [s^2/kg]", law["eta_s2_per_kg"]), ("samples", s["samples"]),
             (f"end-effector mass [{M}]", s["inertia"]["effector_mass"]),
             (f"payload [{M}]", s["inertia"]["payload"]),
             (f"proximal rods AB, DC (mass [{M}], com [{L}], inertia [{M} {L}^2])",
              [list(r.values()) for r in s["inertia"]["proximal"]]),
             (f"distal rods BP, CP (mass [{M}], com [{L}], inertia [{M} {L}^2])",
              [list(r.values()) for r in s["inertia"]["distal"]]),
             (f"rotor inertia [{M} {L}^2]", s["inertia"]["rotor"]),
             (f"gravity [{L}/{T}^2]", s["inertia"]["gravity"])]
    parts.append(_table(rows))
    parts.append("<h2>Results</h2>")
    c = s["cost"]
    rows = [(f"cost Phi (total) [{E} {T}]", c["total"]), ("kinetic part", c["kinetic"]),
            ("inertial part", c["inertial"]),
            (f"peak |tau| exact (motor A, D) [{Q}]", s["torques"]["exact"]["peak"]),
            (f"RMS tau exact (motor A, D) [{Q}]", s["torques"]["exact"]["rms"]),
            (f"peak |power| (motor A, D) [{E}/{T}]", s["peak_power"]),
            (f"peak passive-joint forces [{M} {L}/{T}^2]", s["peak_joint_forces"])]
    if "optimal_law_solver" in s:
        rows.append(("optimal-law ODE residual", s["optimal_law_solver"]["residual"]))
    if "beta0_deg" in s.get("paper_model", {}):
        pm = s["paper_model"]
        rows += [(f"peak |tau| paper (42) [{Q}]", s["torques"]["paper"]["peak"]),
                 ("beta range along the path [deg]", s["beta_range_deg"]),
                 ("beta0 [deg]", pm["beta0_deg"]),
                 ("C1, C2, C3, C4", [pm["C1"], pm["C2"], pm["C3"], pm["C4"]]),
                 ("paper torque error: max / RMS (relative to peak)",
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
        ("power balance max |tau.qdot - dT/dt| / max |tau.qdot|", v["power_balance_relative"]),
        ("forward re-simulation: final error / angle range",
         fw["final_error_relative_to_range"]),
        ("forward re-simulation: max error [rad]", fw["max_error_rad"])]))
    parts.append("<h2>Figures</h2>")
    for name, data in pngs.items():
        b64 = base64.b64encode(data).decode("ascii")
        parts.append(f"<figure><img alt='{name}' src='data:image/png;base64,{b64}'>"
                     f"<figcaption>{html.escape(CAPTIONS.get(name, name))}</figcaption></figure>")
    parts.append("<h2>Assumptions</h2><ul>")
    parts += [f"<li>{html.escape(a)}</li>" for a in s["assumptions"]]
    parts.append("</ul></body></html>\n")
    return "".join(parts)
