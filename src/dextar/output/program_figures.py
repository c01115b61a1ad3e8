"""Figures and report of a robot program: the moves on the workspace map, the joint motion and
torques against time with the limits, and each motor's torque-speed operating points against
its envelope (the plot a drive engineer sizes motors with)."""

from __future__ import annotations

import html
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from ..geometry import FiveBar
from ..kinematics import workspace_map
from ..program import ProgramResult
from .figures import plot_workspace
from .html_page import figures, page


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
    ax.set_title(f"Program: {len(res.moves)} moves, cycle {res.cycle_time_s:.3f} s "
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
    fig.tight_layout()
    return fig


def operating_points_figure(res: ProgramResult, sizing: list[dict[str, Any]]) -> Figure:
    """Each motor's (speed, torque) operating points against its torque-speed envelope, with
    the peak and the RMS points."""
    fig = Figure(figsize=(9.0, 4.0))
    axes = fig.subplots(1, 2)
    m = res.motors
    for i, ax in enumerate(axes):
        w, tau = np.abs(res.dq[:, i]), np.abs(res.tau[:, i])
        ax.plot(w, tau, ".", ms=2, alpha=0.4, label="operating points")
        s = sizing[i]
        k = int(np.argmax(tau))  # the operating point of the peak torque
        ax.plot([w[k]], [tau[k]], "r^", label=f"peak torque ({s['peak_torque_Nm']:.3g} N m)")
        rms_speed = float(np.sqrt(np.mean(res.dq[:, i] ** 2)))
        ax.plot([rms_speed], [s["rms_torque_Nm"]], "ks", label="RMS speed and torque")
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
    fig.tight_layout()
    return fig


def program_report(summary: dict[str, Any], pngs: dict[str, bytes]) -> str:
    """A self-contained HTML page: the moves, the sizing, the violations and the figures."""
    esc = html.escape
    rows = "".join(
        f"<tr><td>{m['index']}</td><td>{esc(m['type'])}</td><td>{esc(str(m['law']))}</td>"
        f"<td>{m['start_s']:.4f}</td><td>{m['duration_s']:.4f}</td>"
        f"<td>{m['min_type1_distance']:.3g}</td><td>{m['min_type2_distance']:.3g}</td></tr>"
        for m in summary["moves"])
    keys = [("peak_torque_Nm", "peak torque [N m]"), ("rms_torque_Nm", "RMS torque [N m]"),
            ("peak_speed_rad_s", "peak speed [rad/s]"), ("peak_power_W", "peak power [W]"),
            ("energy_J", "energy delivered [J]"), ("peak_torque_ratio",
                                                   "peak torque / available torque"),
            ("rms_torque_ratio", "RMS torque / rating"), ("peak_speed_ratio",
                                                           "peak speed / maximum speed")]
    motors = summary["motors"]
    sizing = "".join(
        f"<tr><td>{esc(label)}</td>" + "".join(
            f"<td>{m[k]:.4g}</td>" if k in m else "<td>-</td>" for m in motors) + "</tr>"
        for k, label in keys)
    viol = "".join(f"<li>motor {v['motor']}: {esc(v['quantity'])} {v['value']:.4g} above "
                   f"{v['limit']:.4g}" + (f" at t = {v['t_s']:.4g} s in move {v['move']}"
                                          if v["t_s"] is not None else "") + "</li>"
                   for v in summary["violations"]) or "<li>none</li>"
    return page(
        f"dextar program {summary['config']}",
        f"<h1>Program {esc(str(summary['config']))}: {esc(summary['status'])} the motors</h1>"
        f"<p>Cycle time {summary['cycle_time_s']:.4f} s; setpoints at "
        f"{summary['servo_rate_hz']:g} Hz. Units: {esc(summary['units'])}.</p>"
        "<h2>Moves</h2><table><tr><th>move</th><th>type</th><th>law</th><th>start [s]</th>"
        "<th>duration [s]</th><th>min type-1 distance</th><th>min type-2 distance</th></tr>"
        f"{rows}</table><h2>Motor sizing</h2><table><tr><th></th><th>motor A</th>"
        f"<th>motor D</th></tr>{sizing}</table><h2>Violations</h2><ul>{viol}</ul>"
        f"<h2>Figures</h2>{figures(pngs)}")
