"""Writing a calibration: the measurement poses, the parameter table, the summary, the
residual and accuracy figures, the report and the calibrated config (texts and Figure
objects, written by :func:`write_calibration`), and what ``dextar poses`` and ``dextar
calibrate`` say (payloads, words, warnings). Files speak mm, degrees and micrometres."""

from __future__ import annotations

import html
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..calibration.accuracy import AccuracyMap, accuracy_map
from ..calibration.data import PoseData, rows_text
from ..calibration.fit import CalibrationResult, Errors, encoder_std
from ..calibration.model import FRAME, KinematicModel, to_file_units
from ..calibration.poses import PoseSelection
from ..errors import NumericalError
from ..geometry import WORKING_MODES, FiveBar
from .config_file import toml_number as _num
from .figures import png_bytes
from .files import OutputDir
from .html_page import figures, page

if TYPE_CHECKING:  # the real module; at run time matplotlib is imported where first used
    import matplotlib.figure as mfigure
    from matplotlib.figure import Figure
else:
    mfigure = lazy_module("matplotlib.figure")


#: Colour of each working mode in the figures.
MODE_COLOURS = {"++": "tab:blue", "+-": "tab:orange", "-+": "tab:green", "--": "tab:red"}
STATUS_WORDS = {0: "calibrated", 1: "not converged", 2: "residuals above the stated noise",
                3: "outliers"}
#: The status code of a fit whose data hold outliers (no calibrated config is written).
OUTLIERS = 3
#: The status code of a fit that did not converge (no calibrated config is written: its
#: parameters are where the solver stopped, not a calibration).
NOT_CONVERGED = 1
#: Every file of ``dextar calibrate``.
CALIBRATION_FILES = ("calibrated.toml", "parameters.csv", "summary.json", "residuals.png",
                     "accuracy.png", "report.html")


# ---------------------------------------------------------------------------------- poses
def poses_csv(sel: PoseSelection) -> str:
    """``mode, assembly, phi_deg, psi_deg, x_mm, y_mm``: the poses in visiting order, the
    encoder readings to command and the nominal point (robot frame)."""
    out = ["mode,assembly,phi_deg,psi_deg,x_mm,y_mm"]
    r, P = np.degrees(sel.readings), 1e3 * sel.points
    for i, m in enumerate(sel.modes):
        out.append(f"{m},{sel.assembly},{_num(r[i, 0])},{_num(r[i, 1])},{_num(P[i, 0])},"
                   f"{_num(P[i, 1])}")
    return "\n".join(out) + "\n"


def poses_summary(sel: PoseSelection) -> dict[str, Any]:
    """The selection's figures, JSON-ready: count per mode, the index, O1, O3, condition
    number, singularity distances, the modes asked for without a pose, the region (mm)."""
    o = sel.observability
    return {"status": sel.status, "success": sel.success, "message": sel.message,
            "n_poses": len(sel), "n_candidates": sel.n_candidates,
            "modes": {m: sel.modes.count(m) for m in WORKING_MODES if m in sel.modes},
            "assembly": sel.assembly, "parameters": list(sel.parameters), "index": sel.index,
            "o1": o.o1, "o3": o.o3, "condition_number": o.condition_number,
            "min_type1_distance": float(sel.type1.min()),
            "min_type2_distance": float(sel.type2.min()),
            "missing_modes": list(sel.missing_modes),
            "region_mm": None if sel.region is None else [1e3 * v for v in sel.region]}


def poses_figure(sel: PoseSelection, robot: FiveBar) -> Figure:
    """The poses over the legs' reach of ``robot`` (m), coloured by working mode, numbered in
    visiting order (robot frame, mm)."""
    fig = mfigure.Figure(figsize=(7.0, 5.6))
    ax = fig.subplots()
    _robot_outline(ax, robot)
    P = 1e3 * sel.points
    for m in dict.fromkeys(sel.modes):
        k = np.array([x == m for x in sel.modes])
        ax.plot(P[k, 0], P[k, 1], "o-", color=MODE_COLOURS[m], ms=4, lw=0.6, alpha=0.8,
                label=f"mode {m} ({int(k.sum())})")
    for i in range(len(P)):
        ax.annotate(str(i + 1), P[i], fontsize=6, xytext=(2, 2), textcoords="offset points")
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm] (robot frame)")
    ax.set_ylabel("y [mm]")
    o = sel.observability
    ax.set_title(f"{len(sel)} measurement poses in visiting order: O1 {o.o1:.3g}, O3 "
                 f"{o.o3:.3g}, condition number {o.condition_number:.3g}", fontsize=9)
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


# ---------------------------------------------------------------------------- calibration
def parameters_csv(res: CalibrationResult) -> str:
    """``name, nominal, value, std, unit``: one row per parameter in mm or deg; ``std`` is
    empty for a parameter not identifiable (its value stays nominal)."""
    out = ["name,nominal,value,std,unit"]
    for p in res.parameters:
        unit, nom, val, std = p.in_file_units()
        out.append(f"{p.name},{_num(nom)},{_num(val)},{'' if std is None else _num(std)},"
                   f"{unit}")
    return "\n".join(out) + "\n"


def calibration_summary(res: CalibrationResult, *, data: str = "", config: str = "",
                        accuracy: Sequence[AccuracyMap] = (),
                        encoder_counts: float | None = None,
                        outliers: Sequence[int] = (), outlier_message: str = ""
                        ) -> dict[str, Any]:
    """The calibration's summary, JSON-ready (mm, deg, um): ``status``, ``n_poses``,
    ``identifiable``, ``not_identifiable``, the RMS and largest errors before and after,
    ``validation`` (the same on held-out poses), the parameters, their correlation, the
    observability and the accuracy maps' figures.

    ``outliers``: row numbers of outliers the fit ``res`` kept (a diagnosis): the status is
    then ``"outliers"`` (code 3), the message ``outlier_message``, ``outlier_rows`` the
    rows."""
    e = res.errors.as_dict()
    status = OUTLIERS if outliers else res.status
    params = []
    for p in res.parameters:
        unit, nom, val, std = p.in_file_units()
        params.append({"name": p.name, "unit": unit, "nominal": nom, "value": val,
                       "std": std, "identifiable": p.identifiable})
    out: dict[str, Any] = {
        "status": STATUS_WORDS.get(status, str(status)), "status_code": status,
        "success": status == 0, "message": outlier_message if outliers else res.message,
        "data": data,
        "config": config or "defaults", "frame": res.frame, "n_poses": len(res.errors.rows),
        "n_read": len(res.data), "rejected_rows": list(res.rejected),
        "outlier_rows": [int(r) for r in outliers],
        "modes": {m: res.data.subset(res.kept).modes.count(m) for m in WORKING_MODES
                  if m in res.data.subset(res.kept).modes},
        "identifiable": list(res.identifiable), "not_identifiable": list(res.not_identifiable),
        "not_identifiable_combinations": dict(res.combinations),
        "rms_error_before_mm": e["rms_error_before_mm"],
        "rms_error_after_mm": e["rms_error_after_mm"],
        "max_error_before_mm": e["max_error_before_mm"],
        "max_error_after_mm": e["max_error_after_mm"],
        "parameters": params,
        "correlation": {"names": list(res.identifiable),
                        "matrix": [[float(v) for v in row] for row in res.correlation]},
        "observability": res.observability.as_dict(),
        "residual_std": (res.residual_std if res.chi2 is not None
                         else 1e3 * res.residual_std),
        "residual_std_unit": "standard deviations of the stated noise" if res.chi2 is not None
        else "mm",
        "chi2_reduced": res.chi2, "nfev": res.nfev, "warnings": list(res.warnings),
        "units": "mm, deg; errors are distances |measured - predicted|; the model before "
                 "calibration is the nominal robot in the registered instrument frame"}
    if res.validation is not None:
        out["validation"] = res.validation.as_dict()
    if accuracy:
        out["accuracy"] = {"encoder_counts": encoder_counts, "unit": "um",
                           "measure": "largest standard deviation of the position reached",
                           "modes": {m.mode: {"median_um": 1e6 * m.median,
                                              "worst_um": 1e6 * m.worst} for m in accuracy}}
    return out


def _robot_outline(ax: Any, robot: FiveBar) -> None:
    """Pivots and the legs' reach circles on ``ax``, in mm for ``robot`` in m."""
    th = np.linspace(0.0, 2.0 * np.pi, 361)
    r = robot.scaled(1e3)
    for centre, l, L in ((r.A, r.l1, r.L1), (r.D, r.l2, r.L2)):
        for rad in {abs(l - L), l + L}:
            if rad > 0:
                ax.plot(centre[0] + rad * np.cos(th), centre[1] + rad * np.sin(th), color="0.7",
                        lw=0.6, ls="--")
    ax.plot([r.A[0], r.D[0]], [0.0, 0.0], "ks", ms=5)


def _nice(v: float) -> float:
    """A round length near ``v`` (1, 2 or 5 times a power of ten)."""
    if not (v > 0 and math.isfinite(v)):
        return 1.0
    e = math.floor(math.log10(v))
    m = v / 10 ** e
    return float((1 if m < 1.5 else 2 if m < 3.5 else 5 if m < 7.5 else 10) * 10 ** e)


def _length_text(mm: float) -> str:
    return f"{mm:g} mm" if mm >= 0.1 else f"{1e3 * mm:g} µm"


def _quiver(ax: Any, P: Array, E: Array, modes: Sequence[str], robot: FiveBar, title: str,
            span: float) -> None:
    """Error vectors ``E`` (n, 2, mm) at points ``P`` (n, 2, mm), magnified so that the
    95th-percentile one is 8 % of ``span``, with a key of a round length."""
    _robot_outline(ax, robot)
    mag = np.hypot(*E.T)
    ref = float(np.quantile(mag, 0.95)) if mag.size else 1.0
    ref = ref if ref > 0 else 1.0
    scale = ref / (0.08 * span)  # mm of error per mm of plot
    for m in dict.fromkeys(modes):
        k = np.array([x == m for x in modes])
        ax.quiver(P[k, 0], P[k, 1], E[k, 0], E[k, 1], color=MODE_COLOURS[m], angles="xy",
                  scale_units="xy", scale=scale, width=0.004, label=f"mode {m}")
        ax.plot(P[k, 0], P[k, 1], ".", color=MODE_COLOURS[m], ms=3)
    key = _nice(ref)
    q = ax.quiver([], [], [], [], scale_units="xy", scale=scale, angles="xy", width=0.004)
    ax.quiverkey(q, 0.80, 0.04, key, f"{_length_text(key)} error", labelpos="E",
                 coordinates="axes", fontproperties={"size": 7})
    ax.set_title(title, fontsize=9)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm] (robot frame)")
    ax.set_ylabel("y [mm]")
    ax.grid(alpha=0.3)


def residuals_figure(res: CalibrationResult, validation: PoseData | None = None) -> Figure:
    """Error vectors ``measured - predicted`` over the workspace (robot frame, mm), before
    (the nominal robot in the registered frame) and after calibration, each magnified to be
    seen (the key gives the scale); a second row for held-out poses (``validation``, the
    :class:`PoseData` of ``res.validation``) when given."""
    rows = 2 if (validation is not None and res.validation is not None) else 1
    fig = mfigure.Figure(figsize=(11.0, 4.6 * rows))
    axes = np.atleast_2d(fig.subplots(rows, 2, squeeze=False))
    robot = res.calibrated.robot
    R = res.calibrated.rotation()
    span = 2e3 * max(robot.l1 + robot.L1, robot.l2 + robot.L2) + 1e3 * robot.d
    d = res.data.subset(res.kept)
    sets: list[tuple[str, PoseData, Errors]] = [("calibration poses", d, res.errors)]
    if rows == 2 and validation is not None and res.validation is not None:
        sets.append(("held-out poses", validation, res.validation))
    for i, (name, data, err) in enumerate(sets):
        P = 1e3 * res.calibrated.to_robot(data.points)
        for j, (when, E) in enumerate((("before", err.residuals_before),
                                       ("after", err.residuals_after))):
            Er = 1e3 * (E @ R)
            _quiver(axes[i, j], P, Er, data.modes, robot,
                    f"{name}, {when} calibration: RMS "
                    f"{1e3 * (err.rms_before if j == 0 else err.rms_after):.3g} mm, max "
                    f"{1e3 * (err.max_before if j == 0 else err.max_after):.3g} mm", span)
    axes[0, 0].legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return fig


def accuracy_figure(maps: Sequence[AccuracyMap], points: Mapping[str, Array] | None = None
                    ) -> Figure:
    """The predicted position uncertainty (um) over the workspace of each map's working
    mode, one panel each on a common colour scale, the calibration poses of that mode as
    dots (``points``: mode -> (n, 2) robot-frame points in m)."""
    n = len(maps)
    cols = 1 if n == 1 else 2
    rows = (n + cols - 1) // cols
    fig = mfigure.Figure(figsize=(6.0 * cols, 4.8 * rows))
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    vals = np.concatenate([1e6 * m.std[m.valid] for m in maps]) if maps else np.zeros(0)
    vmax = float(np.quantile(vals, 0.95)) if vals.size else 1.0
    im = None
    for ax, m in zip(axes, maps, strict=False):
        Z = np.ma.masked_where(~m.valid, 1e6 * m.std)
        im = ax.pcolormesh(1e3 * m.x, 1e3 * m.y, Z, shading="auto", cmap="viridis", vmin=0.0,
                           vmax=vmax, rasterized=True)
        if m.valid.sum() > 10:
            levels = [v for v in (1, 2, 5, 10, 20, 50, 100, 200, 500) if v < float(Z.max())]
            if levels:
                cs = ax.contour(1e3 * m.x, 1e3 * m.y, Z, levels=levels, colors="white",
                                linewidths=0.6)
                ax.clabel(cs, fontsize=6, fmt="%g")
        if points is not None and m.mode in points and len(points[m.mode]):
            pts = 1e3 * np.asarray(points[m.mode])
            ax.plot(pts[:, 0], pts[:, 1], "k.", ms=3, label="calibration poses")
            ax.legend(fontsize=7, loc="upper right")
        ax.set_aspect("equal")
        ax.set_title(f"mode {m.mode}: median {1e6 * m.median:.3g} µm, worst "
                     f"{1e6 * m.worst:.3g} µm", fontsize=9)
        ax.set_xlabel("x [mm] (robot frame)")
        ax.set_ylabel("y [mm]")
    for ax in axes[len(maps):]:
        ax.set_visible(False)
    if im is not None:
        enc = ("" if maps[0].reading_std is None else
               f" and encoder resolution (s = {np.degrees(maps[0].reading_std) * 3600:.3g} "
               "arcsec)")
        fig.colorbar(im, ax=list(axes[:len(maps)]), extend="max",
                     label=f"position uncertainty [µm]: parameters' covariance{enc}")
    fig.suptitle("Predicted positioning uncertainty of the calibrated robot (1 sigma, worst "
                 "direction)", fontsize=10)
    return fig


def calibration_report(summary: Mapping[str, Any], pngs: dict[str, bytes]) -> str:
    """The report page: the summary, the parameters with their deviations, the correlation
    matrix, the errors before and after (and on held-out poses), the figures."""
    esc = html.escape
    facts: list[tuple[str, str]] = [
        ("status", f"{summary['status']} ({summary['message']})"),
        ("frame of the measured points", str(summary["frame"])),
        ("poses used / read", f"{summary['n_poses']} / {summary['n_read']}"),
        ("working modes", ", ".join(f"{k}: {v}" for k, v in summary["modes"].items())),
        ("rejected rows", ", ".join(str(r) for r in summary["rejected_rows"]) or "none"),
        *([("outlier rows (kept in this fit; no calibrated config written)",
            ", ".join(str(r) for r in summary["outlier_rows"]))]
          if summary.get("outlier_rows") else []),
        ("identifiable", ", ".join(summary["identifiable"])),
        ("not identifiable (kept nominal)", "; ".join(
            summary["not_identifiable_combinations"].values()) or "none"),
    ]
    o = summary["observability"]
    facts.append(("observability", f"O1 {o['o1']:.4g}, O3 {o['o3']:.4g}, condition number "
                                   f"{o['condition_number']:.4g}"))
    fact_rows = "".join(f"<tr><td>{esc(k)}</td><td>{esc(v)}</td></tr>" for k, v in facts)
    err_rows = [("calibration poses", summary)]
    if "validation" in summary:
        err_rows.append(("held-out poses", summary["validation"]))
    errs = "".join(
        f"<tr><td>{esc(name)}</td><td>{e['rms_error_before_mm']:.4g}</td>"
        f"<td>{e['rms_error_after_mm']:.4g}</td><td>{e['max_error_before_mm']:.4g}</td>"
        f"<td>{e['max_error_after_mm']:.4g}</td></tr>" for name, e in err_rows)
    prm = "".join(
        f"<tr><td>{esc(p['name'])}</td><td>{esc(p['unit'])}</td><td>{p['nominal']:.6g}</td>"
        f"<td>{p['value']:.6g}</td><td>{'' if p['std'] is None else format(p['std'], '.3g')}"
        f"</td><td>{'yes' if p['identifiable'] else 'no'}</td></tr>"
        for p in summary["parameters"])
    names = summary["correlation"]["names"]
    mat = summary["correlation"]["matrix"]
    head = "".join(f"<th>{esc(n)}</th>" for n in names)
    body = "".join(
        f"<tr><th>{esc(n)}</th>" + "".join(
            f"<td style='background:rgba(200,60,60,{abs(v) * 0.6 if i != j else 0:.2f})'>"
            f"{v:+.2f}</td>" for j, v in enumerate(row)) + "</tr>"
        for i, (n, row) in enumerate(zip(names, mat, strict=True)))
    warn = "".join(f"<li>{esc(w)}</li>" for w in summary["warnings"]) or "<li>none</li>"
    acc = ""
    if "accuracy" in summary:
        a = summary["accuracy"]
        acc = ("<h2>Predicted accuracy</h2><p>Largest standard deviation of the position "
               "reached when commanding a point, from the parameters' covariance"
               + (f" and {a['encoder_counts']:g} counts per turn" if a["encoder_counts"]
                  else "") + ":</p><ul>"
               + "".join(f"<li>mode {esc(k)}: median {v['median_um']:.3g} um, worst "
                         f"{v['worst_um']:.3g} um</li>" for k, v in a["modes"].items())
               + "</ul>")
    return page(
        f"Kinematic calibration from {summary['data'] or 'measured poses'}",
        f"<table>{fact_rows}</table><h2>Warnings</h2><ul>{warn}</ul>"
        "<h2>Errors [mm]</h2><p>Distances between measured and predicted points; before: the "
        "nominal robot in the registered instrument frame.</p><table><tr><th></th>"
        "<th>RMS before</th><th>RMS after</th><th>max before</th><th>max after</th></tr>"
        f"{errs}</table><h2>Parameters</h2><table><tr><th>name</th><th>unit</th>"
        "<th>nominal</th><th>value</th><th>std</th><th>identifiable</th></tr>"
        f"{prm}</table><h2>Correlation of the estimates</h2><table><tr><th></th>{head}</tr>"
        f"{body}</table>{acc}<h2>Figures</h2>{figures(pngs)}")


# ---------------------------------------------------------------------------- the config
def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return _num(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise NumericalError(f"value {v!r} cannot be written in a config")


def calibrated_toml(model: KinematicModel, *, working_mode: str, assembly_mode: str,
                    frame_identified: bool = True, encoder_counts: float | None = None,
                    extra: Mapping[str, Any] | None = None, comment: str = "",
                    sigma_mm: float | None = None,
                    region_mm: Sequence[float] | None = None) -> str:
    """A config whose ``[robot]`` is the calibrated robot (lengths in mm and
    ``encoder_offset_deg = [phi, psi]``, with ``encoder_counts`` when given) and whose
    ``[instrument]`` (``x0_mm, y0_mm, theta0_deg``) is the identified frame (when
    ``frame_identified``; ``sigma_mm`` the instrument's noise and ``region_mm`` where it
    measures, kept with it); the tables of
    ``extra`` (the rest of the user's config, raw TOML values; arrays of tables as lists of
    tables) follow as given."""
    r = FiveBar(*(to_file_units(n, v) for n, v in model.robot.as_dict().items()))
    top = {k: v for k, v in (extra or {}).items()
           if not isinstance(v, Mapping) and not (isinstance(v, list) and v
                                                  and all(isinstance(x, Mapping) for x in v))}
    lines = [f"# {line}" for line in comment.splitlines()]
    lines += [f"{k} = {_toml_value(v)}" for k, v in top.items()]
    lines += [
        "", "[robot]                # mm, deg",
        *(f"{k} = {_num(v)}" for k, v in r.as_dict().items()),
        f'working_mode = "{working_mode}"', f'assembly_mode = "{assembly_mode}"',
        f"encoder_offset_deg = [{_num(to_file_units('phi_offset', model.phi_offset))}, "
        f"{_num(to_file_units('psi_offset', model.psi_offset))}]   # geometric angle = "
        "reading + offset"]
    if encoder_counts is not None:
        c = float(encoder_counts)
        lines.append(f"encoder_counts = {_toml_value(int(c) if c.is_integer() else c)}")
    if frame_identified:
        x0, y0, th = (model.in_file_units()[n] for n in FRAME)
        lines += ["", "[instrument]           # the robot frame in the instrument's frame",
                  f"x0_mm = {_num(x0)}", f"y0_mm = {_num(y0)}", f"theta0_deg = {_num(th)}"]
    elif sigma_mm is not None or region_mm is not None:
        lines += ["", "[instrument]           # points measured in the robot frame"]
    if sigma_mm is not None:
        lines.append(f"sigma_mm = {_num(sigma_mm)}   # per axis")
    if region_mm is not None:
        lines.append(f"region = [{', '.join(_num(v) for v in region_mm)}]   # mm, robot "
                     "frame: xmin, xmax, ymin, ymax")
    for name, table in (extra or {}).items():
        if name in ("robot", "instrument") or name in top:
            continue
        if isinstance(table, list):
            for item in table:
                lines += ["", f"[[{name}]]", *(f"{k} = {_toml_value(v)}" for k, v in item.items())]
        elif isinstance(table, Mapping):
            plain = {k: v for k, v in table.items() if not isinstance(v, Mapping)}
            lines += ["", f"[{name}]", *(f"{k} = {_toml_value(v)}" for k, v in plain.items())]
            for k, v in table.items():
                if isinstance(v, Mapping):
                    lines += ["", f"[{name}.{k}]",
                              *(f"{kk} = {_toml_value(vv)}" for kk, vv in v.items())]
    return "\n".join(lines) + "\n"


def calibration_files(res: CalibrationResult, *, data: str, config: str = "",
                      working_mode: str, assembly_mode: str,
                      encoder_counts: float | None = None,
                      extra: Mapping[str, Any] | None = None,
                      validation: PoseData | None = None, figures: bool = True,
                      resolution: int = 121, dpi: int = 110, outliers: Sequence[int] = (),
                      outlier_message: str = "", sigma_mm: float | None = None,
                      region_mm: Sequence[float] | None = None) -> dict[str, str | bytes]:
    """Every file of ``dextar calibrate`` by name: ``calibrated.toml`` (not for a fit that
    did not converge), ``parameters.csv``, ``summary.json`` and, with ``figures``,
    ``residuals.png``, ``accuracy.png`` and ``report.html`` (the accuracy maps of the working modes of the kept poses, in
    ``assembly_mode``, with the encoders' rounding of ``encoder_counts`` per turn).

    ``extra`` holds the user's other config tables (raw TOML values) to carry into
    ``calibrated.toml``; ``validation`` the held-out poses of ``res.validation`` (drawn in
    ``residuals.png``); ``resolution`` the accuracy maps' grid, ``dpi`` the figures';
    ``sigma_mm`` the instrument's noise (``[instrument].sigma_mm``) and ``region_mm`` where
    it measures (``[instrument].region``), kept in the config.
    With ``outliers`` (the rows of a fit that kept them, see :func:`calibration_summary`)
    every file but ``calibrated.toml`` is written: a diagnosis, not a calibration.
    """
    kept = res.data.subset(res.kept)
    reading_std = None if encoder_counts is None else encoder_std(encoder_counts)
    modes = [m for m in WORKING_MODES if m in kept.modes]
    maps = [accuracy_map(res.calibrated, res.identifiable, res.covariance, m,
                         assembly=assembly_mode, reading_std=reading_std,
                         resolution=resolution) for m in modes] if figures else []
    summary = calibration_summary(res, data=data, config=config, accuracy=maps,
                                  encoder_counts=encoder_counts, outliers=outliers,
                                  outlier_message=outlier_message)
    comment = (f"calibrated by dextar from {data} ({summary['status']}: "
               f"{summary['rms_error_before_mm']:.4g} -> {summary['rms_error_after_mm']:.4g} "
               f"mm RMS over {summary['n_poses']} poses)")
    files: dict[str, str | bytes] = {}
    if not outliers and res.status != NOT_CONVERGED:
        files["calibrated.toml"] = calibrated_toml(
            res.calibrated, working_mode=working_mode, assembly_mode=assembly_mode,
            frame_identified=res.frame == "instrument", encoder_counts=encoder_counts,
            extra=extra, comment=comment, sigma_mm=sigma_mm, region_mm=region_mm)
    files["parameters.csv"] = parameters_csv(res)
    files["summary.json"] = json.dumps(summary, indent=2, allow_nan=False) + "\n"
    if figures:
        pts = {m: res.calibrated.to_robot(kept.points[[x == m for x in kept.modes]])
               for m in modes}
        pngs = {"residuals": png_bytes(residuals_figure(res, validation), dpi=dpi),
                "accuracy": png_bytes(accuracy_figure(maps, pts), dpi=dpi)}
        files["residuals.png"] = pngs["residuals"]
        files["accuracy.png"] = pngs["accuracy"]
        files["report.html"] = calibration_report(summary, pngs)
    return files


# ------------------------------------------------------------------------ the commands' words
#: Below this RMS error (m) of the nominal robot the measured points are its own predictions:
#: a poses.csv, not measurements.
NOMINAL_ECHO = 1e-9
#: What the columns of a poses file of ``dextar poses`` are.
POSES_UNITS = ("phi_deg, psi_deg: the encoder readings to command (geometric angle - "
               "[robot].encoder_offset_deg); x_mm, y_mm: the nominal point, robot frame")


def poses_payload(sel: PoseSelection, *, where: str, config: str, frame: str,
                  encoder_offset_deg: Sequence[float]) -> dict[str, Any]:
    """The JSON payload of ``dextar poses``: :func:`poses_summary`, where the file went
    (``where``), the config (``""``: the defaults), the frame and the encoder offsets."""
    return {**poses_summary(sel), "out": where, "config": config or "defaults",
            "frame": frame, "encoder_offset_deg": list(encoder_offset_deg),
            "units": POSES_UNITS}


def poses_text(sel: PoseSelection, where: str) -> str:
    """``dextar poses`` in words: the selection and what to record at each pose."""
    return (f"{sel.message}\nwrote {where}: mode, assembly, phi_deg, psi_deg (encoder "
            "readings to command), x_mm, y_mm (nominal point, robot frame); at each pose "
            "record the readings and the measured point in phi_deg, psi_deg, x_mm, y_mm: "
            "the file of dextar calibrate")


def poses_warnings(sel: PoseSelection) -> list[str]:
    """A warning when the selection relaxed its spacing; the working modes without a pose
    (exit 1)."""
    if sel.missing_modes:
        return [f"dextar poses: {sel.message.split('; ')[-1]}: choose --modes among those "
                "with poses, widen the region or lower the margin"]
    return [] if sel.success else [f"dextar poses: warning: {sel.message}"]


def write_calibration(od: OutputDir, files: Mapping[str, str | bytes]) -> tuple[str, ...]:
    """Write ``files`` (:func:`calibration_files`) into ``od`` in the order of
    :data:`CALIBRATION_FILES`; the names written."""
    with od:
        for name in CALIBRATION_FILES:
            content = files.get(name)
            if isinstance(content, bytes):
                od.write_bytes(name, content)
            elif content is not None:
                od.write_text(name, content)
    return tuple(n for n in CALIBRATION_FILES if n in files)


@dataclass(frozen=True)
class CalibrationRun:
    """What ``dextar calibrate`` says of a fit besides its files.

    Attributes
    ----------
    result : CalibrationResult
    out : str
        The output directory as printed.
    written : tuple of str
        The files written there (:func:`write_calibration`).
    outliers : tuple of int
        Rows of the outliers the fit kept (a diagnosis; ``problem`` the error's words).
    problem : str
    robust : str or None
        The robust loss asked for.
    sigma_mm : float or None
        The config's ``[instrument].sigma_mm``.
    default_robot : FiveBar or None
        The nominal robot (mm) when no config was given (a note names it), in
        ``working_mode``.
    working_mode : str
    """

    result: CalibrationResult
    out: str
    written: tuple[str, ...]
    outliers: tuple[int, ...] = ()
    problem: str = ""
    robust: str | None = None
    sigma_mm: float | None = None
    default_robot: FiveBar | None = None
    working_mode: str = ""

    @property
    def code(self) -> int:
        """The exit status: 0 calibrated, 1 a fit that does not fit its data."""
        return 0 if self.result.status == 0 and not self.outliers else 1

    def payload(self, files: Mapping[str, str | bytes]) -> dict[str, Any]:
        """The JSON payload: the summary of ``files``, the directory and the files."""
        summary = files["summary.json"]
        return {**json.loads(summary), "out": self.out, "files": list(self.written)}

    def text(self) -> str:
        """The fit in words: status, errors before and after, the parameters, the files."""
        res = self.result
        lines = [f"{STATUS_WORDS[OUTLIERS]}: {self.problem}" if self.outliers else res.message,
                 _errors_line(f"{len(res.errors.rows)} poses", res.errors)
                 + " (nominal robot -> calibrated)"]
        if res.validation is not None:
            lines.append(_errors_line(f"{len(res.validation.rows)} held-out poses",
                                      res.validation))
        for p in res.parameters:
            unit, nom, val, std = p.in_file_units()
            spread = f" +- {std:.3g}" if std is not None else " (not identifiable: nominal)"
            lines.append(f"  {p.name:<10} {nom:12.6g} -> {val:12.6g}{spread} {unit}")
        first, *rest = self.written
        lines.append(f"wrote {Path(self.out) / first}, {', '.join(rest)}")
        return "\n".join(lines)

    def warnings(self) -> list[str]:
        """The lines for stderr: the outliers and where their diagnosis is, or the status,
        the rows rejected, the fit's warnings, a poses file given as measurements, the
        nominal robot assumed."""
        res = self.result
        if self.outliers:  # one line: the rows, what to do, where the diagnosis is
            them = "it" if len(self.outliers) == 1 else "them"
            return [f"dextar calibrate: {self.problem} (--robust soft_l1); the fit with {them} "
                    f"kept is in {self.out} (no calibrated.toml)"]
        out: list[str] = []
        if res.status != 0:
            stated = (f"; or [instrument].sigma_mm = {self.sigma_mm:g} mm understates the "
                      "instrument's noise" if res.status == 2 and res.data.sigma is None
                      and self.sigma_mm is not None else "")
            unwritten = (f"; no calibrated.toml written (the files in {self.out} are a "
                         "diagnosis)" if res.status == NOT_CONVERGED else "")
            out.append(f"dextar calibrate: {STATUS_WORDS.get(res.status)}: "
                       f"{res.message}{stated}{unwritten}")
        if res.rejected:
            out.append(f"dextar calibrate: note: the robust loss {self.robust} rejected "
                       f"row{'s' if len(res.rejected) > 1 else ''} "
                       f"{rows_text(np.asarray(res.rejected))}")
        out += [f"dextar calibrate: warning: {w}" for w in res.warnings]
        if res.rms_error_before < NOMINAL_ECHO:
            out.append("dextar calibrate: warning: the measured points are the nominal "
                       f"robot's own predictions (RMS error {1e3 * res.rms_error_before:.2g} "
                       "mm): is this the file of dextar poses rather than the measurements?")
        if self.default_robot is not None:
            g = self.default_robot
            out.insert(0, f"dextar calibrate: note: no --config: the nominal robot is the "
                       f"DexTAR (l1 = {g.l1:g}, l2 = {g.l2:g}, L1 = {g.L1:g}, L2 = {g.L2:g}, "
                       f"d = {g.d:g} mm, encoder offsets 0, working mode {self.working_mode})")
        return out


def _errors_line(what: str, e: Errors) -> str:
    """``what``: RMS and largest errors before -> after calibration (mm)."""
    return (f"  {what}: RMS error {1e3 * e.rms_before:.4g} -> {1e3 * e.rms_after:.4g} mm, "
            f"max {1e3 * e.max_before:.4g} -> {1e3 * e.max_after:.4g} mm")
