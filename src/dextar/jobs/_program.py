"""A robot program, ``dextar program``: its moves planned under the motors, the motors'
sizing over the cycle and, with ``[drive]``, the drives' view of it (PVT points, the
motor side, the torque feedforward against the drives' limits)."""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..config import Scenario
from ..errors import ConfigError, DextarError
from ..output.program import ProgramSummary
from ..program import ProgramResult, sizing
from ..program.drive import DriveUnits, PvtPoints, drive_report, pvt_points, torque_checks


@dataclass(frozen=True)
class ProgramJob:
    """A program planned and sized.

    Attributes
    ----------
    result : ProgramResult
        The moves, their laws and the setpoints at the servo rate (SI).
    summary : ProgramSummary
        The cycle, every move, the motors' figures and every limit exceeded
        (``summary.sizing.fits`` is the verdict ``fits the motors``).
    drive : DriveUnits or None
        The drives (``[drive]``), or None.
    pvt : PvtPoints or None
        The PVT points (with ``[drive]``).
    warnings : tuple of str
        What is above a rating but within the limits (a torque feedforward above the rated
        torque), each naming the motor, the move and the time.
    """

    result: ProgramResult
    summary: ProgramSummary
    drive: DriveUnits | None
    pvt: PvtPoints | None
    warnings: tuple[str, ...] = ()

    @property
    def start_mode(self) -> str | None:
        """The working mode the planner chose at the start (``working_mode = "auto"``), or
        None (the configured one)."""
        c = self.result.mode_choice
        return None if c is None else c.start_mode

    @property
    def fits(self) -> bool:
        """Every motor within every limit, every move ending where it was sent."""
        return self.summary.sizing.fits


def program(sc: Scenario) -> ProgramJob:
    """Plan the scenario's program (``[program]``, ``[[move]]``, ``[motors]``) in SI and size
    its motors; with ``[drive]`` also its PVT points and its drives' figures."""
    drive = sc.drive()
    res = sc.program_request().plan()
    try:
        pvt = None if drive is None else pvt_points(res, drive)
    except DextarError as exc:
        raise ConfigError(f"config table [drive]: {exc}") from None
    sized, report = sizing(res), None
    notes: list[str] = []
    if drive is not None and pvt is not None:
        report = {**drive_report(res, drive, sc.si_model.inertia.rotor),
                  "pvt_max_error_counts": pvt.max_error_counts}
        over, notes = torque_checks(res, drive)
        sized = replace(sized, violations=(*sized.violations, *over))
    summary = ProgramSummary(sc.source, res.cycle_time_s, sc.output.servo_rate_hz,
                             tuple(res.timeline()), sized, res.rms_fit, report,
                             sc.robot_table.encoder_offset_deg, res.mode_choice)
    return ProgramJob(res, summary, drive, pvt, tuple(notes))
