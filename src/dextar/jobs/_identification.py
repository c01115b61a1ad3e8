"""Identification's jobs: an exciting motion to record (``dextar excite``) and the model
identified from a recording (``dextar identify``), each against the task the model is for
when one is given."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .._arrays import Array
from ..config import Scenario, load_scenario
from ..errors import ConfigError
from ..identification.coverage import JointRegion
from ..identification.data import MotionData, read_motion_csv
from ..identification.excite import ExcitationResult, design_excitation
from ..identification.fit import IdentificationResult, identify
from ..output.identification import IdentificationReport, model_comment


def task_motion(path: str, sc: Scenario) -> tuple[Array, Array, Array]:
    """The joint motion ``(q, dq, ddq)`` (SI) of a task file: its program planned, or its
    run sampled, on the config's robot (a task for another robot is refused)."""
    task = load_scenario(path)
    if task.robot_mm != sc.robot_mm:
        raise ConfigError(f"--task {path!r} is for another robot ({task.robot_mm.as_dict()} "
                          f"mm) than the config's ({sc.robot_mm.as_dict()} mm)")
    if task.moves:
        res = task.program_request().plan()
        return res.q, res.dq, res.ddq
    tr = task.in_units("si").trajectory()
    return tr.q, tr.dq, tr.ddq


@dataclass(frozen=True)
class Excitation:
    """An exciting motion (``dextar excite``).

    Attributes
    ----------
    result : ExcitationResult
        The Fourier trajectory, its condition number, headroom, coverage against the floors
        and the verdict (``status`` 2: short of a floor after every attempt).
    region : JointRegion or None
        The task's joint region and speeds it was made to cover (``task``), or None.
    """

    result: ExcitationResult
    region: JointRegion | None


def excite(sc: Scenario, *, harmonics: int = 5, base_hz: float = 0.2, duration: float = 20.0,
           seed: int = 0, task: str | None = None) -> Excitation:
    """Design an exciting trajectory for the scenario's robot and prior model (SI), within
    its motors, covering the joint region and speeds of the task file ``task`` when given."""
    region = None
    if task is not None:
        q, dq, _ = task_motion(task, sc)
        region = JointRegion.from_samples(q, dq)
    res = design_excitation(sc.si_model, sc.mode, harmonics=harmonics, base_hz=base_hz,
                            duration=duration, motors=sc.si_motors, seed=seed, region=region)
    return Excitation(res, region)


@dataclass(frozen=True)
class Identified:
    """A model identified from measured motion (``dextar identify``).

    Attributes
    ----------
    result : IdentificationResult
        The base parameters, their uncertainty, the physical set and the verdict
        (``success``: identified; otherwise ``reasons`` names why not).
    report : IdentificationReport
        The summary (``summary.json``) and, with validation data, the prediction of it.
    data : MotionData
        The measured motion.
    model_toml : str
        The identified model as a config file (``identified.toml``).
    """

    result: IdentificationResult
    report: IdentificationReport
    data: MotionData
    model_toml: str


def identify_model(data_path: str, sc: Scenario, *, config: str | None = None,
                   cutoff_hz: float | None = None, task: str | None = None,
                   validate: str | None = None) -> Identified:
    """Identify the scenario's robot (its prior model, SI) from the CSV ``data_path``; the
    prediction uncertainty along the task file ``task`` (default: the recorded motion); with
    ``validate`` (a second recording) its prediction measured. ``config`` names the config
    in the outputs."""
    if cutoff_hz is not None and not (math.isfinite(cutoff_hz) and cutoff_hz > 0):
        raise ConfigError(f"--cutoff-hz {cutoff_hz!r} must be a positive number")
    model = sc.si_model
    data = read_motion_csv(data_path)
    vdata = read_motion_csv(validate) if validate else None
    reference = None if task is None else task_motion(task, sc)
    res = identify(data, model, mode=sc.mode, cutoff_hz=cutoff_hz, reference=reference,
                   reference_name=f"the task {task}")
    rep = IdentificationReport.of(res, data, model, sc.mode, data_path, config, vdata,
                                  validate)
    return Identified(res, rep, data, sc.model_file(
        sc.robot_mm, sc.mode, res.inertia, model_comment(res, data_path, config)))
