"""The paper's figures 3-9, the workspace with the path, and an animation of the robot."""

from __future__ import annotations

import io
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..analysis import Analysis  # noqa: E402
from ..kinematics import elbows, plot_workspace, workspace_map  # noqa: E402
from ..trajectory import Trajectory  # noqa: E402


def _labels(an: Analysis) -> dict[str, str]:
    n = an.scenario.units.names
    return {"t": f"time t [{n['time']}]", "E": f"energy [{n['energy']}]",
            "tau": f"torque [{n['torque']}]", "w": f"angular velocity [rad/{n['time']}]",
            "len": n["length"]}


def _angles(tr: Trajectory, title: str, an: Analysis) -> Any:
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(tr.t, np.degrees(tr.q[:, 0]), label=r"$\varphi(t)$ (motor A)")
    ax.plot(tr.t, np.degrees(tr.q[:, 1]), label=r"$\psi(t)$ (motor D)")
    ax.set_xlabel(_labels(an)["t"])
    ax.set_ylabel("angle [deg]")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig


def fig3(an: Analysis, uniform: Trajectory) -> Any:
    return _angles(uniform, "Fig. 3: leading angles, uniform motion on the path", an)


def fig5(an: Analysis) -> Any:
    return _angles(an.trajectory, "Fig. 5: leading angles, optimal law", an)


def fig4(an: Analysis) -> Any:
    tr, r = an.trajectory, an.scenario.robot
    fig, ax = plt.subplots(figsize=(7.6, 5.0))
    ax.plot(tr.P[:, 0], tr.P[:, 1], "k-", lw=1, label="path")
    T = an.law.duration
    times = np.linspace(0, T, 9)
    idx = [int(np.argmin(np.abs(tr.t - t))) for t in times]
    colors = plt.cm.viridis(np.linspace(0, 1, len(idx)))
    for i, c in zip(idx, colors, strict=True):
        B, C = elbows(r, tr.q[i])
        P = tr.P[i]
        ax.plot([r.A[0], B[0], P[0], C[0], r.D[0]], [r.A[1], B[1], P[1], C[1], r.D[1]], "o-",
                color=c, lw=1.5, ms=3, label=f"t = {tr.t[i]:.3g}")
    ax.plot([r.A[0], r.D[0]], [0, 0], "ks", ms=7)
    ax.set_aspect("equal")
    u = _labels(an)["len"]
    ax.set_xlabel(f"x [{u}]")
    ax.set_ylabel(f"y [{u}]")
    ax.set_title("Fig. 4: robot every T/8, optimal law")
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    return fig


def fig6(an: Analysis) -> Any:
    p, t = an.paper, an.trajectory.t
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(t, p.T_exact, "k-", lw=2.5, label=r"$T_{exact} = m|\dot P|^2/2$")
    ax.plot(t, p.T_fd, "c--", lw=1.5, label=r"$T_{comp}$: (30), finite differences")
    ax.plot(t, p.T_approx, "r-.", lw=1.5, label=r"$T_{approx}$: (32), constant $\beta_0$")
    ax.set_xlabel(_labels(an)["t"])
    ax.set_ylabel(_labels(an)["E"])
    ax.set_title("Fig. 6: kinetic energy of the end-effector")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig


def fig7(an: Analysis) -> Any:
    p, t = an.paper, an.trajectory.t
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(t, p.T_exact + p.T_S, "b-", label=r"$T_P + T_S$ (end-effector + translation of CPB)")
    ax.plot(t, p.T_r, "r--", label=r"$T_r$ (rotation of CPB)")
    ax.set_xlabel(_labels(an)["t"])
    ax.set_ylabel(_labels(an)["E"])
    f = p.fig7
    ax.set_title(f"Fig. 7: energies of CPB ($m_L$ = {f['distal_mass']:.3g}, "
                 f"$J_L$ = {f['JL']:.3g}, $\\lambda$ = {f['lambda']:.2g})", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig


def fig8(an: Analysis) -> Any:
    tr = an.trajectory
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(tr.t, tr.dq[:, 0], label=r"$\dot\varphi(t)$")
    ax.plot(tr.t, tr.dq[:, 1], label=r"$\dot\psi(t)$")
    ax.set_xlabel(_labels(an)["t"])
    ax.set_ylabel(_labels(an)["w"])
    ax.set_title("Fig. 8: angular velocities of the rods, optimal law")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig


def fig9(an: Analysis) -> Any:
    tr = an.trajectory
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(tr.t, an.tau[:, 0], "b-", lw=2, label=r"$M_1$ exact")
    ax.plot(tr.t, an.tau[:, 1], "g-", lw=2, label=r"$M_2$ exact")
    if an.paper is not None:
        ax.plot(tr.t, an.paper.tau[:, 0], "b--", lw=1.2, label=r"$M_1$ paper (42)")
        ax.plot(tr.t, an.paper.tau[:, 1], "g--", lw=1.2, label=r"$M_2$ paper (42)")
    ax.set_xlabel(_labels(an)["t"])
    ax.set_ylabel(_labels(an)["tau"])
    ine = an.scenario.inertia
    ax.set_title(f"Fig. 9: motor torques ($m_L$ = {ine.distal[0].mass:.3g}, "
                 f"$m_l$ = {ine.proximal[0].mass:.3g})", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def workspace_figure(an: Analysis) -> Any:
    sc = an.scenario
    ws = workspace_map(sc.robot, sc.mode, resolution=241)
    mid = len(an.trajectory.t) // 2
    return plot_workspace(ws, path=an.trajectory.P, unit=sc.units.names["length"],
                          pose=(an.trajectory.q[mid], an.trajectory.P[mid]))


def animation_gif(an: Analysis, frames: int = 41) -> bytes:
    """A GIF of the robot following the path (``frames`` poses equally spaced in time)."""
    from PIL import Image

    tr, r = an.trajectory, an.scenario.robot
    fig, ax = plt.subplots(figsize=(4.8, 3.6), dpi=80)
    ax.plot(tr.P[:, 0], tr.P[:, 1], "k-", lw=0.8)
    ax.plot([r.A[0], r.D[0]], [0, 0], "ks", ms=6)
    (arm,) = ax.plot([], [], "o-", color="tab:orange", lw=2.5, ms=4)
    label = ax.text(0.02, 0.95, "", transform=ax.transAxes)
    B, C = elbows(r, tr.q)
    pts = np.concatenate([tr.P, B, C, [r.A, r.D]])
    pad = 0.1 * np.ptp(pts, axis=0).max()
    ax.set_xlim(pts[:, 0].min() - pad, pts[:, 0].max() + pad)
    ax.set_ylim(pts[:, 1].min() - pad, pts[:, 1].max() + pad)
    ax.set_aspect("equal")
    ax.set_title("DexTAR following the path (optimal law)", fontsize=9)
    fig.tight_layout()
    images = []
    for i in np.linspace(0, len(tr.t) - 1, frames).round().astype(int):
        arm.set_data([r.A[0], B[i, 0], tr.P[i, 0], C[i, 0], r.D[0]],
                     [r.A[1], B[i, 1], tr.P[i, 1], C[i, 1], r.D[1]])
        label.set_text(f"t = {tr.t[i]:.3f} {an.scenario.units.names['time']}")
        fig.canvas.draw()
        rgba = np.asarray(fig.canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[..., :3]).convert("P", palette=Image.ADAPTIVE))
    plt.close(fig)
    buf = io.BytesIO()
    images[0].save(buf, format="GIF", save_all=True, append_images=images[1:], duration=80,
                   loop=0)
    return buf.getvalue()


def png_bytes(fig: Any, dpi: int = 110) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def svg_bytes(fig: Any) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="svg")
    return buf.getvalue()
