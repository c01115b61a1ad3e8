"""Writing an identification: the identified config (TOML in config units), the parameter
table, the fit figure and the report."""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from typing import Any

from matplotlib.figure import Figure

from .._arrays import Array
from ..dynamics import Inertia
from ..errors import NumericalError
from ..geometry import FiveBar
from ..identification.fit import IdentificationResult
from .html_page import figures, page


def _num(v: float) -> str:
    v = float(v)
    if not math.isfinite(v):
        raise NumericalError(f"identified value {v!r} is not finite")
    return repr(v)


def _pair(a: float, b: float) -> str:
    return f"[{_num(a)}, {_num(b)}]"


def identified_toml(robot_mm: FiveBar, working_mode: str, assembly_mode: str, inertia: Inertia,
                    *, coulomb_speed_deg_s: float, gravity_mm_s2: tuple[float, float],
                    extra: Mapping[str, Mapping[str, Any]] | None = None,
                    comment: str = "") -> str:
    """A config with ``[robot]``, ``[inertia]``, ``[friction]``, ``[gravity]`` (and the
    tables of ``extra`` as given) whose model is ``inertia`` (SI) on ``robot_mm``; values in
    config units (mm, kg, kg mm^2, N m, N m s/rad), written to 17 digits."""
    p1, p2 = inertia.proximal
    d1, d2 = inertia.distal
    kgmm2 = 1e6
    lines = [f"# {line}" for line in comment.splitlines()] + [
        "",
        "[robot]",
        *(f"{k} = {_num(v)}" for k, v in robot_mm.as_dict().items()),
        f'working_mode = "{working_mode}"',
        f'assembly_mode = "{assembly_mode}"',
        "",
        "[inertia]            # kg, mm, kg mm^2",
        f"effector_mass = {_num(inertia.effector_mass)}",
        f"payload = {_num(inertia.payload)}",
        f"proximal_mass = {_pair(p1.mass, p2.mass)}",
        f"proximal_com = {_pair(p1.com * 1e3, p2.com * 1e3)}",
        f"proximal_inertia = {_pair(p1.inertia * kgmm2, p2.inertia * kgmm2)}",
        f"distal_mass = {_pair(d1.mass, d2.mass)}",
        f"distal_com = {_pair(d1.com * 1e3, d2.com * 1e3)}",
        f"distal_inertia = {_pair(d1.inertia * kgmm2, d2.inertia * kgmm2)}",
        f"rotor_inertia = {_pair(inertia.rotor[0] * kgmm2, inertia.rotor[1] * kgmm2)}",
        "",
        "[friction]           # N m s/rad, N m, deg/s",
        f"viscous = {_pair(*inertia.viscous)}",
        f"coulomb = {_pair(*inertia.coulomb)}",
        f"coulomb_speed_deg_s = {_num(coulomb_speed_deg_s)}",
        "",
        "[gravity]            # mm/s^2",
        f"vector = {_pair(*gravity_mm_s2)}",
    ]
    for name, table in (extra or {}).items():
        lines += ["", f"[{name}]"]
        for k, v in table.items():
            if isinstance(v, (list, tuple)):
                lines.append(f"{k} = [{', '.join(_num(x) for x in v)}]")
            elif isinstance(v, str):
                lines.append(f'{k} = "{v}"')
            else:
                lines.append(f"{k} = {_num(v)}")
    return "\n".join(lines) + "\n"


def parameters_csv(res: IdentificationResult) -> str:
    """``name, meaning, unit, value, std, rel_std_percent``: one row per base parameter."""
    out = ["name,meaning,unit,value,std,rel_std_percent"]
    for name, meaning, unit, v, s in zip(res.base.names, res.base.meanings, res.base.units,
                                         res.beta, res.std, strict=True):
        rel = 100.0 * s / abs(v) if v != 0 else math.inf
        out.append(f'{name},"{meaning}",{unit},{_num(v)},{_num(s)},'
                   f"{_num(rel) if math.isfinite(rel) else 'inf'}")
    return "\n".join(out) + "\n"


def fit_figure(panels: Sequence[tuple[str, Array, Array, Array]]) -> Figure:
    """Measured against predicted torques and their residuals; one column per data set
    ``(title, t (m,), measured (m, 2), predicted (m, 2))``."""
    fig = Figure(figsize=(5.2 * len(panels), 6.4))
    axes = fig.subplots(3, len(panels), squeeze=False, sharex="col")
    for j, (title, t, meas, pred) in enumerate(panels):
        for k, name in enumerate(("motor A", "motor D")):
            ax = axes[k, j]
            ax.plot(t, meas[:, k], lw=1.0, label="measured (filtered)")
            ax.plot(t, pred[:, k], lw=1.0, ls="--", label="predicted")
            ax.set_ylabel(f"{name} torque [N m]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        axes[0, j].set_title(title)
        ax = axes[2, j]
        for k, name in enumerate(("motor A", "motor D")):
            ax.plot(t, meas[:, k] - pred[:, k], lw=0.8, label=name)
        ax.set_ylabel("residual [N m]")
        ax.set_xlabel("t [s]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def identification_report(summary: Mapping[str, Any], csv_rows: str,
                          pngs: dict[str, bytes]) -> str:
    """The report page: the summary, the base parameters with their deviations, the fit."""
    esc = html.escape
    rows = []
    for line in csv_rows.splitlines()[1:]:
        name, rest = line.split(",", 1)
        meaning, tail = rest[1:].split('",', 1)
        unit, value, std, rel = tail.split(",")
        rows.append(f"<tr><td>{esc(name)}</td><td>{esc(meaning)}</td><td>{esc(unit)}</td>"
                    f"<td>{float(value):.6g}</td><td>{float(std):.3g}</td>"
                    f"<td>{esc(rel if rel == 'inf' else f'{float(rel):.3g}')}</td></tr>")
    facts = [("status", summary["status"]), ("message", summary["message"]),
             ("method", summary["method"]), ("samples read / used",
                                             f"{summary['n_samples']} / {summary['n_used']}"),
             ("cut-off [Hz]", f"{summary['cutoff_hz']:.4g}"),
             ("condition number", f"{summary['condition_number']:.4g}"),
             ("RMS residual [N m]", ", ".join(f"{v:.4g}" for v in summary["rms_residual_Nm"]))]
    if "validation_rms_error_Nm" in summary:
        facts += [("validation RMS error, identified [N m]",
                   ", ".join(f"{v:.4g}" for v in summary["validation_rms_error_Nm"])),
                  ("validation RMS error, prior [N m]",
                   ", ".join(f"{v:.4g}" for v in summary["validation_rms_error_prior_Nm"])),
                  ("validation RMS torque [N m]",
                   ", ".join(f"{v:.4g}" for v in summary["validation_rms_torque_Nm"]))]
    fact_rows = "".join(f"<tr><td>{esc(k)}</td><td>{esc(str(v))}</td></tr>" for k, v in facts)
    warn = "".join(f"<li>{esc(w)}</li>" for w in summary["warnings"]) or "<li>none</li>"
    return page(
        f"dextar identify {summary['data']}",
        f"<h1>Identification from {esc(str(summary['data']))}</h1>"
        f"<table>{fact_rows}</table><h2>Warnings</h2><ul>{warn}</ul>"
        "<h2>Base parameters</h2><p>Each a combination of standard parameters (SI); the "
        "standard deviations account for the correlation the low-pass leaves in the "
        "residuals.</p><table><tr><th>name</th><th>meaning</th><th>unit</th><th>value</th>"
        f"<th>std</th><th>std [%]</th></tr>{''.join(rows)}</table>"
        f"<h2>Fit</h2>{figures(pngs)}")
