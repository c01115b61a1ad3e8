"""Calibration's jobs: where to measure (``dextar poses``) and the robot calibrated from what
was measured (``dextar calibrate``). Both read only the config's robot and instrument
(:class:`~dextar.config.kinematic.KinematicConfig`): no law, path or dynamics."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ..calibration.data import PoseData, read_poses_csv
from ..calibration.fit import Diagnosis, calibrate_or_diagnose, encoder_std
from ..calibration.poses import DEFAULT_MARGIN, PoseSelection, select_poses
from ..config.kinematic import KinematicConfig
from ..geometry import WORKING_MODES


def poses(kc: KinematicConfig, count: int, *, modes: Sequence[str] = WORKING_MODES,
          region_mm: Sequence[float] | None = None, margin: float = DEFAULT_MARGIN,
          seed: int = 0, frame: str = "instrument") -> PoseSelection:
    """``count`` measurement poses of the config's robot: D-optimal (O1) over ``modes``,
    ``margin`` away from both singularity types, inside ``region_mm`` (``[xmin, xmax, ymin,
    ymax]`` mm, robot frame; default ``[instrument].region``), weighted by the instrument's
    and the encoders' noise where the config states them, in visiting order."""
    rt, inst = kc.robot, kc.instrument
    region = region_mm if region_mm is not None else inst.region_mm
    return select_poses(kc.model, count, modes=modes, start_mode=rt.working_mode,
                        assembly=rt.assembly_mode, frame=frame, margin=margin,
                        point_std=None if inst.sigma_mm is None else 1e-3 * inst.sigma_mm,
                        reading_std=(None if rt.encoder_counts is None
                                     else encoder_std(rt.encoder_counts)),
                        seed=seed, region=None if region is None else [1e-3 * v for v in region])


@dataclass(frozen=True)
class Calibrated:
    """A calibration from measured poses (``dextar calibrate``).

    Attributes
    ----------
    diagnosis : Diagnosis
        The fit (``diagnosis.result``: parameters, covariance, errors before and after, the
        verdict) or, where outliers stopped it, the fit that keeps them with their rows.
    data : PoseData
        The measured poses.
    held : PoseData or None
        The held-out poses (``validate``).
    """

    diagnosis: Diagnosis
    data: PoseData
    held: PoseData | None


def calibrate(data_path: str, kc: KinematicConfig, *, validate: str | None = None,
              frame: str = "instrument", robust: str | None = None,
              outlier_factor: float | None = None) -> Calibrated:
    """Calibrate the config's robot (its lengths, encoder offsets and the instrument frame)
    from the poses measured in the CSV ``data_path``; ``validate``: held-out poses; a fit
    stopped by outliers is diagnosed (:func:`~dextar.calibration.calibrate_or_diagnose`)."""
    rt, inst = kc.robot, kc.instrument
    data = read_poses_csv(data_path, working_mode=rt.working_mode)
    held = read_poses_csv(validate, working_mode=rt.working_mode) if validate else None
    diagnosis = calibrate_or_diagnose(
        data, kc.model, frame=frame, robust=robust, outlier_factor=outlier_factor,
        point_std=None if inst.sigma_mm is None else 1e-3 * inst.sigma_mm,
        reading_std=None if rt.encoder_counts is None else encoder_std(rt.encoder_counts),
        validation=held)
    return Calibrated(diagnosis, data, held)
