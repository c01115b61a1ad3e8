"""Every job of the command line as one library call returning one typed result, from a
config (:class:`~dextar.config.Scenario`, or the robot's own tables for a calibration).

A command parses its options, calls its job, writes the result's files and prints; a Python
user calls the same job::

    from dextar import jobs
    from dextar.config import load_scenario

    res = jobs.run(load_scenario("examples/paper.toml"))      # the paper's example
    res.analysis.tau, res.summary["claims"], res.validation()  # torques, claims, checks
    prog = jobs.program(load_scenario("examples/pick_place.toml"))
    prog.fits, prog.summary.sizing.motors[0].rms_torque_Nm

====================  ==========================================  =========================
job                   call                                        result
====================  ==========================================  =========================
``dextar run``        :func:`run`                                 :class:`RunResult`
``dextar plan``       :func:`plan`                                :class:`Planned`
``dextar torques``    :func:`torques`                             :class:`Torques`
``dextar simulate``   :func:`simulate`                            :class:`Simulated`
``dextar export``     :func:`mjcf`                                MuJoCo XML (str)
``dextar program``    :func:`program`                             :class:`ProgramJob`
``dextar excite``     :func:`excite`                              :class:`Excitation`
``dextar identify``   :func:`identify_model`                      :class:`Identified`
``dextar poses``      :func:`poses`                               ``PoseSelection``
``dextar calibrate``  :func:`calibrate`                           :class:`Calibrated`
``dextar design``     :func:`design` (of :func:`design_sweep`)    :class:`Designed`
====================  ==========================================  =========================

The modules are imported when first used (a calibration loads no law; :mod:`dextar._lazy`).
"""

from typing import TYPE_CHECKING

from .._lazy import lazy_attributes

if TYPE_CHECKING:
    from ._calibration import Calibrated, calibrate, poses
    from ._design import Designed, DesignStore, DesignSweep, MemoryStore, design, design_sweep
    from ._identification import Excitation, Identified, excite, identify_model, task_motion
    from ._motion import Planned, Simulated, Torques, mjcf, plan, simulate, torques
    from ._program import ProgramJob, program
    from ._run import RunResult, run

__all__ = ["Calibrated", "DesignStore", "DesignSweep", "Designed", "Excitation", "Identified",
           "MemoryStore", "Planned", "ProgramJob", "RunResult", "Simulated", "Torques",
           "calibrate", "design", "design_sweep", "excite", "identify_model", "mjcf", "plan",
           "poses", "program", "run", "simulate", "task_motion", "torques"]

__getattr__, __dir__ = lazy_attributes(__name__, {
    **dict.fromkeys(("Calibrated", "calibrate", "poses"), "._calibration"),
    **dict.fromkeys(("Designed", "DesignStore", "DesignSweep", "MemoryStore", "design",
                     "design_sweep"), "._design"),
    **dict.fromkeys(("Excitation", "Identified", "excite", "identify_model", "task_motion"),
                    "._identification"),
    **dict.fromkeys(("Planned", "Simulated", "Torques", "mjcf", "plan", "simulate", "torques"),
                    "._motion"),
    **dict.fromkeys(("ProgramJob", "program"), "._program"),
    **dict.fromkeys(("RunResult", "run"), "._run"),
})
