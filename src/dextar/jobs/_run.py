"""The main job, ``dextar run``: the configured law along the path (the paper's example by
default), its trajectory, exact and paper-model torques, the uniform law of Fig. 3, the
summary with the paper's claims, and the physics checks."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..analysis import Analysis, analyze, run_summary, validation
from ..config import Scenario
from ..output.parallel import Forked
from ..trajectory import Trajectory
from ._motion import refuse_crossing

#: ``stage(name, fn) -> fn()``: runs one named step (the command's progress and timings).
Stage = Callable[[str, Callable[[], Any]], Any]


def _plain(name: str, fn: Callable[[], Any]) -> Any:
    return fn()


@dataclass(frozen=True)
class RunResult:
    """What ``dextar run`` computed.

    Attributes
    ----------
    scenario : Scenario
        The config it ran.
    analysis : Analysis
        The law, its trajectory, exact torques, powers, energy, joint forces and the paper's
        model beside them where it applies.
    uniform : Trajectory
        The uniform law along the same path (the paper's Fig. 3).
    summary : dict
        Everything computed and claimed, JSON-ready (``summary.json`` without its
        ``validation``, ``files`` and ``timing_s``).
    """

    scenario: Scenario
    analysis: Analysis
    uniform: Trajectory
    summary: dict[str, Any]
    checks: Forked[tuple[dict[str, Any], float]] = field(repr=False, compare=False)

    def validation(self) -> tuple[dict[str, Any], float]:
        """The physics checks (:func:`dextar.analysis.validation`: power balance, forward
        re-simulation in windows, each with its figure, threshold and verdict) and the
        seconds they took; computed beside the caller's own work where a second process can
        be forked, waited for here."""
        try:
            return self.checks.result()
        finally:
            self.checks.close()

    @property
    def passed(self) -> bool:
        """Every physics check passed."""
        return bool(self.validation()[0]["passed"])


def run(sc: Scenario, *, stage: Stage = _plain) -> RunResult:
    """Run the scenario: the law, the trajectory and its torques, the uniform law, the
    summary; the physics checks start in a forked process (:class:`RunResult.validation`
    waits for them), so that a caller drawing the figures meanwhile uses both cores.

    ``stage(name, fn)`` runs each named step (``dextar run`` times them and shows them)."""
    refuse_crossing(sc, "run")
    inputs = sc.inputs()
    an: Analysis = stage(f"{sc.law_table.type} law, trajectory and torques",
                         lambda: analyze(inputs, sc.law()))
    uniform: Trajectory = stage("uniform law (Fig. 3)",
                                lambda: inputs.trajectory(sc.law("uniform")))

    def checked() -> tuple[dict[str, Any], float]:
        t0 = time.perf_counter()
        return validation(an), time.perf_counter() - t0

    checks = Forked(checked)
    checks.__enter__()  # the child starts now; RunResult.validation ends it
    try:
        summary = run_summary(an, None, inputs.trajectory(uniform.law, samples=201))
    except BaseException:
        checks.close()
        raise
    return RunResult(sc, an, uniform, summary, checks)
