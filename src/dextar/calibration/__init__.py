"""Kinematic calibration of a five-bar from measured poses, in all its working modes.

A real five-bar is off by its machining and assembly: rod lengths, the distance between the
pivots, the encoders' zero positions; and the instrument that measures it (a laser tracker,
a camera, a coordinate-measuring machine) sees it from a frame of its own. The model
(:mod:`.model`) has ten parameters, ``l1, l2, L1, L2, d``, the encoder offsets
``phi_offset, psi_offset`` (geometric angle = reading + offset) and the pose ``x0, y0,
theta0`` of the robot frame in the instrument's frame (seven when the points are given in
the robot frame). Which of them a set of poses identifies is computed
(:mod:`.observability`: the numerical rank of the scaled identification Jacobian); the
others are reported and kept nominal.

Poses from all four working modes make the parameters better observable than poses of one:
the idea of Joubair, Slamani and Bonev's calibration of the DexTAR (A. Joubair, M. Slamani,
I. A. Bonev, "Kinematic calibration of a five-bar planar parallel robot using all working
modes", Robotics and Computer-Integrated Manufacturing 29(4), 2013), who measured the robot
with a laser tracker in each working mode. :func:`select_poses` chooses poses from the
modes asked for (all four by default) to maximise the observability index O1;
``tests/calibration`` shows the difference one mode against four makes, in the index and in
the error on held-out poses.

Modules (each a stage, imports pointing down):

* :mod:`.model`: :class:`KinematicModel`, the prediction of a measured point and its
  analytic Jacobian, the readings that put the robot at a point (the inverse use);
* :mod:`.data`: :class:`PoseData` and :func:`read_poses_csv` (checked measured poses);
* :mod:`.observability`: identifiability, O1, O3 and the condition number;
* :mod:`.poses`: :func:`select_poses`, D-optimal measurement poses in visiting order;
* :mod:`.fit`: :func:`calibrate`, the least-squares fit and its checks, returning a
  :class:`CalibrationResult`;
* :mod:`.accuracy`: :func:`accuracy_map`, the predicted position uncertainty;
* :mod:`.synthetic`: a perturbed robot and noisy measurements of it.

Units: SI (m, rad) in Python; files speak mm and degrees.
"""

from .accuracy import AccuracyMap, accuracy_map, position_covariance
from .data import PoseData, poses_from_arrays, read_poses_csv
from .errors import CouplingError, OutlierError
from .fit import (
    CalibrationResult,
    Diagnosis,
    Errors,
    Parameter,
    calibrate,
    calibrate_or_diagnose,
    check_scale,
    encoder_std,
    register,
)
from .model import FRAME, NAMES, ROBOT, KinematicModel
from .observability import Identifiability, Observability, identifiability, observability
from .poses import PoseSelection, select_poses
from .synthetic import measure, perturbed

__all__ = [
    "FRAME",
    "NAMES",
    "ROBOT",
    "AccuracyMap",
    "CalibrationResult",
    "CouplingError",
    "Diagnosis",
    "Errors",
    "Identifiability",
    "KinematicModel",
    "Observability",
    "OutlierError",
    "Parameter",
    "PoseData",
    "PoseSelection",
    "accuracy_map",
    "calibrate",
    "calibrate_or_diagnose",
    "check_scale",
    "encoder_std",
    "identifiability",
    "measure",
    "observability",
    "perturbed",
    "poses_from_arrays",
    "position_covariance",
    "read_poses_csv",
    "register",
    "select_poses",
]
