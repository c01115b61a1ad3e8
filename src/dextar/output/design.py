"""Writing a design sweep or search: the rows of ``designs.csv`` (one formatting for rows
fresh and resumed, so a resumed run ends with the same bytes), the figures and the
report."""

from __future__ import annotations

import csv
import html
import io
import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..design.pareto import Choice
from ..design.search import REFERENCE_POINT, SEARCHES, HypervolumeCurve, SearchSettings
from ..design.space import (
    LENGTHS,
    METRICS,
    UNITS,
    DesignSpace,
    columns_of_width,
    row_columns,
)
from ..design.sweep import SweepStats
from ..errors import ConfigError
from ..geometry import FiveBar
from ..kinematics import workspace_map
from .figures import plot_workspace, png_bytes, svg_bytes
from .files import OutputDir, write_text
from .html_page import figures, grid, page, table
from .tables import number

if TYPE_CHECKING:  # the real module; at run time matplotlib is imported where first used
    import matplotlib.figure as mfigure
    from matplotlib.figure import Figure
else:
    mfigure = lazy_module("matplotlib.figure")


#: Most design numbers a resumed search's file may hold.
MAX_DESIGNS = 10_000_000


def columns(variables: Sequence[str] = LENGTHS) -> tuple[str, ...]:
    """The columns of designs.csv and pareto.csv for designs of ``variables`` (the lengths,
    and the counterweights and motor indices a sweep varies), each with its unit."""
    return ("design", *(f"{k}_{UNITS[k]}" if UNITS[k] else k for k in variables), "feasible",
            "reason", "motor", *METRICS)


#: Columns of designs.csv and pareto.csv of a sweep of the lengths.
COLUMNS = columns()


#: Every file a sweep may write.
DESIGN_FILES = ("designs.csv", "sweep.json", "pareto.csv", "best.toml", "summary.json",
                "report.html", *(f"{n}.{e}" for n in ("pareto", "designs", "best_workspace",
                                                      "hypervolume") for e in ("png", "svg")))

#: A metric in words, for an axis (its unit follows from its name's suffix).
METRIC_WORDS = {
    "cycle_time_s": "cycle time",
    "footprint_mm": "footprint (largest reach from the base's middle)",
    "min_type1_distance": "distance to serial singularities (smallest sine)",
    "min_type2_distance": "distance to parallel singularities (smallest sine)",
    "gci": "dexterity (mean inverse condition number of J)",
    "peak_torque_A_Nm": "peak torque of motor A", "peak_torque_D_Nm": "peak torque of motor D",
    "rms_torque_A_Nm": "RMS torque of motor A", "rms_torque_D_Nm": "RMS torque of motor D",
    "workspace_area_mm2": "usable workspace area",
    "shaking_force_N": "peak shaking force", "rms_shaking_force_N": "RMS shaking force",
    "shaking_moment_Nm": "peak shaking moment (about the middle of AD)",
    "rms_shaking_moment_Nm": "RMS shaking moment (about the middle of AD)",
    "motor_mass_kg": "mass of both motors", "motor_price": "price of both motors",
    "gear_ratio": "gear ratio (motor turns per joint turn)",
}
#: Units of the metrics by the suffix of their names (longest first).
UNIT_SUFFIXES = (("_mm2", "mm²"), ("_Nm", "N m"), ("_mm", "mm"), ("_kg", "kg"), ("_s", "s"),
                 ("_N", "N"), ("_W", "W"), ("_J", "J"))


def metric_label(objective: str) -> str:
    """An objective (a metric name, ``-`` before one that is maximised) as an axis label in
    words with its unit: ``"cycle time [s]"``, ``"distance to parallel singularities
    (smallest sine) [-], maximised"``; a metric without words of its own is named from its
    name (``shaking_force_peak_N`` -> ``"shaking force peak [N]"``)."""
    name = objective.lstrip("-")
    unit, stem = "-", name
    for suffix, u in UNIT_SUFFIXES:
        if name.endswith(suffix):
            unit, stem = u, name[:-len(suffix)]
            break
    words = METRIC_WORDS.get(name, stem.replace("_", " "))
    return f"{words} [{unit}]" + (", maximised" if objective.startswith("-") else "")


def header(variables: Sequence[str] = LENGTHS) -> str:
    """The CSV header line."""
    return ",".join(columns(variables)) + "\n"


def row_line(row: Mapping[str, Any]) -> str:
    """One design's CSV line: numbers to 17 digits, an empty cell for a metric that does not
    exist (the plan failed first), ``true``/``false`` for ``feasible``."""
    cells: list[str] = [str(int(row["design"]))]
    cells += [number(row[k]) for k in row_columns(row)]
    cells += ["true" if row["feasible"] else "false", str(row["reason"]),
              str(row.get("motor", ""))]
    cells += ["" if row[k] is None else number(row[k]) for k in METRICS]
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow(cells)
    return buf.getvalue()


def parse_line(line: str, variables: Sequence[str] = LENGTHS) -> dict[str, Any] | None:
    """A row back from its CSV line (of designs of ``variables``); None for a line cut short
    (a sweep killed mid-write)."""
    if not line.endswith("\n"):
        return None
    try:
        cells = next(csv.reader([line]))
    except (csv.Error, StopIteration):
        return None
    if len(cells) != len(columns(variables)):
        return None
    n = len(variables)
    try:
        row: dict[str, Any] = {"design": int(cells[0])}
        row.update({k: float(c) for k, c in zip(variables, cells[1:n + 1], strict=True)})
        row["feasible"] = cells[n + 1] == "true"
        row["reason"] = cells[n + 2]
        row["motor"] = cells[n + 3]
        row.update({k: None if c == "" else float(c)
                    for k, c in zip(METRICS, cells[n + 4:], strict=True)})
    except ValueError:
        return None
    return row


def pareto_figure(F: Array, pareto: Array, best: int, names: Sequence[str]) -> Figure:
    """The feasible designs in the objectives (each pair of them), the Pareto designs
    marked, the chosen one starred; axes in words and units, a maximised objective drawn
    with its own sign."""
    F = np.asarray(F, float) * np.array([-1.0 if n.startswith("-") else 1.0 for n in names])
    k = F.shape[1]
    labels = [metric_label(n) for n in names]
    if k == 1:
        fig = mfigure.Figure(figsize=(6.0, 4.6))
        ax = fig.subplots()
        ax.plot(np.sort(F[:, 0]), ".", color="0.6", label="feasible designs (sorted)")
        ax.set_ylabel(labels[0])
        ax.set_xlabel("rank")
        ax.legend(fontsize=8)
        fig.tight_layout()
        return fig
    m = k - 1
    fig = mfigure.Figure(figsize=(2.0 + 3.6 * m, 1.4 + 3.2 * m))
    axes = fig.subplots(m, m, squeeze=False)
    for i in range(m):  # row: objective i + 1; column: objective j
        for j in range(m):
            ax = axes[i, j]
            if j > i:
                ax.set_visible(False)
                continue
            x, y = j, i + 1
            ax.scatter(F[:, x], F[:, y], s=6, color="0.75", label="feasible designs")
            ax.scatter(F[pareto, x], F[pareto, y], s=14, color="C0", label="Pareto designs")
            ax.scatter(F[best, x], F[best, y], s=140, marker="*", color="C3", label="chosen")
            if i == m - 1:
                ax.set_xlabel(labels[x], fontsize=8)
            if j == 0:
                ax.set_ylabel(labels[y], fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(f"Pareto front in the {k} objectives ({sum(pareto)} of {len(F)} feasible "
                 "designs)", fontsize=9)
    fig.tight_layout()
    return fig


def hypervolume_figure(curve: HypervolumeCurve, kind: str) -> Figure:
    """The hypervolume of the front found against the designs evaluated."""
    fig = mfigure.Figure(figsize=(6.0, 4.2))
    ax = fig.subplots()
    ax.plot(curve.evaluations, curve.hypervolume, "-", color="C0", drawstyle="steps-post",
            label=kind)
    ax.axhline(curve.hypervolume[-1], ls=":", color="0.5", lw=1,
               label=f"final: {curve.hypervolume[-1]:.4g}")
    ax.set_xlabel("designs evaluated")
    ax.set_ylabel("hypervolume of the front found [-]")
    ax.set_title(f"objectives scaled to [0, 1] between the final front's best and worst, "
                 f"reference point {REFERENCE_POINT:g}", fontsize=8)
    ax.set_ylim(bottom=0.0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def scatter_matrix(X: Array, feasible: Array, names: Sequence[str]) -> Figure:
    """Every pair of varied lengths (mm; tied lengths are one axis), feasible designs in
    blue, the others in grey."""
    k = X.shape[1]
    fig = mfigure.Figure(figsize=(2.2 * k + 1, 2.2 * k + 1))
    axes = fig.subplots(k, k, squeeze=False)
    for i in range(k):
        for j in range(k):
            ax = axes[i, j]
            if i == j:
                ax.hist([X[feasible, i], X[~feasible, i]], bins=20, stacked=True,
                        color=["C0", "0.7"])
            else:
                ax.scatter(X[~feasible, j], X[~feasible, i], s=3, color="0.7")
                ax.scatter(X[feasible, j], X[feasible, i], s=3, color="C0")
            if i == k - 1:
                ax.set_xlabel(names[j])
            if j == 0:
                ax.set_ylabel(names[i])
            ax.tick_params(labelsize=7)
    fig.suptitle("designs: feasible (blue) and not (grey)")
    fig.tight_layout()
    return fig


def design_report(summary: Mapping[str, Any], pareto_rows: Sequence[Mapping[str, Any]],
                  pngs: dict[str, bytes]) -> str:
    """The sweep's report: counts, the chosen design, the Pareto designs, the figures."""
    esc = html.escape
    labels = {"designs": "designs", "feasible": "feasible designs",
              "feasible_fraction": "feasible fraction", "pareto": "Pareto designs",
              "objectives": "objectives (minimised; - maximises)", "search": "search",
              "population": "population", "seed": "seed", "workers": "workers",
              "final_hypervolume": "hypervolume of the front (scaled by it)",
              "wall_time_s": "wall time [s]",
              "designs_per_second": "designs per second", "evaluated": "evaluated",
              "resumed": "resumed from an earlier run"}
    facts = table([(label, _rounded(summary[k])) for k, label in labels.items()
                   if k in summary])
    variables = row_columns(pareto_rows[0]) if pareto_rows else LENGTHS
    pareto = grid([c for c in columns(variables) if c not in ("feasible", "reason")],
                  [(r["design"], *(_rounded(r[k]) for k in variables), r.get("motor", ""),
                    *(_rounded(r[k]) for k in METRICS)) for r in pareto_rows])
    best = summary.get("best")
    chosen = (f"<p>Chosen (the Pareto design closest to the ideal point): design "
              f"{best['design']}, l1 = {best['l1']:.4g}, l2 = {best['l2']:.4g}, L1 = "
              f"{best['L1']:.4g}, L2 = {best['L2']:.4g}, d = {best['d']:.4g} mm; written to "
              "best.toml.</p>") if best else "<p>No feasible design.</p>"
    what = "search" if summary.get("search") in SEARCHES else "sweep"
    return page(f"Design {what} of {Path(str(summary['task'])).name}",
                f"<p>Task file {esc(str(summary['task']))}.</p>{facts}{chosen}"
                f"<h2>Pareto designs</h2>{pareto}<h2>Figures</h2>{figures(pngs)}")


def _rounded(v: Any) -> Any:
    """A number to 4 significant digits for a table (other values as they are)."""
    return float(f"{v:.4g}") if isinstance(v, float) else v


class DesignsFile:
    """``designs.csv`` of a sweep or search in an output directory, with ``sweep.json`` (its
    signature).

    Opened fresh, or to ``resume`` (the complete rows of the same run kept, a line cut
    short by a kill dropped); the directory's own checks (empty, ``--force``) are
    :class:`~dextar.output.files.OutputDir`'s. Rows are appended as chunks finish (flushed to
    disk each time); :meth:`finish` rewrites the file in design order, atomically."""

    def __init__(self, od: OutputDir, designs: Array | None, signature: str, *, resume: bool,
                 label: str, variables: Sequence[str] | None = None) -> None:
        """Read the rows to resume (of a sweep's ``designs``, their values checked; of a
        search's, ``designs`` None: the search checks each against its proposal); nothing
        is written yet. ``variables`` are the design's columns (default: from the width of
        ``designs``; a search's must be given).

        Raises
        ------
        ConfigError
            ``resume`` without a run of the same signature, or with rows of other lengths.
        """
        self.od, self.designs, self.signature = od, designs, signature
        if variables is not None:
            self.variables = tuple(variables)
        elif designs is not None:
            self.variables = columns_of_width(designs.shape[1])
        else:
            raise ValueError("a search's designs file needs its variables")
        self.csv, self.meta = od.path / "designs.csv", od.path / "sweep.json"
        self.rows: dict[int, dict[str, Any]] = {}
        self._fh: Any = None
        if resume:
            self._resume(label)

    def _resume(self, label: str) -> None:
        designs = self.designs
        n = len(designs) if designs is not None else MAX_DESIGNS
        if not (self.csv.is_file() and self.meta.is_file()):
            raise ConfigError(f"--resume: {label} holds no sweep to resume (designs.csv and "
                              "sweep.json)")
        try:
            same = json.loads(self.meta.read_text()).get("signature") == self.signature
        except (ValueError, OSError):
            same = False
        if not same:
            raise ConfigError(f"--resume: the sweep in {label} was made with another task, "
                              "[design] or --samples/--seed; rerun without --resume (and "
                              "--force to overwrite it)")
        for line in self.csv.read_text().splitlines(keepends=True)[1:]:
            r = parse_line(line, self.variables)
            if r is None or not 0 <= r["design"] < n:
                continue
            if designs is not None and not np.allclose([r[k] for k in self.variables],
                                                       designs[r["design"]], rtol=1e-12):
                raise ConfigError(f"--resume: design {r['design']} in {self.csv} has other "
                                  "lengths than this sweep's")
            self.rows[r["design"]] = r

    def __enter__(self) -> DesignsFile:
        write_text(self.meta, json.dumps({"signature": self.signature} | (
            {} if self.designs is None else {"designs": len(self.designs)})) + "\n")
        write_text(self.csv, header(self.variables) + "".join(
            row_line(self.rows[i]) for i in sorted(self.rows)))
        self.od.record("sweep.json")
        self.od.record("designs.csv")
        self._fh = open(self.csv, "a", encoding="utf-8")  # noqa: SIM115 - closed in __exit__
        return self

    def append(self, rows: list[dict[str, Any]]) -> None:
        """Append a finished chunk's rows and flush them to disk."""
        for r in rows:
            self.rows[r["design"]] = r
        self._fh.write("".join(row_line(r) for r in rows))
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def __exit__(self, *exc: object) -> None:
        self._fh.close()

    def finish(self, n: int) -> list[dict[str, Any]]:
        """The rows of designs ``0 .. n - 1`` in design order, the file rewritten so
        (atomically)."""
        ordered = [self.rows[i] for i in range(n)]
        write_text(self.csv, header(self.variables) + "".join(row_line(r) for r in ordered))
        return ordered


def reason_counts(rows: Sequence[Mapping[str, Any]]) -> dict[str, int]:
    """How many designs failed for each kind of reason."""
    kinds = (("geometry", "geometry"), ("motors exceeded", "motors exceeded"),
             ("singularity", "singularity"), ("out of reach", "unreachable"),
             ("internal error", "internal error"))
    out: dict[str, int] = {}
    for r in rows:
        if not r["feasible"]:
            text = str(r["reason"])
            kind = next((name for key, name in kinds if key in text), "other")
            out[kind] = out.get(kind, 0) + 1
    return out


def sweep_summary(task_file: str, kind: str, space: DesignSpace, stats: SweepStats,
                  choice: Choice, rows: Sequence[Mapping[str, Any]],
                  search: SearchSettings | None = None,
                  hypervolume: HypervolumeCurve | None = None) -> dict[str, Any]:
    """``summary.json`` of a sweep or search: counts, the sampling or the search, the run's
    figures, the hypervolume against the designs evaluated, the chosen design and the
    reasons designs failed."""
    n = len(rows)
    how: dict[str, Any] = ({"search": space.sampling, "sampling": space.sampling,
                            "seed": space.seed} if search is None else
                           {"search": search.kind, "population": search.population,
                            "evaluations": search.evaluations, "seed": search.seed,
                            "batch": search.batch, "batches_in_flight": search.in_flight})
    hv: dict[str, Any] = {}
    if hypervolume is not None:
        hv = {"final_hypervolume": float(hypervolume.hypervolume[-1]),
              "hypervolume": {"evaluations": hypervolume.evaluations.tolist(),
                              "value": hypervolume.hypervolume.tolist(),
                              "ideal": hypervolume.ideal.tolist(),
                              "nadir": hypervolume.nadir.tolist(),
                              "reference_point": REFERENCE_POINT}}
    return {
        "task": task_file, "task_kind": kind, "designs": n,
        "feasible": len(choice.feasible), "feasible_fraction": len(choice.feasible) / n,
        "objectives": list(space.objectives), **how,
        "varied": [name for name, *_ in space.dims],
        "mass_per_length_kg_m": (list(space.mass_per_length) if space.mass_per_length
                                 else None),
        "evaluated": stats.evaluated, "resumed": n - stats.evaluated,
        "workers": stats.workers, "wall_time_s": stats.wall_s,
        "designs_per_second": stats.evaluated / stats.wall_s if stats.wall_s > 0 else 0.0,
        "pareto": len(choice.pareto_rows), "best": choice.best_row,
        "reasons": reason_counts(rows), **hv}


def best_workspace_figure(robot_mm: FiveBar, mode: str, P: Array) -> Figure:
    """The chosen design's workspace with the task's path."""
    ws = workspace_map(robot_mm, mode, resolution=241)
    fig: Figure = plot_workspace(ws, path=P, unit="mm")
    fig.axes[0].set_title(f"chosen design: l1 = {robot_mm.l1:.4g}, l2 = {robot_mm.l2:.4g}, "
                          f"L1 = {robot_mm.L1:.4g},\nL2 = {robot_mm.L2:.4g}, d = "
                          f"{robot_mm.d:.4g} mm (working mode {mode})", fontsize=9)
    return fig


def write_sweep_outputs(od: OutputDir, summary: Mapping[str, Any], choice: Choice,
                        rows: Sequence[Mapping[str, Any]], varied: Sequence[tuple[int, str]],
                        best_toml: str | None, best_figure: Figure | None, *,
                        with_figures: bool = True,
                        hypervolume: HypervolumeCurve | None = None) -> None:
    """Write ``best.toml`` (with a feasible design), ``pareto.csv``, the figures (PNG and
    SVG: the front, the designs, the chosen robot's workspace, the hypervolume against the
    designs evaluated), ``report.html`` and ``summary.json`` into the run's directory."""
    pngs: dict[str, bytes] = {}
    if best_toml is not None:
        od.write_text("best.toml", best_toml)
    variables = row_columns(rows[0]) if rows else LENGTHS
    if with_figures and choice.best >= 0 and best_figure is not None:
        X = np.array([[r[k] for k in variables] for r in rows])
        names = list(summary["objectives"])
        for name, fig in (
                ("pareto", pareto_figure(choice.F, choice.pareto, choice.best, names)),
                ("designs", scatter_matrix(X[:, [c for c, _ in varied]],
                                           np.array([r["feasible"] for r in rows]),
                                           [f"{label} [{UNITS[variables[c]]}]"
                                            if UNITS[variables[c]] else label
                                            for c, label in varied])),
                ("best_workspace", best_figure),
                *((("hypervolume", hypervolume_figure(hypervolume, str(summary["search"]))),)
                  if hypervolume is not None else ())):
            pngs[name] = png_bytes(fig)
            od.write_bytes(f"{name}.png", pngs[name])
            od.write_bytes(f"{name}.svg", svg_bytes(fig))
    od.write_text("pareto.csv", header(variables)
                  + "".join(row_line(r) for r in choice.pareto_rows))
    if with_figures:
        od.write_text("report.html", design_report(summary, choice.pareto_rows, pngs))
    od.write_text("summary.json", json.dumps(summary, indent=2, allow_nan=False) + "\n")
