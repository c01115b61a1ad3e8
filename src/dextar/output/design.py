"""Writing a design sweep: the rows of ``designs.csv`` (one formatting for rows fresh and
resumed, so a resumed sweep ends with the same bytes), the figures and the report."""

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


def columns(variables: Sequence[str] = LENGTHS) -> tuple[str, ...]:
    """The columns of designs.csv and pareto.csv for designs of ``variables`` (the lengths,
    and the counterweights and motor indices a sweep varies), each with its unit."""
    return ("design", *(f"{k}_{UNITS[k]}" if UNITS[k] else k for k in variables), "feasible",
            "reason", "motor", *METRICS)


#: Columns of designs.csv and pareto.csv of a sweep of the lengths.
COLUMNS = columns()


#: Every file a sweep may write.
DESIGN_FILES = ("designs.csv", "sweep.json", "pareto.csv", "best.toml", "summary.json",
                "report.html", *(f"{n}.{e}" for n in ("pareto", "designs", "best_workspace")
                                 for e in ("png", "svg")))


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
    """The feasible designs on the first two objectives (minimised; a maximised objective
    is drawn with its sign), the Pareto designs marked, the chosen one starred."""
    fig = mfigure.Figure(figsize=(6.0, 4.6))
    ax = fig.subplots()
    if F.shape[1] == 1:
        ax.plot(np.sort(F[:, 0]), ".", color="0.6", label="feasible designs (sorted)")
        ax.set_ylabel(names[0])
        ax.set_xlabel("rank")
    else:
        ax.scatter(F[:, 0], F[:, 1], s=8, color="0.7", label="feasible designs")
        ax.scatter(F[pareto, 0], F[pareto, 1], s=18, color="C0", label="Pareto designs")
        ax.scatter(F[best, 0], F[best, 1], s=140, marker="*", color="C3", label="chosen")
        ax.set_xlabel(names[0])
        ax.set_ylabel(names[1])
        if F.shape[1] > 2:
            ax.set_title(f"Pareto on {F.shape[1]} objectives ({', '.join(names)}), shown on "
                         "the first two", fontsize=8)
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
              "objectives": "objectives (minimised; - maximises)", "sampling": "sampling",
              "seed": "seed", "workers": "workers", "wall_time_s": "wall time [s]",
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
    return page(f"Design sweep of {Path(str(summary['task'])).name}",
                f"<p>Task file {esc(str(summary['task']))}.</p>{facts}{chosen}"
                f"<h2>Pareto designs</h2>{pareto}<h2>Figures</h2>{figures(pngs)}")


def _rounded(v: Any) -> Any:
    """A number to 4 significant digits for a table (other values as they are)."""
    return float(f"{v:.4g}") if isinstance(v, float) else v


class DesignsFile:
    """``designs.csv`` of a sweep in an output directory, with ``sweep.json`` (the sweep's
    signature).

    Opened fresh, or to ``resume`` (the complete rows of the same sweep kept, a line cut
    short by a kill dropped); the directory's own checks (empty, ``--force``) are
    :class:`~dextar.output.files.OutputDir`'s. Rows are appended as chunks finish (flushed to
    disk each time); :meth:`finish` rewrites the file in design order, atomically."""

    def __init__(self, od: OutputDir, designs: Array, signature: str, *, resume: bool,
                 label: str, variables: Sequence[str] | None = None) -> None:
        """Read the rows to resume; nothing is written yet.

        Raises
        ------
        ConfigError
            ``resume`` without a sweep of the same signature, or with rows of other lengths.
        """
        self.od, self.designs, self.signature = od, designs, signature
        self.variables = tuple(variables) if variables is not None else columns_of_width(
            designs.shape[1])
        self.csv, self.meta = od.path / "designs.csv", od.path / "sweep.json"
        self.rows: dict[int, dict[str, Any]] = {}
        self._fh: Any = None
        if resume:
            self._resume(label)

    def _resume(self, label: str) -> None:
        designs, n = self.designs, len(self.designs)
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
            if not np.allclose([r[k] for k in self.variables], designs[r["design"]],
                               rtol=1e-12):
                raise ConfigError(f"--resume: design {r['design']} in {self.csv} has other "
                                  "lengths than this sweep's")
            self.rows[r["design"]] = r

    @property
    def missing(self) -> list[int]:
        """The designs without a row."""
        return [i for i in range(len(self.designs)) if i not in self.rows]

    def __enter__(self) -> DesignsFile:
        write_text(self.meta, json.dumps({"signature": self.signature,
                                          "designs": len(self.designs)}) + "\n")
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

    def finish(self) -> list[dict[str, Any]]:
        """Every row in design order, the file rewritten so (atomically)."""
        ordered = [self.rows[i] for i in range(len(self.designs))]
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
                  choice: Choice, rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """``summary.json`` of a sweep: counts, the sampling, the run's figures, the chosen
    design and the reasons designs failed."""
    n = len(rows)
    return {
        "task": task_file, "task_kind": kind, "designs": n,
        "feasible": len(choice.feasible), "feasible_fraction": len(choice.feasible) / n,
        "objectives": list(space.objectives), "sampling": space.sampling, "seed": space.seed,
        "varied": [name for name, *_ in space.dims],
        "mass_per_length_kg_m": (list(space.mass_per_length) if space.mass_per_length
                                 else None),
        "evaluated": stats.evaluated, "resumed": n - stats.evaluated,
        "workers": stats.workers, "wall_time_s": stats.wall_s,
        "designs_per_second": stats.evaluated / stats.wall_s if stats.wall_s > 0 else 0.0,
        "pareto": len(choice.pareto_rows), "best": choice.best_row,
        "reasons": reason_counts(rows)}


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
                        with_figures: bool = True) -> None:
    """Write ``best.toml`` (with a feasible design), ``pareto.csv``, the figures (PNG and
    SVG), ``report.html`` and ``summary.json`` into the sweep's directory."""
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
                ("best_workspace", best_figure)):
            pngs[name] = png_bytes(fig)
            od.write_bytes(f"{name}.png", pngs[name])
            od.write_bytes(f"{name}.svg", svg_bytes(fig))
    od.write_text("pareto.csv", header(variables)
                  + "".join(row_line(r) for r in choice.pareto_rows))
    if with_figures:
        od.write_text("report.html", design_report(summary, choice.pareto_rows, pngs))
    od.write_text("summary.json", json.dumps(summary, indent=2, allow_nan=False) + "\n")
