"""motion.png: the joint accelerations and jerks drawn with their limits when the motors set
them, and only the angles, speeds and torques when they do not."""

import numpy as np
import pytest

from dextar.motors import MotorLimits
from dextar.output.program import motion_figure
from dextar.program.plan import ProgramResult


def result(motors):
    t = np.linspace(0.0, 1.0, 201)
    q = np.stack([np.sin(2 * np.pi * t), np.cos(2 * np.pi * t)], -1)
    dq = np.gradient(q, t, axis=0)
    ddq = np.gradient(dq, t, axis=0)
    return ProgramResult([], 1.0, t, np.zeros(len(t), int), q, q, dq, ddq, 0.1 * ddq, motors)


def limit_lines(ax):
    """The levels of the horizontal dashed lines of an axis."""
    return sorted({round(float(ln.get_ydata()[0]), 9) for ln in ax.get_lines()
                   if ln.get_linestyle() == "--" and len(set(ln.get_ydata())) == 1})


@pytest.mark.slow
@pytest.mark.parametrize("kw, panels", [
    ({}, ["angle", "speed", "torque"]),
    ({"max_acceleration": (60.0, 50.0)}, ["angle", "speed", "acceleration", "torque"]),
    ({"max_jerk": (3000.0, 2000.0)}, ["angle", "speed", "acceleration", "jerk", "torque"]),
    ({"max_acceleration": (60.0, 50.0), "max_jerk": (3000.0, 2000.0),
      "max_torque_rate": (40.0, 40.0)},
     ["angle", "speed", "acceleration", "jerk", "torque rate", "torque"])])
def test_the_panels_follow_the_limits_the_motors_set(kw, panels):
    fig = motion_figure(result(MotorLimits((1.5, 1.5), (30.0, 30.0), None, **kw)))
    names = [ax.get_ylabel().split(" [")[0] for ax in fig.axes]
    assert names == panels
    by = dict(zip(names, fig.axes, strict=True))
    if "max_jerk" in kw:  # both motors' limits, both signs
        assert limit_lines(by["jerk"]) == [-3000.0, -2000.0, 2000.0, 3000.0]
    if "max_acceleration" in kw:
        assert limit_lines(by["acceleration"]) == [-60.0, -50.0, 50.0, 60.0]
    elif "acceleration" in by:  # drawn for the jerk limit, with no acceleration limit
        assert limit_lines(by["acceleration"]) == []


def test_the_jerk_drawn_is_the_setpoints_finite_difference():
    res = result(MotorLimits((1.5, 1.5), max_jerk=(3000.0, 3000.0)))
    ax = motion_figure(res).axes[3]
    line = ax.get_lines()[0]
    expected = np.diff(res.ddq[:, 0]) / np.diff(res.t)
    assert np.allclose(line.get_ydata(), expected)
