"""Writing an identification: the parameter table, the fit figure and the report (the
identified config is :func:`dextar.output.config_file.model_toml`)."""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from typing import Any

from matplotlib.figure import Figure

from .._arrays import Array
from ..identification.fit import IdentificationResult
from .config_file import toml_number as _num
from .html_page import figures, page


def parameters_csv(res: IdentificationResult) -> str:
    """``name, meaning, value, std, rel_std_percent, unit``: one row per base parameter
    (SI values)."""
    out = ["name,meaning,value,std,rel_std_percent,unit"]
    for name, meaning, unit, v, s in zip(res.base.names, res.base.meanings, res.base.units,
                                         res.beta, res.std, strict=True):
        rel = 100.0 * s / abs(v) if v != 0 else math.inf
        out.append(f'{name},"{meaning}",{_num(v)},{_num(s)},'
                   f"{_num(rel) if math.isfinite(rel) else 'inf'},{unit}")
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


def identification_report(summary: Mapping[str, Any], pngs: dict[str, bytes]) -> str:
    """The report page: the summary, the base parameters with their deviations, the fit."""
    esc = html.escape
    rows = []
    for p in summary["base_parameters"]:
        v, s = p["value"], p["std"]
        rel = f"{100.0 * s / abs(v):.3g}" if v != 0 else "inf"
        rows.append(f"<tr><td>{esc(p['name'])}</td><td>{esc(p['meaning'])}</td>"
                    f"<td>{esc(p['unit'])}</td><td>{v:.6g}</td><td>{s:.3g}</td>"
                    f"<td>{rel}</td></tr>")
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
