"""The one joint-friction model of dextar: viscous plus regularised Coulomb friction.

For each motor,

    tau_f = viscous * qdot + coulomb * tanh(qdot / coulomb_speed),

``coulomb_speed`` (``v_s``) is the regularisation speed: below a few ``v_s`` the Coulomb part
grows smoothly from zero, above it it is ``coulomb * sign(qdot)`` to within
``exp(-2 |qdot| / v_s)``. The model is exactly zero at rest, continuous, odd, and bounded by
``coulomb`` in magnitude, so a speed that is rounding noise (1e-14) gives a torque that is
rounding noise too, and a forward integration stays smooth through a velocity reversal.

Every stage that needs friction calls :func:`friction_torque`: the exact inverse dynamics
(and through it the forward dynamics and the control simulation), the time-optimal law's
limits and the MuJoCo export (``frictionloss`` and ``damping``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

#: Default regularisation speed ``v_s`` in config units (deg/s): 0.01 deg/s. Friction reaches
#: 99.5 % of its value at 0.03 deg/s, so it behaves as dry friction (MuJoCo's stiff
#: ``frictionloss`` replays our torques to 6e-5 rad over the paper's motion with gravity),
#: while a speed that is rounding noise still gives no friction.
DEFAULT_COULOMB_SPEED_DEG_S = 0.01


def friction_torque(dq: Any, viscous: float, coulomb: float, speed: float) -> Any:
    """Friction torque of one motor at joint rate ``dq`` (array or float).

    Parameters
    ----------
    dq : float or ndarray
        Joint rate (rad per time unit).
    viscous : float
        Viscous coefficient (torque per rad per time unit).
    coulomb : float
        Coulomb torque (magnitude at speed).
    speed : float
        Regularisation speed ``v_s`` (> 0, rad per time unit).

    Returns
    -------
    float or ndarray
        ``viscous * dq + coulomb * tanh(dq / speed)``, the shape of ``dq``.
    """
    if coulomb == 0.0:
        return viscous * dq
    if isinstance(dq, float):
        return viscous * dq + coulomb * math.tanh(dq / speed)
    return viscous * dq + coulomb * np.tanh(np.asarray(dq) / speed)
