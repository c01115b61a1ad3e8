"""Writing a run: ``trajectory.csv``, ``fig3..fig9`` (PNG and SVG), ``workspace.png``,
``animation.gif``, ``report.html`` (self-contained) and ``summary.json``, into an output
directory whose files appear only when complete."""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from functools import partial
from typing import TYPE_CHECKING, Any

from ..analysis.summary import is_paper_example
from ..errors import DextarError
from . import figures as fg
from .files import OutputDir
from .parallel import Job, render
from .report import render_report
from .tables import csv_text, run_columns

if TYPE_CHECKING:
    from ..analysis import Analysis
    from ..trajectory import Trajectory

#: Figures a run can draw (``[output].figures``).
FIGURES = ("fig3", "fig4", "fig5", "fig6", "fig7", "fig8", "fig9", "workspace", "animation")
#: Every file a run may write.
RUN_FILES = ("trajectory.csv", "summary.json", "report.html", "animation.gif", "workspace.png",
             *(f"fig{k}.{ext}" for k in range(3, 10) for ext in ("png", "svg")))


class Progress:
    """Step messages on stderr for a person at a terminal (silent otherwise)."""

    def __init__(self, enabled: bool) -> None:
        """Messages only when ``enabled`` (a person at a terminal)."""
        self.enabled = enabled
        self.t0 = time.perf_counter()
        self.timings: dict[str, float] = {}
        self._last = self.t0

    def step(self, name: str) -> None:
        """Announce the step ``name``."""
        now = time.perf_counter()
        if self.enabled:
            sys.stderr.write(f"[{now - self.t0:5.1f} s] {name}\n")
            sys.stderr.flush()
        self._last = now

    def done(self, name: str) -> None:
        """Record the time the step ``name`` took."""
        now = time.perf_counter()
        self.timings[name] = round(now - self._last, 4)
        self._last = now


Stage = Callable[[str, Callable[[], Any]], Any]


def staged(progress: Progress) -> Stage:
    """A runner of named steps: progress on stderr, timings, errors prefixed by the step."""
    def stage(name: str, fn: Callable[[], Any]) -> Any:
        progress.step(name)
        try:
            result = fn()
        except DextarError as exc:
            raise type(exc)(f"step '{name}': {exc}") from None
        progress.done(name)
        return result

    return stage


def default_figures(an: Analysis) -> tuple[str, ...]:
    """The figures that apply: every one for the paper's example; for another task none of
    the paper's illustrations of its own example (Fig. 3, its uniform law; Fig. 7, its
    masses)."""
    if is_paper_example(an.inputs):
        return FIGURES
    return tuple(f for f in FIGURES if f not in ("fig3", "fig7"))


def write_run(od: OutputDir, an: Analysis, uniform: Trajectory, summary: dict[str, Any], *,
              validation: Callable[[], tuple[dict[str, Any], float]] | None = None,
              figures: tuple[str, ...] | None, animation_frames: int, stage: Stage,
              progress: Progress) -> None:
    """Write a run's files into ``od``: ``trajectory.csv``, the figures (PNG and SVG; None:
    :func:`default_figures`), the animation, ``report.html`` and, last, ``summary.json``
    (with the files and timings). ``validation`` gives the physics checks, the summary's
    ``validation``, and the seconds they took, once the figures are drawn (``dextar run``
    computes them meanwhile on the other core: :class:`~dextar.output.parallel.Forked`; the
    timings give their own seconds, not the wait)."""
    if figures is None:
        figures = default_figures(an)
    stage("trajectory.csv", lambda: od.write_text("trajectory.csv", csv_text(run_columns(an))))
    files = stage("figures and animation.gif",
                  lambda: _figures(an, uniform, figures, animation_frames))
    if validation is not None:
        name = "validation (power balance, forward re-simulation)"
        summary["validation"], seconds = stage(name, validation)
        progress.timings[name] = round(seconds, 4)
    for name, data in files.items():
        od.write_bytes(name, data)
    pngs = {n[:-4]: files[n] for n in files if n.endswith(".png")}
    summary["timing_s"] = progress.timings
    summary["files"] = sorted(set(od.written) | {"summary.json", "report.html"})
    stage("report.html", lambda: od.write_text("report.html",
                                               _report(an, summary, pngs,
                                                       files.get("animation.gif"),
                                                       animation_frames)))
    od.write_text("summary.json", json.dumps(summary, indent=2, allow_nan=False) + "\n")


#: What each figure costs to draw, relative to the others (measured in a run): the order in
#: which the two processes take them (:func:`~dextar.output.parallel.render`).
_COSTS = {"fig3": 1.0, "fig4": 1.1, "fig5": 0.95, "fig6": 1.2, "fig7": 1.0, "fig8": 1.1,
          "fig9": 1.5, "workspace": 1.1, "animation": 1.6}


def _figures(an: Analysis, uniform: Any, wanted: tuple[str, ...], animation_frames: int
             ) -> dict[str, bytes]:
    """The figures in ``wanted`` (PNG, and SVG but for the workspace) and the animation, by
    file name, drawn on two cores where there are two (:mod:`dextar.output.parallel`)."""
    makers: dict[str, Callable[[], Any]] = {
        "fig3": lambda: fg.fig3(an, uniform), "fig4": lambda: fg.fig4(an),
        "fig5": lambda: fg.fig5(an), "fig6": lambda: fg.fig6(an), "fig7": lambda: fg.fig7(an),
        "fig8": lambda: fg.fig8(an), "fig9": lambda: fg.fig9(an),
        "workspace": lambda: fg.workspace_figure(an)}

    def files(name: str) -> dict[str, bytes]:
        fig = makers[name]()
        out = {f"{name}.png": fg.png_bytes(fig)}
        if name != "workspace":
            out[f"{name}.svg"] = fg.svg_bytes(fig)
        return out

    jobs: dict[str, Job[dict[str, bytes]]] = {
        name: (partial(files, name), _COSTS[name]) for name in makers
        if name in wanted and not (name in ("fig6", "fig7") and an.paper is None)}
    if "animation" in wanted:
        jobs["animation"] = (lambda: {"animation.gif": fg.animation_gif(an, animation_frames)},
                             _COSTS["animation"])
    fg.warm_up()
    return {k: v for part in render(jobs).values() for k, v in part.items()}


def _report(an: Analysis, summary: dict[str, Any], pngs: dict[str, bytes],
            gif: bytes | None, animation_frames: int) -> str:
    return render_report(an, summary, pngs, gif,
                         fg.pace_words(fg.animation_pace(an, animation_frames)))
