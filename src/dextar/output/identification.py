"""Writing an identification and an exciting trajectory: the summary, the parameter table,
the fit figure and the report (the identified config is
:func:`dextar.output.config_file.model_toml`), the exciting trajectory's samples."""

from __future__ import annotations

import html
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..dynamics import Model, inverse_dynamics
from ..dynamics.regressor import NAMES
from ..identification.data import MotionData
from ..identification.excite import (
    COND_CEILING,
    REFERENCE_WORDS,
    ExcitationResult,
    coverage_floors,
)
from ..identification.fit import (
    RESIDUAL_FACTOR,
    UNCERTAINTY_LIMIT,
    IdentificationResult,
    Validation,
)
from ..identification.fit import validate as validate_fit
from .config_file import toml_number as _num
from .figures import png_bytes
from .files import OutputDir
from .html_page import figures, page

if TYPE_CHECKING:  # the real module; at run time matplotlib is imported where first used
    import matplotlib.figure as mfigure
    from matplotlib.figure import Figure
else:
    mfigure = lazy_module("matplotlib.figure")



def excitation_columns(model: Model, res: ExcitationResult, rate: float) -> dict[str, Array]:
    """An exciting trajectory's samples at ``rate`` (Hz) with the model's torques (SI)."""
    n = int(round(res.duration * rate)) + 1
    t = np.arange(n) / rate
    q, dq, ddq = res.trajectory.evaluate(t)
    tau = inverse_dynamics(model, q, dq, ddq, t=t)
    return {"t_s": t, "phi_rad": q[:, 0], "psi_rad": q[:, 1], "dphi_rad_s": dq[:, 0],
            "dpsi_rad_s": dq[:, 1], "ddphi_rad_s2": ddq[:, 0], "ddpsi_rad_s2": ddq[:, 1],
            "tau1_Nm": tau[:, 0], "tau2_Nm": tau[:, 1]}


def excitation_payload(res: ExcitationResult, harmonics: int, base_hz: float, samples: int,
                       rate: float, out: str) -> dict[str, Any]:
    """What ``dextar excite`` reports (JSON)."""
    return {"condition_number": res.condition_number, "duration_s": res.duration,
            "periods": res.periods, "period_s": res.trajectory.period,
            "harmonics": harmonics, "base_hz": base_hz, "samples": samples, "rate_hz": rate,
            "rest_pose_deg": [float(v) for v in np.degrees(res.trajectory.q0)],
            "min_type1_distance": res.min_type1_distance,
            "min_type2_distance": res.min_type2_distance,
            "peak_torque_Nm": [float(v) for v in res.peak_torque],
            "peak_speed_rad_s": [float(v) for v in res.peak_speed],
            "status": res.status, "message": res.message, "out": out,
            "headroom": [float(v) for v in res.headroom],
            "headroom_note": "each motor's peak use of its torque (at its speed) and speed",
            "attempts": res.attempts,
            **({} if res.coverage is None else {"coverage": _coverage(res)}),
            **({} if math.isnan(res.region_coverage) else {
                "task_coverage": res.region_coverage,
                "task_speed_ratio": [float(v) for v in res.region_speed_ratio]})}


def _coverage(res: ExcitationResult) -> dict[str, Any]:
    """The excitation's coverage against its advisory floors (JSON)."""
    c = res.coverage
    assert c is not None
    ref = c.reference
    return {"floors": {**coverage_floors(), "condition_number": COND_CEILING},
            "advisory": True,
            "range_deg": [float(v) for v in np.degrees(c.range)],
            "reference_range_deg": [float(v) for v in np.degrees(ref.range)],
            "peak_speed_rad_s": [float(v) for v in c.speed],
            "reference_speed_rad_s": [float(v) for v in ref.speed],
            "rated_speed_rad_s": [_finite(v) for v in ref.rated_speed],
            "speed_of_rated": [_finite(v) for v in c.rated_fraction],
            "peak_acceleration_rad_s2": [float(v) for v in c.acceleration],
            "reference_acceleration_rad_s2": [float(v) for v in ref.acceleration],
            "fractions": {k: [float(x) for x in v] for k, v in c.fractions.items()},
            "met": c.met, "missed": list(c.missed),
            "note": f"each motor's range, peak speed and peak acceleration over a reference "
                    f"(the range: {ref.range_of}; the speed and acceleration: the top "
                    "harmonic sweeping that range, capped by the motors), which a motion of "
                    "both motors may exceed; the peak speed also over the motors' rated "
                    "speed. The floors are advisory (a design below them is made again from "
                    "new deterministic starts, then kept with a warning): identify's verdict "
                    "tells whether the data fix the model"}


def coverage_text(res: ExcitationResult, task: bool) -> str:
    """The excitation's coverage in words (``dextar excite``'s summary)."""
    c = res.coverage
    assert c is not None
    fr, ref = c.fractions, c.reference

    def two(x: Array, fmt: str) -> str:
        return " / ".join(format(float(v), fmt) for v in x)

    rated = ("" if not np.isfinite(c.rated_fraction).all() else
             f"; {two(100 * c.rated_fraction, '.3g')} % of the rated "
             f"{two(ref.rated_speed, '.3g')} rad/s")
    floors = " / ".join(f"{100 * v:g}" for v in coverage_floors().values())
    return (f"coverage, motor A / D: range {two(np.degrees(c.range), '.3g')} deg "
            f"({two(100 * fr['range'], '.3g')} % of {'the task' if task else 'each motor'}'s "
            f"{'range' if task else 'free range from the rest pose, the other at rest'}), "
            f"peak speed {two(c.speed, '.3g')} rad/s ({two(100 * fr['speed'], '.3g')} % of "
            f"{REFERENCE_WORDS['speed']}{rated}), peak acceleration "
            f"{two(c.acceleration, '.3g')} rad/s^2 ({two(100 * fr['acceleration'], '.3g')} % "
            f"of {REFERENCE_WORDS['acceleration']}); advisory floors {floors} %, "
            f"{res.attempts} design{'s' if res.attempts > 1 else ''}")


def _finite(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def _rms(x: Array) -> list[float]:
    return [float(v) for v in np.sqrt((x ** 2).mean(axis=0))]


@dataclass(frozen=True)
class IdentificationReport:
    """An identification as written: the summary (``summary.json``), the result and the
    fit figure's panels ``(title, t, measured, predicted)``."""

    summary: dict[str, Any]
    result: IdentificationResult
    panels: tuple[tuple[str, Array, Array, Array], ...]
    validation: Validation | None = None

    @classmethod
    def of(cls, res: IdentificationResult, data: MotionData, model: Model, mode: str,
           data_path: str, config: str | None, vdata: MotionData | None = None,
           validate: str | None = None) -> IdentificationReport:
        """The summary of ``res`` (and of its prediction of ``vdata`` when given)."""
        c = res.conditioned
        if c is None:
            raise ValueError("an identification result without its conditioned data")
        summary: dict[str, Any] = {
            "status": res.status_text, "status_code": res.status,
            "message": res.message, "method": res.method, "data": data_path,
            "config": config or "defaults", "n_samples": res.n_samples, "n_used": res.n_used,
            "rows_used": [int(v) for v in res.rows_used],
            "sample_rate_hz": data.rate_hz, "cutoff_hz": res.cutoff_hz,
            "parallel_cutoff_hz": res.parallel_hz,
            "condition_number": res.condition_number,
            "rms_residual_Nm": [float(v) for v in res.rms_residual],
            "fit_quality": [float(v) for v in res.fit_quality],
            "fit_quality_note": "RMS residual / RMS torque per motor (motor A, motor D)",
            "torque_scale": [float(v) for v in res.torque_scale],
            "torque_noise_Nm": [float(v) for v in res.torque_noise],
            "explained_fit_quality": [float(v) for v in res.explained_quality],
            "explained_fit_quality_note": (
                "the fit quality the torques' noise (after the parallel filter) and the "
                f"filters explain; a poor fit beyond {RESIDUAL_FACTOR:g}x it"),
            "prediction_uncertainty": [_finite(v) for v in res.uncertainty],
            "prediction_uncertainty_reference": res.reference,
            "prediction_uncertainty_limit": UNCERTAINTY_LIMIT,
            "prediction_uncertainty_note": (
                "RMS standard deviation of the torques predicted along the reference over "
                "their RMS, per motor (the parameters' covariance propagated; 1 sigma). "
                "Without --task the reference is the recorded motion, its poses and speeds "
                "named: the verdict covers motions like it; elsewhere a prediction "
                "extrapolates (--task measures the uncertainty along the motion the model "
                "is for, --validate names the samples of another motion outside)"),
            "reasons": list(res.reasons),
            "unphysical_distance_sigmas": res.unphysical_distance,
            "poorly_determined": list(res.poorly_determined),
            "base_parameters": [{"name": n, "meaning": m, "unit": u, "value": float(v),
                                 "std": float(s),
                                 "rel_std": float(r) if math.isfinite(r) else None,
                                 "poorly_determined": n in res.poorly_determined}
                                for n, m, u, v, s, r in zip(res.base.names, res.base.meanings,
                                                            res.base.units, res.beta, res.std,
                                                            res.rel_std, strict=True)],
            "unidentifiable": [NAMES[j] for j in res.base.unidentifiable],
            "physically_consistent": res.consistent, "warnings": list(res.warnings),
            "units": "SI: s, rad, N m; base parameters in the unit of their column",
            "rel_std_note": "std / |value|; null where the value is 0 (a parameter held at "
                            "its physical bound: poorly determined)"}
        panels = [("identification data", c.t, c.tau, res.base.columns(c.Y) @ res.beta)]
        v = None
        if vdata is not None:
            v = validate_fit(res, vdata, model, mode=mode)
            cov = v.coverage
            summary["validation_data"] = validate
            summary["validation_rms_error_Nm"] = [float(x) for x in v.rms_error]
            summary["validation_rms_error_prior_Nm"] = [float(x) for x in v.rms_error_prior]
            summary["validation_rms_torque_Nm"] = [float(x) for x in v.rms_torque]
            summary["validation_error"] = [float(x) for x in v.error]
            summary["validation_error_prior"] = [float(x) for x in v.error_prior]
            summary["validation_inside_fraction"] = cov.fraction
            summary["validation_outside_rows"] = len(cov.rows)
            summary["warnings"] = [*summary["warnings"], *v.warnings]
            vc = v.conditioned
            panels.append(("validation data", vc.t, vc.tau, vc.Y @ res.theta))
        return cls(summary, res, tuple(panels), v)

    def lines(self) -> list[str]:
        """The identification in words (without the files)."""
        res, s = self.result, self.summary
        lines = [f"{res.status_text}: {res.base.size} base parameters from {res.n_samples} "
                 f"samples ({res.n_used} used after filtering at {res.cutoff_hz:.3g} Hz, "
                 f"parallel filter {res.parallel_hz:.3g} Hz): {res.method}, condition number "
                 f"{res.condition_number:.4g}, RMS residual {res.rms_residual[0]:.4g}, "
                 f"{res.rms_residual[1]:.4g} N m, fit quality {res.fit_quality[0]:.2%}, "
                 f"{res.fit_quality[1]:.2%} of the RMS torques (noise and filters explain "
                 f"{res.explained_quality[0]:.2%}, {res.explained_quality[1]:.2%}); "
                 f"predicted torques along {res.reference} uncertain by "
                 f"{res.uncertainty[0]:.2%}, {res.uncertainty[1]:.2%} of their RMS (limit "
                 f"{UNCERTAINTY_LIMIT:.0%})",
                 *(f"  {n:<7} = {v: .6g} +- {sd:.2g} {u}  ({m})" for n, m, u, v, sd in
                   zip(res.base.names, res.base.meanings, res.base.units, res.beta, res.std,
                       strict=True))]
        if "validation_rms_error_Nm" in s:
            e, ep = s["validation_rms_error_Nm"], s["validation_rms_error_prior_Nm"]
            lines.append(f"validation on {s['validation_data']}: RMS error {e[0]:.4g}, "
                         f"{e[1]:.4g} N m (prior model {ep[0]:.4g}, {ep[1]:.4g} N m); "
                         f"{s['validation_inside_fraction']:.1%} of its samples inside the "
                         "excited region")
        return lines


def model_comment(res: IdentificationResult, data_path: str, config: str | None) -> str:
    """The comment at the top of ``identified.toml``: its first line names the status as
    ``dextar calibrate``'s ``calibrated.toml`` does, ``identified by dextar from DATA
    (STATUS: ...)``, with every reason when the status is not "identified" (``--model``
    refuses such a file: :func:`dextar.config.scenario.load_scenario`)."""
    if res.success:
        what = (f"identified: {res.method}, condition number {res.condition_number:.4g}; "
                f"predicted torques along {res.reference} uncertain by "
                f"{100 * res.uncertainty[0]:.3g} / {100 * res.uncertainty[1]:.3g} % of their "
                "RMS, motor A / D")
    else:
        said = res.message.replace("\n", " ")  # every reason, the worst first
        what = (said if said.startswith(f"{res.status_text}:")
                else f"{res.status_text}: {said}") + "; dextar refuses this file as --model"
    return (f"identified by dextar from {data_path} ({what})\nbase parameters reproduced "
            "exactly; the split between rods, rotor and payload that the torques cannot see "
            f"follows {config or 'the defaults'}")


#: Every file an identification may write.
IDENTIFICATION_FILES = ("identified.toml", "parameters.csv", "summary.json", "fit.png",
                        "report.html")


def write_identification(out: str, rep: IdentificationReport, model_toml: str, *,
                         force: bool = False, with_figures: bool = True) -> None:
    """Write ``identified.toml``, ``parameters.csv``, ``fit.png``, ``report.html`` and
    ``summary.json`` into ``out``."""
    with OutputDir(out, force=force, produces=IDENTIFICATION_FILES) as od:
        od.write_text("identified.toml", model_toml)
        od.write_text("parameters.csv", parameters_csv(rep.result))
        if with_figures:
            png = png_bytes(fit_figure(rep.panels))
            od.write_bytes("fit.png", png)
            od.write_text("report.html", identification_report(rep.summary, {"fit": png}))
        od.write_text("summary.json", json.dumps(rep.summary, indent=2, allow_nan=False)
                      + "\n")


def parameters_csv(res: IdentificationResult) -> str:
    """``name, meaning, value, std, rel_std_percent, unit, poorly_determined`` (relative std
    above 50 %): one row per base parameter (SI values)."""
    out = ["name,meaning,value,std,rel_std_percent,unit,poorly_determined"]
    for name, meaning, unit, v, s in zip(res.base.names, res.base.meanings, res.base.units,
                                         res.beta, res.std, strict=True):
        rel = 100.0 * s / abs(v) if v != 0 else math.inf
        flag = "true" if name in res.poorly_determined else "false"
        out.append(f'{name},"{meaning}",{_num(v)},{_num(s)},'
                   f"{_num(rel) if math.isfinite(rel) else 'inf'},{unit},{flag}")
    return "\n".join(out) + "\n"


def fit_figure(panels: Sequence[tuple[str, Array, Array, Array]]) -> Figure:
    """Measured against predicted torques and their residuals; one column per data set
    ``(title, t (m,), measured (m, 2), predicted (m, 2))``."""
    fig = mfigure.Figure(figsize=(5.2 * len(panels), 6.4))
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
        flag = (" <b>poorly determined</b>" if p.get("poorly_determined") else "")
        rows.append(f"<tr><td>{esc(p['name'])}</td><td>{esc(p['meaning'])}</td>"
                    f"<td>{esc(p['unit'])}</td><td>{v:.6g}</td><td>{s:.3g}</td>"
                    f"<td>{rel}{flag}</td></tr>")
    facts = [("status", summary["status"]), ("message", summary["message"]),
             ("method", summary["method"]), ("samples read / used",
                                             f"{summary['n_samples']} / {summary['n_used']}"),
             ("state / parallel filter cut-off [Hz]",
              f"{summary['cutoff_hz']:.4g} / {summary['parallel_cutoff_hz']:.4g}"),
             ("condition number", f"{summary['condition_number']:.4g}"),
             ("RMS residual [N m]", ", ".join(f"{v:.4g}" for v in summary["rms_residual_Nm"])),
             ("fit quality: RMS residual / RMS torque",
              ", ".join(f"{v:.3%}" for v in summary["fit_quality"])),
             ("fit quality the noise and filters explain",
              ", ".join(f"{v:.3%}" for v in summary["explained_fit_quality"])),
             (f"predicted-torque uncertainty along {summary['prediction_uncertainty_reference']}"
              f" (limit {summary['prediction_uncertainty_limit']:.0%})",
              ", ".join("inf" if v is None else f"{v:.3%}"
                        for v in summary["prediction_uncertainty"])),
             ("parameters with a relative std above 50 %",
              ", ".join(summary["poorly_determined"]) or "none")]
    if "validation_rms_error_Nm" in summary:
        facts += [("validation RMS error, identified [N m]",
                   ", ".join(f"{v:.4g}" for v in summary["validation_rms_error_Nm"])),
                  ("validation RMS error, prior [N m]",
                   ", ".join(f"{v:.4g}" for v in summary["validation_rms_error_prior_Nm"])),
                  ("validation RMS torque [N m]",
                   ", ".join(f"{v:.4g}" for v in summary["validation_rms_torque_Nm"])),
                  ("validation samples inside the excited region",
                   f"{summary['validation_inside_fraction']:.1%}")]
    fact_rows = "".join(f"<tr><td>{esc(k)}</td><td>{esc(str(v))}</td></tr>" for k, v in facts)
    warn = "".join(f"<li>{esc(w)}</li>" for w in summary["warnings"]) or "<li>none</li>"
    return page(
        f"Identification from {summary['data']}",
        f"<table>{fact_rows}</table><h2>Warnings</h2><ul>{warn}</ul>"
        "<h2>Base parameters</h2><p>Each a combination of standard parameters (SI); the "
        "standard deviations account for the correlation the low-pass leaves in the "
        "residuals.</p><table><tr><th>name</th><th>meaning</th><th>unit</th><th>value</th>"
        f"<th>std</th><th>std [%]</th></tr>{''.join(rows)}</table>"
        f"<h2>Fit</h2>{figures(pngs)}")
