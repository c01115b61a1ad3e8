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
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from .._arrays import Array
from ..geometry import FiveBar
from ..kinematics import workspace_map
from ..program import MoveTiming, ProgramResult, Sizing
from .figures import plot_workspace, png_bytes, svg_bytes, tight_layout, warm_up
from .files import OutputDir
from .html_page import figures, grid, page
from .tables import csv_text

#: Every file a program may write.
PROGRAM_FILES = ("setpoints.csv", "summary.json", "report.html",
                 *(f"{n}.{e}" for n in ("moves", "motion", "operating_points")
                   for e in ("png", "svg")))
#: What the units of a program's outputs are.
UNITS = "SI: s, rad, N m, W, J; positions in mm in setpoints.csv"


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
    """

    config: str
    cycle_time_s: float
    servo_rate_hz: float
    moves: tuple[MoveTiming, ...]
    sizing: Sizing

    @property
    def status(self) -> str:
        """``"fits"`` or ``"exceeds"`` (the motors)."""
        return "fits" if self.sizing.fits else "exceeds"

    def as_json(self) -> dict[str, Any]:
        """``summary.json``."""
        return {"status": self.status, "cycle_time_s": self.cycle_time_s,
                "servo_rate_hz": self.servo_rate_hz, "config": self.config,
                "moves": [asdict(m) for m in self.moves],
                "motors": [m.as_dict() for m in self.sizing.motors],
                "violations": [v.as_dict() for v in self.sizing.violations], "units": UNITS}

    def lines(self, out: str, samples: int) -> list[str]:
        """The summary in words."""
        return [
            f"program: cycle time {self.cycle_time_s:.6g} s, {len(self.moves)} moves; "
            f"{self.status} the motors",
            *(f"  move {m.index} ({m.type}): {m.law or 'dwell'} {m.duration_s:.4g} s from "
              f"{m.start_s:.4g} s" + (", blended into the next" if m.blended_with_next else "")
              for m in self.moves),
            *(f"  motor {m.motor}: peak {m.peak_torque_Nm:.4g} N m, RMS {m.rms_torque_Nm:.4g} "
              f"N m, peak speed {m.peak_speed_rad_s:.4g} rad/s" for m in self.sizing.motors),
            f"wrote {Path(out) / 'setpoints.csv'} ({samples} setpoints at "
            f"{self.servo_rate_hz:g} Hz) and {Path(out) / 'summary.json'}"]


def setpoint_columns(res: ProgramResult) -> dict[str, Array]:
    """``setpoints.csv``: time, move, end-effector (mm), joint motion and torques (SI)."""
    return {"t_s": res.t, "move": res.move_index.astype(float), "x_mm": res.P[:, 0] * 1e3,
            "y_mm": res.P[:, 1] * 1e3, "phi_rad": res.q[:, 0], "psi_rad": res.q[:, 1],
            "dphi_rad_s": res.dq[:, 0], "dpsi_rad_s": res.dq[:, 1],
            "ddphi_rad_s2": res.ddq[:, 0], "ddpsi_rad_s2": res.ddq[:, 1],
            "tau1_Nm": res.tau[:, 0], "tau2_Nm": res.tau[:, 1]}


def write_program(out: str, res: ProgramResult, summary: ProgramSummary, robot_mm: FiveBar,
                  mode: str, *, force: bool = False, with_figures: bool = True) -> None:
    """Write ``setpoints.csv``, the figures (PNG and SVG), ``report.html`` and
    ``summary.json`` into ``out``."""
    with OutputDir(out, force=force, produces=PROGRAM_FILES) as od:
        od.write_text("setpoints.csv", csv_text(setpoint_columns(res)))
        if with_figures:
            pngs: dict[str, bytes] = {}
            for name, (png, svg) in _figures(res, summary, robot_mm, mode).items():
                pngs[name] = png
                od.write_bytes(f"{name}.png", png)
                od.write_bytes(f"{name}.svg", svg)
            od.write_text("report.html", program_report(summary, pngs))
        od.write_text("summary.json", json.dumps(summary.as_json(), indent=2,
                                                 allow_nan=False) + "\n")


def _figures(res: ProgramResult, summary: ProgramSummary, robot_mm: FiveBar, mode: str
             ) -> dict[str, tuple[bytes, bytes]]:
    """Each figure's PNG and SVG, drawn on two cores where there are two
    (:mod:`dextar.output.parallel`)."""
    from .parallel import Job, render

    makers: dict[str, Callable[[], Figure]] = {
        "moves": lambda: moves_figure(res, robot_mm, mode), "motion": lambda: motion_figure(res),
        "operating_points": lambda: operating_points_figure(res, summary.sizing)}

    def files(name: str) -> tuple[bytes, bytes]:
        fig = makers[name]()
        return png_bytes(fig), svg_bytes(fig)

    jobs: dict[str, Job[tuple[bytes, bytes]]] = {n: (partial(files, n), 1.0) for n in makers}
    warm_up()
    return render(jobs)


def moves_figure(res: ProgramResult, robot_mm: FiveBar, mode: str) -> Figure:
    """The end-effector's path over the workspace map of the starting working mode, each move
    numbered at its middle."""
    ws = workspace_map(robot_mm, mode, resolution=241)
    fig: Figure = plot_workspace(ws, path=res.P * 1e3, unit="mm")
    ax = fig.axes[0]
    for index in np.unique(res.move_index):
        P = res.P[res.move_index == index] * 1e3
        x, y = P[len(P) // 2]
        ax.annotate(str(int(index)), (x, y), fontsize=8, color="white",
                    bbox={"boxstyle": "circle,pad=0.2", "fc": "black", "alpha": 0.7})
    ax.set_title(f"Program: {len(res.move_types) or len(res.moves)} moves, cycle "
                 f"{res.cycle_time_s:.3f} s "
                 f"(working mode at the start: {mode})", fontsize=10)
    return fig


def motion_figure(res: ProgramResult) -> Figure:
    """Joint angles, speeds and torques against time, move boundaries dotted, limits dashed."""
    fig = Figure(figsize=(7.0, 8.0))
    axes = fig.subplots(3, 1, sharex=True)
    t = res.t
    labels = ("motor A", "motor D")
    for i in range(2):
        axes[0].plot(t, np.degrees(res.q[:, i]), label=labels[i])
        axes[1].plot(t, res.dq[:, i], label=labels[i])
        axes[2].plot(t, res.tau[:, i], label=labels[i])
    m = res.motors
    if m is not None:
        for i, style in ((0, "C0"), (1, "C1")):
            if np.isfinite(m.max_speed[i]):
                for sgn in (1, -1):
                    axes[1].axhline(sgn * m.max_speed[i], color=style, ls="--", lw=0.8)
            avail = m.available_torque(res.dq)[:, i]
            axes[2].plot(t, avail, color=style, ls="--", lw=0.8)
            axes[2].plot(t, -avail, color=style, ls="--", lw=0.8)
    changes = t[1:][np.diff(res.move_index) != 0]  # where the next move starts
    for ax in axes:
        for tc in changes:
            ax.axvline(tc, color="grey", ls=":", lw=0.8)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("angle [deg]")
    axes[1].set_ylabel("speed [rad/s]")
    axes[2].set_ylabel("torque [N m]")
    axes[2].set_xlabel("time [s]")
    axes[0].legend(fontsize=8)
    axes[0].set_title("Joint motion and torques (dashed: the motors' limits; dotted: moves)",
                      fontsize=10)
    tight_layout(fig)
    return fig


def operating_points_figure(res: ProgramResult, sizing: Sizing) -> Figure:
    """Each motor's (speed, torque) operating points against its torque-speed envelope, with
    the peak and the RMS points."""
    fig = Figure(figsize=(9.0, 4.0))
    axes = fig.subplots(1, 2)
    m = res.motors
    for i, ax in enumerate(axes):
        w, tau = np.abs(res.dq[:, i]), np.abs(res.tau[:, i])
        ax.plot(w, tau, ".", ms=2, alpha=0.4, label="operating points")
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
                  "min type-2 distance"),
                 [(m.index, m.type, m.law or "dwell", m.start_s, m.duration_s,
                   m.min_type1_distance, m.min_type2_distance) for m in summary.moves])
    keys = [("peak_torque_Nm", "peak torque [N m]"), ("rms_torque_Nm", "RMS torque [N m]"),
            ("peak_speed_rad_s", "peak speed [rad/s]"), ("peak_power_W", "peak power [W]"),
            ("energy_J", "energy delivered [J]"),
            ("peak_torque_ratio", "peak torque / available torque"),
            ("rms_torque_ratio", "RMS torque / rating"),
            ("peak_speed_ratio", "peak speed / maximum speed")]
    motors = [m.as_dict() for m in summary.sizing.motors]
    sizing = grid(("", "motor A", "motor D"),
                  [(label, *(m.get(k, "-") for m in motors)) for k, label in keys])
    viol = "".join(f"<li>{esc(v.text())}</li>" for v in summary.sizing.violations
                   ) or "<li>none</li>"
    name = Path(summary.config).name
    return page(
        f"Program {name}: {summary.status} the motors",
        f"<p>Task file {esc(summary.config)}. Cycle time {summary.cycle_time_s:.4f} s; "
        f"setpoints at {summary.servo_rate_hz:g} Hz. Units: {esc(UNITS)}.</p>"
        f"<h2>Moves</h2>{moves}<h2>Motor sizing</h2>{sizing}<h2>Violations</h2>"
        f"<ul>{viol}</ul><h2>Figures</h2>{figures(pngs)}")
