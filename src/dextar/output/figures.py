"""The paper's figures 3-9, the workspace with the path, and an animation of the robot."""

from __future__ import annotations

import io
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..kinematics import WorkspaceMap, elbows, workspace_map

if TYPE_CHECKING:  # the real modules; at run time matplotlib is imported where first used
    import matplotlib as mpl
    import matplotlib.backends.backend_agg as backend_agg
    import matplotlib.figure as mfigure
    from matplotlib.figure import Figure
    from PIL import Image

    from ..analysis import Analysis
    from ..trajectory import Trajectory
else:
    mpl = lazy_module("matplotlib")
    backend_agg = lazy_module("matplotlib.backends.backend_agg")
    mfigure = lazy_module("matplotlib.figure")
    Image = lazy_module("PIL.Image")

# Figures are matplotlib.figure.Figure objects drawn without pyplot: no global backend or
# figure registry is touched, as the Matplotlib docs advise for non-interactive output.

#: The PNGs' resolution (dots per inch). Figures are made at it (:func:`new_figure`).
PNG_DPI = 110
#: zlib's level for the PNGs: 3 encodes in 60 % of the time of the default 6, for 5 % more
#: bytes (the same pixels).
PNG_COMPRESSION = 3


def new_figure(figsize: tuple[float, float], dpi: float = PNG_DPI) -> Figure:
    """A figure of ``figsize`` inches on its own Agg canvas, at the resolution of its PNG:
    the layout pass (:func:`tight_layout`) and the PNG then share one renderer, with its
    caches of text extents and parsed mathtext (a figure made without a canvas lays out on
    a renderer of its own at 100 dpi and the PNG parses and measures every text again)."""
    fig = mfigure.Figure(figsize=figsize, dpi=dpi)
    backend_agg.FigureCanvasAgg(fig)
    return fig


def tight_layout(fig: Any) -> None:
    """Lay ``fig`` out once (``Figure.tight_layout``) and leave it without a layout engine.

    ``Figure.tight_layout`` leaves a placeholder layout engine on the figure, and ``savefig``
    then draws the whole figure once more before each file (for an engine with nothing to
    do): a third of the time of every PNG and SVG. The files are byte for byte the same.
    """
    fig.tight_layout()
    fig.set_layout_engine(None)


def warm_up(*, mathtext: bool = True) -> None:
    """Load the fonts and, with ``mathtext``, build matplotlib's mathtext parser (a tenth of a
    second the first time in a process) before the figures are shared with a forked child
    (:mod:`dextar.output.parallel`), which then starts with them instead of doing it again.
    (Figures without mathtext leave the parser out: nothing would use it.)"""
    fig = new_figure((1, 1))
    fig.text(0.5, 0.5, r"$x$ x" if mathtext else "x")
    fig.canvas.draw()


def _labels(an: Analysis) -> dict[str, str]:
    n = an.inputs.units.names
    return {"t": f"time t [{n['time']}]", "E": f"energy [{n['energy']}]",
            "tau": f"torque [{n['torque']}]", "w": f"angular velocity [rad/{n['time']}]",
            "len": n["length"]}


def _time_plot(an: Analysis, title: str, ylabel: str,
               curves: list[tuple[Array, Array, str, str]], *,
               title_size: float = 12) -> Any:
    """One figure of curves ``(t, y, style, label)`` against time."""
    fig = new_figure((6.4, 4.2))
    ax = fig.subplots()
    for t, y, style, label in curves:
        ax.plot(t, y, style, label=label, lw=2.0 if "-" == style[-1:] else 1.5)
    ax.set_xlabel(_labels(an)["t"])
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=title_size)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    tight_layout(fig)
    return fig


def _angles(tr: Trajectory, title: str, an: Analysis) -> Any:
    return _time_plot(an, title, "angle [deg]", [
        (tr.t, np.degrees(tr.q[:, 0]), "-", r"$\varphi(t)$ (motor A)"),
        (tr.t, np.degrees(tr.q[:, 1]), "-", r"$\psi(t)$ (motor D)")])


def fig3(an: Analysis, uniform: Trajectory) -> Any:
    """Fig. 3: the leading angles under the uniform law."""
    return _angles(uniform, "Fig. 3: leading angles, uniform motion on the path", an)


def fig5(an: Analysis) -> Any:
    """Fig. 5: the leading angles under the run's law."""
    return _angles(an.trajectory, f"Fig. 5: leading angles, {an.law.name} law", an)


def fig4(an: Analysis) -> Any:
    """Fig. 4: the robot at every eighth of the motion."""
    tr, r = an.trajectory, an.inputs.robot
    fig = new_figure((7.6, 5.0))
    ax = fig.subplots()
    ax.plot(tr.P[:, 0], tr.P[:, 1], "k-", lw=1, label="path")
    times = np.linspace(0, an.law.duration, 9)
    idx = [int(np.argmin(np.abs(tr.t - t))) for t in times]
    colors = mpl.colormaps["viridis"](np.linspace(0, 1, len(idx)))
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
    ax.set_title(f"Fig. 4: robot every eighth of the motion, {an.law.name} law")
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    tight_layout(fig)
    return fig


def fig6(an: Analysis) -> Any:
    """Fig. 6: the end-effector's kinetic energy, exact, (30) and (32)."""
    p, t = an.paper, an.trajectory.t
    assert p is not None, "Fig. 6 needs the paper's model"
    return _time_plot(an, "Fig. 6: kinetic energy of the end-effector", _labels(an)["E"], [
        (t, p.T_exact, "k-", r"$T_{exact} = m|\dot P|^2/2$"),
        (t, p.T_fd, "c--", r"$T_{comp}$: (30), finite differences"),
        (t, p.T_approx, "r-.", r"$T_{approx}$: (32), constant $\beta_0$")])


def fig7(an: Analysis) -> Any:
    """Fig. 7: translational against rotational energy of the triangle CPB."""
    p, t = an.paper, an.trajectory.t
    assert p is not None, "Fig. 7 needs the paper's model"
    f = p.fig7
    title = (f"Fig. 7: energies of CPB ($m_L$ = {f['distal_mass']:.3g}, $J_L$ = {f['JL']:.3g}, "
             f"$\\lambda$ = {f['lambda']:.2g})")
    return _time_plot(an, title, _labels(an)["E"], [
        (t, p.T_exact + p.T_S, "b-", r"$T_P + T_S$ (end-effector + translation of CPB)"),
        (t, p.T_r, "r--", r"$T_r$ (rotation of CPB)")], title_size=10)


def fig8(an: Analysis) -> Any:
    """Fig. 8: the driven rods' angular velocities."""
    tr = an.trajectory
    return _time_plot(an, f"Fig. 8: angular velocities of the rods, {an.law.name} law",
                      _labels(an)["w"], [(tr.t, tr.dq[:, 0], "-", r"$\dot\varphi(t)$"),
                                         (tr.t, tr.dq[:, 1], "-", r"$\dot\psi(t)$")])


def fig9(an: Analysis) -> Any:
    """Fig. 9: motor torques, exact and (where it applies) the paper's (42)."""
    tr, ine = an.trajectory, an.inputs.inertia
    curves = [(tr.t, an.tau[:, 0], "b-", r"$M_1$ exact"), (tr.t, an.tau[:, 1], "g-", r"$M_2$ exact")]
    p = an.paper
    if p is not None:
        if p.leaves_out:  # what (42) models: the exact torques without gravity and friction
            without = f"exact without {' and '.join(p.leaves_out)}"
            curves += [(tr.t, p.reference[:, 0], "b:", rf"$M_1$ {without}"),
                       (tr.t, p.reference[:, 1], "g:", rf"$M_2$ {without}")]
        left = f" (no {', no '.join(p.leaves_out)})" if p.leaves_out else ""
        curves += [(tr.t, p.tau[:, 0], "b--", rf"$M_1$ paper (42){left}"),
                   (tr.t, p.tau[:, 1], "g--", rf"$M_2$ paper (42){left}")]
    title = (f"Fig. 9: motor torques ($m_L$ = {ine.distal[0].mass:.3g}, "
             f"$m_l$ = {ine.proximal[0].mass:.3g})")
    return _time_plot(an, title, _labels(an)["tau"], curves, title_size=10)


def workspace_figure(an: Analysis) -> Any:
    """The workspace of the run's working mode with the path and a pose."""
    sc = an.inputs
    ws = workspace_map(sc.robot, sc.mode, resolution=241)
    mid = len(an.trajectory.t) // 2
    return plot_workspace(ws, path=an.trajectory.P, unit=sc.units.names["length"],
                          pose=(an.trajectory.q[mid], an.trajectory.P[mid]))


def animation_gif(an: Analysis, frames: int = 41) -> bytes:
    """A GIF of the robot following the path, played in real time: at most ``frames``
    poses, one every whole number of centiseconds (a GIF's clock; 20 ms at least, as
    browsers play shorter delays slowly), the last at the end of the motion, then a pause
    of :data:`ANIMATION_PAUSE_MS` before it loops. A motion longer than ``frames - 1``
    delays of :data:`MAX_FRAME_MS` plays sped up, said in the title
    (:func:`animation_pace`).

    The still part (axes, path, pivots, title) is drawn once; each frame restores it and
    draws only the arm and the time over it (blitting), and the frames share one palette.
    """
    tr, r = an.trajectory, an.inputs.robot
    fig = mfigure.Figure(figsize=(4.8, 3.6), dpi=80)
    canvas = backend_agg.FigureCanvasAgg(fig)
    ax = fig.subplots()
    ax.plot(tr.P[:, 0], tr.P[:, 1], "k-", lw=0.8)
    ax.plot([r.A[0], r.D[0]], [0, 0], "ks", ms=6)
    # animated: left out of the still background, drawn on it frame by frame
    (arm,) = ax.plot([], [], "o-", color="tab:orange", lw=2.5, ms=4, animated=True)
    label = ax.text(0.02, 0.95, "", transform=ax.transAxes, animated=True)
    B, C = elbows(r, tr.q)
    pts = np.concatenate([tr.P, B, C, [r.A, r.D]])
    pad = 0.1 * np.ptp(pts, axis=0).max()
    ax.set_xlim(pts[:, 0].min() - pad, pts[:, 0].max() + pad)
    ax.set_ylim(pts[:, 1].min() - pad, pts[:, 1].max() + pad)
    ax.set_aspect("equal")
    length = an.inputs.units.names["length"]
    ax.set_xlabel(f"x ({length})", fontsize=8)
    ax.set_ylabel(f"y ({length})", fontsize=8)
    ax.tick_params(labelsize=7)
    times_s = tr.t * an.inputs.units.time_s
    index, durations = _real_time_frames(times_s - times_s[0], frames)
    pace = animation_pace(an, frames)
    ax.set_title(f"The robot following the path ({an.law.name} law),"
                 f"{' ' if pace <= 1.0 else chr(10)}{pace_words(pace, short=True)}", fontsize=9)
    tight_layout(fig)
    canvas.draw()  # type: ignore[no-untyped-call]  # matplotlib's Agg canvas is untyped
    still = canvas.copy_from_bbox(fig.bbox)  # type: ignore[no-untyped-call]  # the same
    packed = []
    for i in index:
        canvas.restore_region(still)  # type: ignore[no-untyped-call]  # the same
        arm.set_data([r.A[0], B[i, 0], tr.P[i, 0], C[i, 0], r.D[0]],
                     [r.A[1], B[i, 1], tr.P[i, 1], C[i, 1], r.D[1]])
        label.set_text(f"t = {tr.t[i]:.3f} {an.inputs.units.names['time']}")
        ax.draw_artist(arm)
        ax.draw_artist(label)
        rgba = canvas.buffer_rgba()  # type: ignore[no-untyped-call]  # the same
        packed.append(_packed(np.asarray(rgba)))
    images = _one_palette(packed)
    buf = io.BytesIO()
    images[0].save(buf, format="GIF", save_all=True, append_images=images[1:],
                   duration=durations, loop=0)
    return buf.getvalue()


#: The animation's pause on its last frame before it loops (ms).
ANIMATION_PAUSE_MS = 600
#: The shortest delay between frames (ms): browsers play shorter GIF delays at 100 ms.
MIN_FRAME_MS = 20
#: The longest (ms): a GIF's delay is at most 65535 centiseconds. A motion longer than
#: ``frames - 1`` of them plays sped up (:func:`animation_pace`), never with more frames than
#: asked (a 1e9 s motion had asked for 1.7e7 frames).
MAX_FRAME_MS = 60_000


def _speedup(total_ms: float, frames: int) -> float:
    """How many times faster than real time a motion of ``total_ms`` plays in at most
    ``frames`` frames (1: real time)."""
    return max(1.0, total_ms / (max(frames - 1, 1) * MAX_FRAME_MS))


def animation_pace(an: Analysis, frames: int) -> float:
    """How many times faster than real time the run's animation of at most ``frames``
    frames plays (1: real time; more for a motion longer than ``frames - 1`` delays of
    :data:`MAX_FRAME_MS`)."""
    t = an.trajectory.t * an.inputs.units.time_s
    return _speedup(1e3 * float(t[-1] - t[0]), frames)


def pace_words(speedup: float, *, short: bool = False) -> str:
    """The animation's pace in words (``short``: its title; else the report's caption)."""
    if speedup <= 1.0:
        return "in real time"
    if short:
        return f"sped up {speedup:.3g} times (not real time)"
    return (f"sped up {speedup:.3g} times (not real time: a GIF frame lasts at most "
            f"{MAX_FRAME_MS / 1e3:g} s)")


def _real_time_frames(t_s: Array, frames: int) -> tuple[Array, list[int]]:
    """The sample indices shown (at most ``frames``, the first and the last sample among
    them) and each frame's delay in ms, so that the motion ``t_s`` (seconds from 0, rising)
    plays in real time: a frame every ``step`` ms (whole centiseconds, from
    :data:`MIN_FRAME_MS` to :data:`MAX_FRAME_MS`), the last one at the motion's end within
    5 ms (a motion shorter than :data:`MIN_FRAME_MS` plays in that time). A motion longer
    than ``frames - 1`` delays of :data:`MAX_FRAME_MS` plays sped up (:func:`_speedup`):
    ``frames`` frames evenly spaced in time, each shown :data:`MAX_FRAME_MS`."""
    total_ms = 1e3 * float(t_s[-1])
    speedup = _speedup(total_ms, frames)
    if speedup > 1.0:
        at = np.linspace(0.0, total_ms, max(frames, 2))
        index = np.minimum(np.searchsorted(t_s * 1e3, at - 1e-9 * total_ms), len(t_s) - 1)
        return index, [MAX_FRAME_MS] * (len(at) - 1) + [ANIMATION_PAUSE_MS]
    step = min(max(MIN_FRAME_MS, 10 * math.ceil(total_ms / max(frames - 1, 1) / 10)),
               MAX_FRAME_MS)
    at = np.arange(0.0, total_ms, step)
    if len(at) > 1 and total_ms - at[-1] < MIN_FRAME_MS:
        at = at[:-1]  # the last gap too short to play: the one before takes it
    at = np.append(at, total_ms)
    index = np.minimum(np.searchsorted(t_s * 1e3, at - 1e-9), len(t_s) - 1)
    gaps = np.diff(at)
    last = max(MIN_FRAME_MS, int(10 * round(gaps[-1] / 10))) if len(gaps) else 0
    delays = [int(step)] * (len(gaps) - 1) + [last] if len(gaps) else []
    return index, [*delays, ANIMATION_PAUSE_MS]


def _packed(rgba: Array) -> Array:
    """The pixels of an RGBA image (h, w, 4) of bytes, each as one integer
    ``R + G 2^8 + B 2^16`` (h, w) (a new array)."""
    return np.asarray(np.ascontiguousarray(rgba).view("<u4")[..., 0] & 0xFFFFFF)


def _one_palette(packed: list[Array]) -> list[Any]:
    """Frames, each an array (h, w) of its pixels' colours packed as ``R + G 2^8 + B 2^16``
    (:func:`_packed`), as palette images sharing the adaptive (median-cut) palette of the
    first frame, each pixel in its nearest palette colour.

    The frames differ from the first only where the arm and the time are drawn, so the
    colours are collected from the first frame and the pixels that change. (PIL's own
    mapping onto a given palette goes through a coarse colour cache: white came out as
    (252, 252, 252).)
    """
    shifts = np.array([0, 8, 16])
    first = ((packed[0][..., None] >> shifts) & 255).astype(np.uint8)  # its RGB pixels
    im0 = Image.fromarray(first).convert("P", palette=Image.Palette.ADAPTIVE)
    palette = np.asarray(im0.getpalette(), np.int64).reshape(-1, 3)
    changed = [p != packed[0] for p in packed]
    colours = np.unique(np.concatenate([packed[0].ravel(), *(p[c] for p, c in
                                                             zip(packed, changed, strict=True))]))
    rgb = (colours[:, None].astype(np.int64) >> shifts) & 255
    nearest = ((rgb[:, None, :] - palette[None, :, :]) ** 2).sum(axis=-1).argmin(axis=1)
    index = nearest.astype(np.uint8)
    base = index[np.searchsorted(colours, packed[0])]
    raw_palette = palette.astype(np.uint8).tobytes()
    images = []
    for p, c in zip(packed, changed, strict=True):
        idx = base.copy()
        idx[c] = index[np.searchsorted(colours, p[c])]
        im = Image.fromarray(idx)  # mode L, which putpalette makes P
        im.putpalette(raw_palette)
        images.append(im)
    return images


def png_bytes(fig: Any, dpi: float = PNG_DPI) -> bytes:
    """A figure as PNG bytes."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, pil_kwargs={"compress_level": PNG_COMPRESSION})
    return buf.getvalue()


def svg_bytes(fig: Any) -> bytes:
    """A figure as SVG bytes."""
    buf = io.BytesIO()
    fig.savefig(buf, format="svg")
    return buf.getvalue()


def tracking_figure(res: Any, units: Any, mass_error: float, payload_kg: float) -> Any:
    """Computed-torque tracking: task and joint errors, and the applied torques against the
    saturation limit (dashed) with the saturated samples marked."""
    fig = new_figure((6.4, 8))
    axes = fig.subplots(3, 1, sharex=True)
    mm = units.length_mm
    axes[0].plot(res.t, res.task_error * mm)
    axes[0].set_ylabel("task-space error [mm]")
    axes[1].plot(res.t, np.degrees(res.joint_error))
    axes[1].set_ylabel("joint error [deg]")
    axes[1].legend([r"$\varphi$", r"$\psi$"], fontsize=8)
    axes[2].plot(res.t, res.tau[:, 0], label="motor A")
    axes[2].plot(res.t, res.tau[:, 1], label="motor D")
    if res.torque_limit is not None:
        for sign in (1, -1):
            axes[2].axhline(sign * res.torque_limit, color="k", ls="--", lw=1,
                            label="torque limit" if sign > 0 else None)
        if res.saturated.any():
            sat = res.saturated
            axes[2].plot(res.t[sat], np.abs(res.tau[sat]).max(axis=1)
                         * np.sign(res.tau[sat][np.arange(sat.sum()),
                                                np.abs(res.tau[sat]).argmax(axis=1)]),
                         "r.", ms=3, label=f"saturated ({res.saturated.mean():.1%})")
    axes[2].set_ylabel(f"torque [{units.names['torque']}]")
    axes[2].legend(fontsize=8)
    axes[2].set_xlabel(f"time [{units.names['time']}]")
    axes[0].set_title(f"Computed-torque tracking: masses {mass_error:+.0%}, unmodelled "
                      f"payload {payload_kg:g} kg", fontsize=10)
    tight_layout(fig)
    return fig


def plot_workspace(
    ws: WorkspaceMap,
    *,
    path: Array | None = None,
    pose: tuple[Array, Array] | None = None,
    unit: str = "mm",
    ax: Any = None,
) -> Any:
    """Draw a :class:`WorkspaceMap`: dexterity colour map, type-1 circles (dashed blue),
    type-2 curves (red), pivots, and optionally a path (n, 2) and a pose ``(q, P)``.

    Returns the matplotlib figure.
    """
    if ax is None:
        fig = new_figure((7, 5.6))
        ax = fig.subplots()
    else:
        fig = ax.figure
    r = ws.robot
    dex = np.ma.masked_where(~ws.reachable, ws.dexterity)
    im = ax.pcolormesh(ws.x, ws.y, dex, shading="auto", cmap="viridis", vmin=0, vmax=1,
                       rasterized=True)  # a raster inside vector output: small and fast
    fig.colorbar(im, ax=ax, label="dexterity (inverse condition number of J)")
    t2 = np.ma.masked_where(~ws.reachable, ws.type2)
    if np.any(t2 > 0) and np.any(t2 < 0):
        ax.contour(ws.x, ws.y, t2, levels=[0.0], colors="red", linewidths=1.5)
    theta = np.linspace(0, 2 * np.pi, 361)
    for centre, l, L in ((r.A, r.l1, r.L1), (r.D, r.l2, r.L2)):
        for rad in {abs(l - L), l + L}:
            if rad > 0:
                ax.plot(
                    centre[0] + rad * np.cos(theta), centre[1] + rad * np.sin(theta), "b--", lw=0.8
                )
    ax.plot([r.A[0], r.D[0]], [0, 0], "ks", ms=6)
    ax.plot([], [], "r-", label="type-2 (parallel) singularity")
    ax.plot([], [], "b--", label="type-1 (serial) singularity")
    if path is not None:
        path = np.asarray(path)
        ax.plot(path[:, 0], path[:, 1], "w-", lw=2.5)
        ax.plot(path[:, 0], path[:, 1], "k-", lw=1.2, label="path")
    if pose is not None:
        q, P = pose
        B, C = elbows(r, q)
        ax.plot(
            [r.A[0], B[0], P[0], C[0], r.D[0]],
            [r.A[1], B[1], P[1], C[1], r.D[1]],
            "o-",
            color="orange",
            lw=2,
        )
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")
    ax.set_title(f'Workspace, working mode "{ws.mode}"')
    ax.legend(loc="lower right", fontsize=8)
    return fig
