"""Writing a robot program: ``setpoints.csv``, its summary (typed, :class:`ProgramSummary`),
the figures (the moves on the workspace map, the joint motion and torques against time with
the limits, each motor's torque-speed operating points against its envelope: the plot a
drive engineer sizes motors with) and the report."""

from __future__ import annotations

import html
import json
from collections.abc import Callable
from dataclasses import asdict, dataclass
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._arrays import Array
from ..geometry import FiveBar
from ..kinematics import workspace_map
from ..program import ModeChoice, MoveTiming, ProgramResult, RmsFit, Sizing
from ..program.drive import DriveUnits, PvtPoints, csp_columns, pvt_points
from ..program.sizing import SIZING_TOLERANCES
from .figures import new_figure, plot_workspace, png_bytes, svg_bytes, tight_layout, warm_up
from .files import OutputDir
from .html_page import figures, grid, page
from .parallel import Job, render
from .tables import csv_text

if TYPE_CHECKING:
    from matplotlib.figure import Figure


#: A program's figures (each as PNG and SVG).
FIGURES = ("moves", "motion", "operating_points")
#: Every file a program may write (``csp.csv`` and ``pvt.csv`` with a ``[drive]`` table).
PROGRAM_FILES = ("setpoints.csv", "summary.json", "report.html", "csp.csv", "pvt.csv",
                 *(f"{n}.{e}" for n in FIGURES for e in ("png", "svg")))
#: What the units of a program's outputs are.
UNITS = "SI: s, rad, N m, W, J; positions in mm in setpoints.csv"
#: What the joint angles of ``setpoints.csv`` are.
ANGLES = ("phi_rad, psi_rad in setpoints.csv are encoder readings: geometric "
          "angle - [robot].encoder_offset_deg")


@dataclass(frozen=True)
class ProgramSummary:
    """What a planned program comes to (``summary.json``), read by the report and the
    command's words.

    Attributes
    ----------
    config : str
        The task file.
    cycle_time_s, servo_rate_hz : float
    moves : tuple of MoveTiming
        Every move of the program, in order.
    sizing : Sizing
    encoder_offset_deg : (float, float)
        ``[robot].encoder_offset_deg``: the setpoints' angles are encoder readings, the
        geometric angles minus these.
    mode_choice : ModeChoice, optional
        The working modes the planner chose (``working_mode = "auto"``).
    """

    config: str
    cycle_time_s: float
    servo_rate_hz: float
    moves: tuple[MoveTiming, ...]
    sizing: Sizing
    rms_fit: RmsFit | None = None
    drive: dict[str, Any] | None = None
    encoder_offset_deg: tuple[float, float] = (0.0, 0.0)
    mode_choice: ModeChoice | None = None

    @property
    def units(self) -> str:
        """The units of the outputs, the setpoints' angles included."""
        a, b = self.encoder_offset_deg
        return f"{UNITS}; {ANGLES} [{a:g}, {b:g}] deg"

    @property
    def status(self) -> str:
        """``"fits"`` or ``"exceeds"`` (the motors, or the drives: :attr:`verdict`)."""
        return "fits" if self.sizing.fits else "exceeds"

    @property
    def verdict(self) -> str:
        """The status with whose limits it is about: ``"fits the motors"`` (``"... and the
        drives"`` with ``[drive]``), ``"exceeds the drives"``, ..."""
        if self.sizing.fits:
            return "fits the motors" + (" and the drives" if self.drive is not None else "")
        return f"exceeds {self.sizing.exceeded}"

    def as_json(self) -> dict[str, Any]:
        """``summary.json``."""
        out = {"status": self.status, "cycle_time_s": self.cycle_time_s,
               "servo_rate_hz": self.servo_rate_hz, "config": self.config,
               "moves": [asdict(m) for m in self.moves],
               "motors": [m.as_dict() for m in self.sizing.motors],
               "violations": [v.as_dict() for v in self.sizing.violations], "encoder_offset_deg": list(self.encoder_offset_deg),
               "tolerances": SIZING_TOLERANCES, "units": self.units}
        if self.rms_fit is not None:
            out["rms_fit"] = self.rms_fit.as_dict()
        if self.mode_choice is not None:
            out["mode_choice"] = self.mode_choice.as_dict()
        if self.drive is not None:
            out["drive"] = self.drive
        return out

    def lines(self, out: str, samples: int, figures: bool = False) -> list[str]:
        """The summary in words (``figures``: the figures and ``report.html`` were written
        too)."""
        return [
            f"program: cycle time {self.cycle_time_s:.6g} s, "
            f"{sum(not m.mode_change for m in self.moves)} moves; {self.verdict}",
            *self.mode_lines(),
            *(f"  move {m.index} ({m.type}{self._mode_words(m)}): {m.law or 'dwell'} "
              f"{m.duration_s:.4g} s from {m.start_s:.4g} s"
              + (", blended into the next" if m.blended_with_next else "")
              for m in self.moves),
            *(crossing_line(m.index, c) for m in self.moves for c in m.crossings),
            *(f"  motor {m.motor}: peak {m.peak_torque_Nm:.4g} N m, RMS {m.rms_torque_Nm:.4g} "
              f"N m, peak speed {m.peak_speed_rad_s:.4g} rad/s" for m in self.sizing.motors),
            *([] if self.rms_fit is None else [
                f"  cycle fitted within the RMS ratings: bound by the {self.rms_fit.bound_by} "
                f"(peak torques planned at {self.rms_fit.peak_scale:.4g} of the motors'; RMS "
                f"ratios {self.rms_fit.rms_ratio[0]:.4f}, {self.rms_fit.rms_ratio[1]:.4f}; "
                f"{self.rms_fit.plans} plans)"]),
            *([] if self.drive is None else [
                f"  drive: PVT points every {1e3 * float(self.drive['pvt_period_s']):g} ms "
                f"within {float(self.drive['pvt_max_error_counts']):.3g} counts of the plan; "
                + "; ".join(f"motor {m['motor']} peak {m['peak_speed_rpm']:.4g} rpm, "
                            f"{m['peak_torque_Nm']:.4g} N m" for m in self.drive["motors"])]),
            f"wrote {Path(out) / 'setpoints.csv'} ({samples} setpoints at "
            f"{self.servo_rate_hz:g} Hz{self._angles_note()})"
            + (f", {Path(out) / 'csp.csv'}, {Path(out) / 'pvt.csv'}" if self.drive else "")
            + (f", {Path(out) / 'summary.json'}, {Path(out) / 'report.html'} and the figures "
               f"({', '.join(FIGURES)}: .png and .svg)" if figures
               else f" and {Path(out) / 'summary.json'}")]

    def mode_lines(self) -> list[str]:
        """The working modes the planner chose, in words (none without auto)."""
        c = self.mode_choice
        if c is None:
            return []
        changes = (f"; a change of mode before move{'s' if len(c.changes) > 1 else ''} "
                   + ", ".join(str(i) for i in c.changes)) if c.changes else ""
        return [f"  working modes chosen by the planner: start {c.start_mode}, then "
                + " ".join(c.modes) + f" (the shortest cycle of {c.plans} motions "
                f"planned{changes})"]

    def _mode_words(self, m: MoveTiming) -> str:
        if m.mode_change:
            return f", change of working mode to {m.working_mode}"
        return f", {m.working_mode}" if self.mode_choice is not None else ""

    def _angles_note(self) -> str:
        if self.encoder_offset_deg == (0.0, 0.0):
            return ""
        a, b = self.encoder_offset_deg
        return f"; angles in encoder readings, offsets [{a:g}, {b:g}] deg"


def crossing_line(index: int, c: dict[str, Any]) -> str:
    """A crossing of the parallel singularity curve in words (``summary.json``'s entry)."""
    x, y = c["point_mm"]
    peak = ", ".join(f"{v:.4g}" for v in c["torque_peak_Nm"])
    ratio = "" if c["torque_peak_ratio"] is None else (
        " (" + ", ".join(f"{v:.4f}" for v in c["torque_peak_ratio"]) + " of the peak torque)")
    return (f"  move {index} crosses the parallel singularity curve at ({x:.4g}, {y:.4g}) mm "
            f"at t = {c['time_s']:.6g} s, {c['speed_mm_s']:.4g} mm/s, assembly mode "
            f"{c['assembly_before']} -> {c['assembly_after']}: degeneracy condition's residual "
            f"{c['residual_N']:.3g} N ({c['residual_ratio']:.2g} of its terms), torque peak "
            f"near it {peak} N m{ratio}")


def setpoint_columns(res: ProgramResult,
                     encoder_offset_deg: tuple[float, float] = (0.0, 0.0)) -> dict[str, Array]:
    """``setpoints.csv``: time, move, end-effector (mm), joint motion in encoder readings
    (the geometric angles minus ``encoder_offset_deg``) and torques (SI)."""
    off = np.radians(encoder_offset_deg)
    return {"t_s": res.t, "move": res.move_index, "x_mm": res.P[:, 0] * 1e3,
            "y_mm": res.P[:, 1] * 1e3, "phi_rad": res.q[:, 0] - off[0],
            "psi_rad": res.q[:, 1] - off[1],
            "dphi_rad_s": res.dq[:, 0], "dpsi_rad_s": res.dq[:, 1],
            "ddphi_rad_s2": res.ddq[:, 0], "ddpsi_rad_s2": res.ddq[:, 1],
            "tau1_Nm": res.tau[:, 0], "tau2_Nm": res.tau[:, 1]}


def write_program(out: str, res: ProgramResult, summary: ProgramSummary, robot_mm: FiveBar,
                  mode: str, *, force: bool = False, with_figures: bool = True,
                  drive: DriveUnits | None = None, pvt: PvtPoints | None = None) -> None:
    """Write ``setpoints.csv``, the figures (PNG and SVG), ``report.html`` and
    ``summary.json`` into ``out``, and with ``drive`` ``csp.csv`` and ``pvt.csv`` (the PVT
    points ``pvt``, computed from the drive when not given)."""
    with OutputDir(out, force=force, produces=PROGRAM_FILES) as od:
        od.write_text("setpoints.csv", _counts_csv(setpoint_columns(
            res, summary.encoder_offset_deg)))
        if drive is not None:
            od.write_text("csp.csv", _counts_csv(csp_columns(res, drive)))
            od.write_text("pvt.csv", _counts_csv((pvt or pvt_points(res, drive)).columns()))
        if with_figures:
            pngs: dict[str, bytes] = {}
            for name, (png, svg) in _figures(res, summary, robot_mm, mode).items():
                pngs[name] = png
                od.write_bytes(f"{name}.png", png)
                od.write_bytes(f"{name}.svg", svg)
            od.write_text("report.html", program_report(summary, pngs))
        od.write_text("summary.json", json.dumps(summary.as_json(), indent=2,
                                                 allow_nan=False) + "\n")


def _counts_csv(columns: dict[str, Array]) -> str:
    """CSV of the setpoints and the drive files: the move index, positions in counts and
    torques in per-mille as whole numbers, the other columns as :func:`csv_text` writes
    them (the shortest text that reads back to the same double); a value that is not finite
    is a :class:`~dextar.errors.NumericalError` naming its column and row."""
    names = list(columns)
    texts = []
    for n in names:
        v = np.asarray(columns[n], dtype=float) + 0.0  # + 0.0: no negative zeros
        if not np.isfinite(v).all():
            csv_text({n: v})  # raises, naming the column and row
        whole = n == "move" or n.startswith(("pos", "torque"))
        texts.append([str(int(x)) for x in v.tolist()] if whole else
                     list(map(repr, v.tolist())))
    return ",".join(names) + "\n" + "".join(",".join(r) + "\n" for r in zip(*texts, strict=True))


def _figures(res: ProgramResult, summary: ProgramSummary, robot_mm: FiveBar, mode: str
             ) -> dict[str, tuple[bytes, bytes]]:
    """Each figure's PNG and SVG, drawn on two cores where there are two
    (:mod:`dextar.output.parallel`)."""
    makers: dict[str, Callable[[], Figure]] = dict(zip(FIGURES, (
        lambda: moves_figure(res, robot_mm, mode), lambda: motion_figure(res),
        lambda: operating_points_figure(res, summary.sizing)), strict=True))

    def files(name: str) -> tuple[bytes, bytes]:
        fig = makers[name]()
        return png_bytes(fig), svg_bytes(fig)

    costs = {"moves": 1.0, "motion": 1.3, "operating_points": 1.1}  # measured: the order taken
    jobs: dict[str, Job[tuple[bytes, bytes]]] = {n: (partial(files, n), costs[n])
                                                 for n in makers}
    warm_up(mathtext=False)  # (no mathtext in a program's figures)
    return render(jobs)


def crossing_points(res: ProgramResult) -> Array:
    """Where the program's moves cross the parallel singularity curve (k, 2), mm."""
    pts = [1e3 * np.asarray(c.crossing.P) for pm in res.moves for c in pm.crossings]
    return np.array(pts).reshape(-1, 2)


def crossing_times(res: ProgramResult) -> Array:
    """When the program's moves cross the parallel singularity curve (k,), s."""
    return np.array([pm.start_s + c.t for pm in res.moves for c in pm.crossings])


def mode_changes(res: ProgramResult, mode: str) -> Array:
    """Where a move ends in another working mode than it started in (k, 2), mm."""
    out, prev = [], mode
    for pm in res.moves:
        if pm.mode and pm.mode != prev:
            out.append(1e3 * np.asarray(pm.sample(np.array([pm.duration_s]))[0][-1]))
        prev = pm.mode or prev
    return np.array(out).reshape(-1, 2)


def mode_samples(res: ProgramResult, mode: str) -> dict[str, Array]:
    """The setpoints (masks (n,)) in each working mode the program visits, in the order
    visited: a move's samples in its mode, a change of working mode's in both."""
    out: dict[str, Array] = {mode: np.zeros(len(res.t), bool)}
    prev = mode
    for k, pm in enumerate(res.moves):
        now = pm.mode or prev
        end = res.moves[k + 1].start_s if k + 1 < len(res.moves) else np.inf  # the last: held
        inside = (res.t >= pm.start_s - 1e-12) & (res.t <= end + 1e-12)
        for m in {prev, now}:
            out[m] = out.get(m, np.zeros(len(res.t), bool)) | inside
        prev = now
    return out


def moves_figure(res: ProgramResult, robot_mm: FiveBar, mode: str) -> Figure:
    """The end-effector's path over the workspace map of each working mode it runs in (its
    assembly modes' regions and singularity curves; a panel per working mode, the moves in
    that mode drawn on it), each move numbered at its middle, the crossings of the parallel
    singularity curve (red stars) and the working-mode changes (black diamonds) marked."""
    spans = mode_samples(res, mode)
    n = len(spans)
    cols = min(n, 2)
    rows = -(-n // cols)
    fig: Figure = new_figure((7.0 * cols, 5.6 * rows))
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax in axes[n:]:
        ax.remove()
    pts = res.P * 1e3
    span = float(np.ptp(pts, axis=0).max()) or 1.0
    lo, hi = pts.min(axis=0) - 0.35 * span, pts.max(axis=0) + 0.35 * span  # the moves' region
    changes = mode_changes(res, mode)
    crossings = crossing_points(res)
    title = (f"Program: {len(res.move_types) or len(res.moves)} moves, cycle "
             f"{res.cycle_time_s:.3f} s")
    for ax, (m, inside) in zip(axes[:n], spans.items(), strict=True):
        ws = workspace_map(robot_mm, m, resolution=241)
        path = pts if n == 1 else np.where(inside[:, None], pts, np.nan)
        plot_workspace(ws, path=path, unit="mm", ax=ax, crossings=crossings)
        if len(changes):
            ax.plot(changes[:, 0], changes[:, 1], "D", color="black", mec="white", ms=8,
                    label="working-mode change")
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        _number_moves(ax, res, inside if n > 1 else np.ones(len(res.t), bool), span)
        if n == 1:
            ax.set_title(f"{title} (working mode at the start: {mode})", fontsize=10)
        else:
            ax.set_title(f"the moves in working mode {m}", fontsize=10)
    if n > 1:
        fig.suptitle(f"{title}, in {n} working modes (start: {mode})", fontsize=11)
    # one legend below the maps, where it covers no move (a move's number at a map's lower
    # right had been hidden under the map's own legend)
    entries: dict[str, Any] = {}
    for ax in axes[:n]:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
        if ax.get_legend() is not None:
            ax.get_legend().remove()
    fig.subplots_adjust(bottom=1.05 / fig.get_figheight())
    fig.legend(list(entries.values()), list(entries), loc="lower center", ncol=3, fontsize=8,
               frameon=False)
    return fig


#: Two moves' numbers closer than this fraction of the moves' extent would touch (the
#: map spans 1.7 times it; a number's circle is about a twentieth of the map): the second
#: is moved aside.
LABEL_GAP = 0.1


def _number_moves(ax: Any, res: ProgramResult, inside: Array, span: float) -> None:
    """Each move's number at its middle (of its samples in ``inside``)."""
    placed: list[Array] = []
    for index in np.unique(res.move_index[inside]):
        P = res.P[(res.move_index == index) & inside] * 1e3
        at = P[len(P) // 2]
        # a label that would sit on another's (a move back over the same segment, a dwell
        # at a move's end) is moved aside, with a leader line to its move
        near = sum(bool(np.hypot(*(at - p)) < LABEL_GAP * span) for p in placed)
        placed.append(at)
        ax.annotate(str(int(index)), at, xytext=(14 * near, 12 * near),
                    textcoords="offset points", fontsize=8, color="white",
                    bbox={"boxstyle": "circle,pad=0.2", "fc": "black", "alpha": 0.7},
                    arrowprops={"arrowstyle": "-", "color": "black", "lw": 0.6} if near
                    else None)


def motion_figure(res: ProgramResult) -> Figure:
    """Joint angles, speeds and torques against time, move boundaries dotted, limits dashed;
    with the joint accelerations when the motors limit them or their jerk, the joint jerks
    (finite differences of the setpoints) when they limit the jerk, and the torque rates
    when they limit those, each with its limits."""
    m = res.motors
    t = res.t
    acc = m is not None and (m.max_acceleration is not None or m.max_jerk is not None)
    jerk = m is not None and m.max_jerk is not None
    rate = m is not None and m.max_torque_rate is not None
    rows = 3 + acc + jerk + rate
    fig = new_figure((7.0, 2.6 * rows + 0.2))
    axes = list(fig.subplots(rows, 1, sharex=True))
    ax_q, ax_v = axes[0], axes[1]
    ax_a = axes[2] if acc else None
    ax_j = axes[2 + acc] if jerk else None
    ax_r = axes[2 + acc + jerk] if rate else None
    ax_tau = axes[-1]
    labels = ("motor A", "motor D")
    dt = np.diff(t)
    safe = np.where(dt > 0, dt, np.inf)[:, None]
    tm = 0.5 * (t[1:] + t[:-1])
    for i in range(2):
        ax_q.plot(t, np.degrees(res.q[:, i]), label=labels[i])
        ax_v.plot(t, res.dq[:, i], label=labels[i])
        ax_tau.plot(t, res.tau[:, i], label=labels[i])
        if ax_a is not None:
            ax_a.plot(t, res.ddq[:, i], label=labels[i])
        if ax_j is not None:
            ax_j.plot(tm, np.diff(res.ddq[:, i]) / safe[:, 0], label=labels[i])
        if ax_r is not None:
            ax_r.plot(tm, np.diff(res.tau[:, i]) / safe[:, 0], label=labels[i])
    if m is not None:
        for i, style in ((0, "C0"), (1, "C1")):
            limits = [(ax_v, m.max_speed[i])]
            if ax_a is not None and m.max_acceleration is not None:
                limits.append((ax_a, m.max_acceleration[i]))
            if ax_j is not None and m.max_jerk is not None:
                limits.append((ax_j, m.max_jerk[i]))
            if ax_r is not None and m.max_torque_rate is not None:
                limits.append((ax_r, m.max_torque_rate[i]))
            for ax, lim in limits:
                if np.isfinite(lim):
                    for sgn in (1, -1):
                        ax.axhline(sgn * lim, color=style, ls="--", lw=0.8)
            avail = m.available_torque(res.dq)[:, i]
            ax_tau.plot(t, avail, color=style, ls="--", lw=0.8)
            ax_tau.plot(t, -avail, color=style, ls="--", lw=0.8)
    changes = t[1:][np.diff(res.move_index) != 0]  # where the next move starts
    crossed = crossing_times(res)
    for ax in axes:
        for tc in changes:
            ax.axvline(tc, color="grey", ls=":", lw=0.8)
        for tc in crossed:
            ax.axvline(tc, color="red", ls="-.", lw=0.9)
        ax.grid(alpha=0.3)
    ax_q.set_ylabel("angle [deg]")
    ax_v.set_ylabel("speed [rad/s]")
    if ax_a is not None:
        ax_a.set_ylabel("acceleration [rad/s^2]")
    if ax_j is not None:
        ax_j.set_ylabel("jerk [rad/s^3]")
    if ax_r is not None:
        ax_r.set_ylabel("torque rate [N m/s]")
    ax_tau.set_ylabel("torque [N m]")
    ax_tau.set_xlabel("time [s]")
    ax_q.legend(fontsize=8)
    ax_q.set_title("Joint motion and torques (dashed: the motors' limits; dotted: moves"
                   + ("; red: type-2 crossings)" if len(crossed) else ")"), fontsize=10)
    tight_layout(fig)
    return fig


#: The operating points drawn: one in each of this many by this many cells of the plot
#: (a marker per setpoint made a 942 s program's SVG 276 MB; markers in one cell of 1/600
#: of the axes overlap at the figure's size).
POINT_CELLS = 600


def distinct_points(x: Array, y: Array, cells: int = POINT_CELLS) -> Array:
    """The indices of the points ``(x, y)`` that fall first in each of ``cells`` by
    ``cells`` equal cells over their ranges (in order)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) == 0:
        return np.zeros(0, np.int64)

    def cell(v: Array) -> Array:
        lo, span = float(v.min()), float(np.ptp(v))
        u = (v - lo) / span if span > 0 else np.zeros_like(v)
        return np.minimum((u * cells).astype(np.int64), cells - 1)

    _, first = np.unique(cell(x) * cells + cell(y), return_index=True)
    return np.sort(first)


def operating_points_figure(res: ProgramResult, sizing: Sizing) -> Figure:
    """Each motor's (speed, torque) operating points against its torque-speed envelope, with
    the peak and the RMS points."""
    fig = new_figure((9.0, 4.0))
    axes = fig.subplots(1, 2)
    m = res.motors
    for i, ax in enumerate(axes):
        w, tau = np.abs(res.dq[:, i]), np.abs(res.tau[:, i])
        seen = distinct_points(w, tau)
        ax.plot(w[seen], tau[seen], ".", ms=2, alpha=0.4, label="operating points")
        s = sizing.motors[i]
        k = int(np.argmax(tau))  # the operating point of the peak torque
        ax.plot([w[k]], [tau[k]], "r^", label=f"peak torque ({s.peak_torque_Nm:.3g} N m)")
        rms_speed = float(np.sqrt(np.mean(res.dq[:, i] ** 2)))
        ax.plot([rms_speed], [s.rms_torque_Nm], "ks", label="RMS speed and torque")
        if m is not None:
            top = m.max_speed[i] if np.isfinite(m.max_speed[i]) else 1.2 * w.max()
            ws = np.linspace(0.0, top, 200)
            env = m.available_torque(np.stack([ws, ws], -1))[:, i]
            ax.plot(ws, env, "k--", lw=1.2, label="envelope")
        if res.rms_limit is not None:
            ax.axhline(res.rms_limit[i], color="grey", ls=":", label="RMS rating")
        ax.set_xlabel("|speed| [rad/s]")
        ax.set_ylabel("|torque| [N m]")
        ax.set_title(f"motor {'AD'[i]}", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    tight_layout(fig)
    return fig


def program_report(summary: ProgramSummary, pngs: dict[str, bytes]) -> str:
    """A self-contained HTML page: the moves, the sizing, the violations and the figures."""
    esc = html.escape
    moves = grid(("move", "type", "law", "start [s]", "duration [s]", "min type-1 distance",
                  "min type-2 distance", "modes at its end"),
                 [(m.index, f"{m.type} (change of working mode)" if m.mode_change else m.type,
                   m.law or "dwell", m.start_s, m.duration_s,
                   m.min_type1_distance, m.min_type2_distance,
                   f"{m.working_mode} {m.assembly_mode}".strip()) for m in summary.moves])
    modes = "".join(f"<p>{esc(line.strip())}</p>" for line in summary.mode_lines())
    keys = [("peak_torque_Nm", "peak torque [N m]"), ("rms_torque_Nm", "RMS torque [N m]"),
            ("peak_speed_rad_s", "peak speed [rad/s]"), ("peak_power_W", "peak power [W]"),
            ("energy_J", "energy delivered [J]"),
            ("peak_torque_ratio", "peak torque / available torque"),
            ("rms_torque_ratio", "RMS torque / rating"),
            ("peak_speed_ratio", "peak speed / maximum speed")]
    if any("peak_jerk_rad_s3" in m.as_dict() for m in summary.sizing.motors):
        keys += [("peak_acceleration_rad_s2", "peak acceleration [rad/s^2]"),
                 ("peak_jerk_rad_s3", "peak jerk [rad/s^3]"),
                 ("peak_torque_rate_Nm_s", "peak torque rate [N m/s]"),
                 ("peak_acceleration_ratio", "peak acceleration / limit"),
                 ("peak_jerk_ratio", "peak jerk / limit"),
                 ("peak_torque_rate_ratio", "peak torque rate / limit")]
    motors = [m.as_dict() for m in summary.sizing.motors]
    sizing = grid(("", "motor A", "motor D"),
                  [(label, *(m.get(k, "-") for m in motors)) for k, label in keys])
    viol = "".join(f"<li>{esc(v.text())}</li>" for v in summary.sizing.violations
                   ) or "<li>none</li>"
    rows = [(m.index, f"{c['time_s']:.6g}", "(" + ", ".join(f"{v:.4g}" for v in c["point_mm"])
             + ")", f"{c['speed_mm_s']:.4g}",
             f"{c['assembly_before']} -> {c['assembly_after']}", f"{c['residual_N']:.3g}",
             f"{c['residual_ratio']:.2g}", ", ".join(f"{v:.4g}" for v in c["torque_peak_Nm"]),
             "-" if c["torque_peak_ratio"] is None else
             ", ".join(f"{v:.4f}" for v in c["torque_peak_ratio"]))
            for m in summary.moves for c in m.crossings]
    crossings = "" if not rows else (
        "<h2>Crossings of the parallel singularity curve</h2><p>Each planned under the "
        "degeneracy condition (the end-effector's force has no component normal to the aligned "
        "distal rods there): its residual, and the torque peak within the crossing's "
        "neighbourhood (normalised distance to the singularity below 0.05).</p>"
        + grid(("move", "time [s]", "point [mm]", "speed [mm/s]", "assembly mode",
                "residual [N]", "residual / terms", "torque peak [N m]", "peak / limit"),
               rows))
    name = Path(summary.config).name
    return page(
        f"Program {name}: {summary.verdict}",
        f"<p>Task file {esc(summary.config)}. Cycle time {summary.cycle_time_s:.4f} s; "
        f"setpoints at {summary.servo_rate_hz:g} Hz. Units: {esc(summary.units)}.</p>"
        f"<h2>Moves</h2>{modes}{moves}{crossings}<h2>Motor sizing</h2>{sizing}<h2>Violations</h2>"
        f"<ul>{viol}</ul><h2>Figures</h2>{figures(pngs)}")
