"""CSV text from named columns (full precision), and the column names with their units.

Every CSV column is named ``quantity_unit``: the same quantity has the same name in every
command, and the unit token is that of the run's unit system:

========================  ===========  ==============
quantity                  SI           paper units
========================  ===========  ==============
time                      ``s``        ``T``
length, position          ``m``        ``L``
velocity                  ``m_s``      ``L_T``
acceleration              ``m_s2``     ``L_T2``
angle                     ``rad``      ``rad``
angular rate              ``rad_s``    ``rad_T``
angular acceleration      ``rad_s2``   ``rad_T2``
torque                    ``Nm``       ``mL2_T2``
energy                    ``J``        ``mL2_T2``
power                     ``W``        ``mL2_T3``
force                     ``N``        ``mL_T2``
path-parameter rate       ``per_s``    ``per_T``
========================  ===========  ==============

The path parameter ``p`` has the path's own unit (radians on an arc, none on a line).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._arrays import Array
from ..errors import NumericalError
from ..units import Units

_TOKENS = {
    "si": {"time": "s", "length": "m", "velocity": "m_s", "acceleration": "m_s2",
           "angle": "rad", "rate": "rad_s", "angular_acceleration": "rad_s2", "torque": "Nm",
           "energy": "J", "power": "W", "force": "N", "per_time": "per_s",
           "per_time2": "per_s2"},
    "paper": {"time": "T", "length": "L", "velocity": "L_T", "acceleration": "L_T2",
              "angle": "rad", "rate": "rad_T", "angular_acceleration": "rad_T2",
              "torque": "mL2_T2", "energy": "mL2_T2", "power": "mL2_T3", "force": "mL_T2",
              "per_time": "per_T", "per_time2": "per_T2"},
}


def unit_tokens(units: Units) -> dict[str, str]:
    """Column-name unit tokens of a unit system, by quantity."""
    return _TOKENS["si" if units.system == "si" else "paper"]


def trajectory_columns(tr: Any, units: Units) -> dict[str, Array]:
    """The motion columns of a trajectory: time, path parameter, end-effector and joints."""
    u = unit_tokens(units)
    return {
        f"t_{u['time']}": tr.t, "p": tr.p, f"dp_{u['per_time']}": tr.dp,
        f"ddp_{u['per_time2']}": tr.ddp,
        f"x_{u['length']}": tr.P[:, 0], f"y_{u['length']}": tr.P[:, 1],
        f"dx_{u['velocity']}": tr.dP[:, 0], f"dy_{u['velocity']}": tr.dP[:, 1],
        f"ddx_{u['acceleration']}": tr.ddP[:, 0], f"ddy_{u['acceleration']}": tr.ddP[:, 1],
        f"phi_{u['angle']}": tr.q[:, 0], f"psi_{u['angle']}": tr.q[:, 1],
        f"dphi_{u['rate']}": tr.dq[:, 0], f"dpsi_{u['rate']}": tr.dq[:, 1],
        f"ddphi_{u['angular_acceleration']}": tr.ddq[:, 0],
        f"ddpsi_{u['angular_acceleration']}": tr.ddq[:, 1],
    }


def number(v: float) -> str:
    """A float as written in every output: the shortest text that reads back to the same
    double (``0.0005``, not ``0.00050000000000000001``), and ``0.0`` for a negative zero."""
    return repr(float(v) + 0.0)


def csv_text(columns: dict[str, Array]) -> str:
    """CSV with a header row of the column names and one row per sample, each number the
    shortest text that reads back to the same double (:func:`number`).

    Raises :class:`~dextar.errors.NumericalError` naming the column and row of a value that
    is not finite: no NaN is ever written.
    """
    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    if not np.isfinite(data).all():
        bad = np.argwhere(~np.isfinite(data))[0]
        raise NumericalError(f"column {names[bad[1]]} is not finite at row {bad[0]} (the "
                             "parameters overflow double precision)")
    rows = (data + 0.0).tolist()  # + 0.0: no negative zeros
    return ",".join(names) + "\n" + "".join(",".join(map(repr, r)) + "\n" for r in rows)


def torque_columns(an: Any) -> dict[str, Array]:
    """Motion columns plus the exact (and, where it applies, the paper's) torques, the motor
    powers, the mechanism's kinetic energy and the passive-joint force magnitudes of an
    :class:`~dextar.analysis.Analysis`."""
    u = unit_tokens(an.units)
    cols = trajectory_columns(an.trajectory, an.units)
    cols[f"tau1_{u['torque']}"], cols[f"tau2_{u['torque']}"] = an.tau[:, 0], an.tau[:, 1]
    if an.paper is not None:
        cols[f"tau1_paper_{u['torque']}"] = an.paper.tau[:, 0]
        cols[f"tau2_paper_{u['torque']}"] = an.paper.tau[:, 1]
    cols[f"power1_{u['power']}"], cols[f"power2_{u['power']}"] = an.power[:, 0], an.power[:, 1]
    cols[f"kinetic_energy_{u['energy']}"] = an.energy
    for name, values in an.reaction_magnitudes().items():
        cols[f"{name}_{u['force']}"] = values
    return cols


def run_columns(an: Any) -> dict[str, Array]:
    """The columns of ``dextar run``: :func:`torque_columns` and, where the paper's model
    applies, the end-effector energies of its Fig. 6 (exact ``m |Pdot|^2 / 2``, (30) by
    finite differences, (32) with ``beta`` frozen)."""
    cols = torque_columns(an)
    if an.paper is not None:
        e = unit_tokens(an.units)["energy"]
        cols[f"effector_energy_{e}"] = an.paper.T_exact
        cols[f"effector_energy_fd_{e}"] = an.paper.T_fd
        cols[f"effector_energy_beta0_{e}"] = an.paper.T_approx
    return cols
