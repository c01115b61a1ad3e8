"""Motor sizing of a planned program: per motor the peak and RMS torque, the peak speed and
power, the energy delivered, the peak acceleration, jerk and torque rate (finite differences
at the servo rate), their ratios to the motors' limits, and the violations."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from .plan import ProgramResult

#: Relative excess over a limit that counts as a violation.
SIZING_TOL = 1e-3
#: ... for the rates measured by finite differences at the servo rate (jerk, torque rate).
SIZING_TOL_RATES = {"jerk": 1e-2, "torque_rate": 1e-2}
#: Both, as ``summary.json`` states them: a limit is exceeded beyond ``1 + tolerance`` times
#: it (``other``: torque, speed, RMS torque, acceleration).
SIZING_TOLERANCES = {"other": SIZING_TOL, **SIZING_TOL_RATES}


@dataclass(frozen=True)
class MotorSizing:
    """One motor over the cycle (SI).

    Attributes
    ----------
    motor : str
        ``"A"`` or ``"D"``.
    peak_torque_Nm, rms_torque_Nm, peak_speed_rad_s, peak_power_W, energy_J : float
        The energy is the positive work the motor delivers.
    peak_torque_ratio, peak_speed_ratio : float, optional
        Against the torque available at the speed (the envelope) and the maximum speed
        (None without motors).
    rms_torque_ratio : float, optional
        Against the continuous rating (None without one).
    peak_acceleration_rad_s2, peak_jerk_rad_s3, peak_torque_rate_Nm_s : float, optional
        The jerk and the torque rate by finite differences of the setpoints at the servo rate.
    peak_acceleration_ratio, peak_jerk_ratio, peak_torque_rate_ratio : float, optional
        Against ``[motors]``' limits (None without one).
    """

    motor: str
    peak_torque_Nm: float
    rms_torque_Nm: float
    peak_speed_rad_s: float
    peak_power_W: float
    energy_J: float
    peak_torque_ratio: float | None = None
    peak_speed_ratio: float | None = None
    rms_torque_ratio: float | None = None
    peak_acceleration_rad_s2: float | None = None
    peak_jerk_rad_s3: float | None = None
    peak_torque_rate_Nm_s: float | None = None
    peak_acceleration_ratio: float | None = None
    peak_jerk_ratio: float | None = None
    peak_torque_rate_ratio: float | None = None

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready, the ratios that do not apply left out."""
        return {k: v for k, v in asdict(self).items() if v is not None}


@dataclass(frozen=True)
class Violation:
    """A limit a motor exceeds: where (the move and the time; None for the RMS rating, a
    property of the whole cycle), the value and the limit (SI)."""

    motor: str
    quantity: str
    value: float
    limit: float
    move: int | None
    t_s: float | None
    #: Where the limit comes from when it is not the plain one (the torque-speed envelope).
    note: str = ""
    #: Whose limit it is: ``"motor"`` (``[motors]``) or ``"drive"`` (``[drive]``).
    limit_of: str = "motor"

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return asdict(self)

    @property
    def unit(self) -> str:
        """The SI unit of the value and the limit."""
        return UNITS.get(self.quantity, "")

    def text(self) -> str:
        """The violation in words, with its unit."""
        where = (f" at t = {self.t_s:.4g} s in move {self.move}" if self.t_s is not None
                 else "")
        u = f" {self.unit}" if self.unit else ""
        whose = "its limit" if self.limit_of == "motor" else "the drive's limit"
        return (f"motor {self.motor} {self.quantity} {self.value:.4g}{u} above {whose} "
                f"{self.limit:.4g}{u}{self.note}{where}")


#: The units of the quantities a :class:`Violation` names (SI).
UNITS = {"torque": "N m", "rms_torque": "N m", "speed": "rad/s", "acceleration": "rad/s^2",
         "jerk": "rad/s^3", "torque_rate": "N m/s"}


@dataclass(frozen=True)
class Sizing:
    """The motors over the cycle and the limits they exceed."""

    motors: tuple[MotorSizing, MotorSizing]
    violations: tuple[Violation, ...]

    @property
    def fits(self) -> bool:
        """True when no limit is exceeded."""
        return not self.violations

    @property
    def exceeded(self) -> str:
        """Whose limits the violations are, in words: ``"the motors"``, ``"the drives"``,
        ``"the motors and the drives"`` (empty when it fits)."""
        whose = {v.limit_of for v in self.violations}
        return " and ".join(f"the {w}s" for w in ("motor", "drive") if w in whose)


def sizing(res: ProgramResult) -> Sizing:
    """Per motor: peak and RMS torque, peak speed, peak power, energy (with their ratios to
    the limits), and the violations."""
    t, tau, dq = res.t, res.tau, res.dq
    power = tau * dq
    dt = np.diff(t)
    step = np.where(dt > 0, dt, np.inf)[:, None]
    jerk = np.diff(res.ddq, axis=0) / step
    rate = np.diff(tau, axis=0) / step
    mo = res.motors
    # the motion's rates are reported when the motors limit one of them (outputs without
    # those limits stay as they were)
    drive_limits = mo is not None and any(
        v is not None for v in (mo.max_acceleration, mo.max_jerk, mo.max_torque_rate))
    motors_out: list[MotorSizing] = []
    violations: list[Violation] = []
    for i, name in enumerate(("A", "D")):
        pos = np.maximum(power[:, i], 0.0)
        rms = float(math.sqrt(np.sum(0.5 * (tau[1:, i] ** 2 + tau[:-1, i] ** 2) * dt)
                              / max(t[-1], 1e-300)))
        ratios: dict[str, float] = {}
        if res.motors is not None:
            m = res.motors
            avail = m.available_torque(dq)[:, i]
            ratio = np.abs(tau[:, i]) / np.maximum(avail, 1e-300)
            ratios["peak_torque_ratio"] = float(ratio.max())
            if math.isfinite(m.max_speed[i]):  # (no ratio to a limit not set)
                ratios["peak_speed_ratio"] = float(np.abs(dq[:, i]).max() / m.max_speed[i])
            k = int(np.argmax(ratio))
            if ratio[k] > 1.0 + SIZING_TOL:
                peak = float(np.asarray(m.peak_torque, float)[i])
                note = (f" (the torque-speed envelope's at {abs(dq[k, i]):.4g} rad/s; the peak "
                        f"{peak:.4g} N m)" if avail[k] < peak * (1 - 1e-9) else "")
                violations.append(Violation(name, "torque", float(abs(tau[k, i])),
                                            float(avail[k]), int(res.move_index[k]),
                                            float(t[k]), note))
            k = int(np.argmax(np.abs(dq[:, i])))
            if abs(dq[k, i]) > m.max_speed[i] * (1 + SIZING_TOL):
                violations.append(Violation(name, "speed", float(abs(dq[k, i])),
                                            float(m.max_speed[i]), int(res.move_index[k]),
                                            float(t[k])))
        motion = {"acceleration": np.abs(res.ddq[:, i]), "jerk": np.abs(jerk[:, i]),
                  "torque_rate": np.abs(rate[:, i])}
        if res.motors is not None:
            m = res.motors
            for key, lim in (("acceleration", m.max_acceleration), ("jerk", m.max_jerk),
                             ("torque_rate", m.max_torque_rate)):
                if lim is None:
                    continue
                v = motion[key]
                k = int(np.argmax(v))
                ratios[f"peak_{key}_ratio"] = float(v[k] / lim[i])
                if v[k] > lim[i] * (1 + SIZING_TOL_RATES.get(key, SIZING_TOL)):
                    violations.append(Violation(name, key, float(v[k]), float(lim[i]),
                                                int(res.move_index[k]), float(t[k])))
        if res.rms_limit is not None:
            ratios["rms_torque_ratio"] = rms / res.rms_limit[i]
            if rms > res.rms_limit[i] * (1 + SIZING_TOL):
                violations.append(Violation(name, "rms_torque", rms, float(res.rms_limit[i]),
                                            None, None))
        motors_out.append(MotorSizing(
            name, float(np.abs(tau[:, i]).max()), rms, float(np.abs(dq[:, i]).max()),
            float(np.abs(power[:, i]).max()), float(np.sum(0.5 * (pos[1:] + pos[:-1]) * dt)),
            **({} if not drive_limits else {
                "peak_acceleration_rad_s2": float(motion["acceleration"].max()),
                "peak_jerk_rad_s3": float(motion["jerk"].max()) if len(jerk) else 0.0,
                "peak_torque_rate_Nm_s": float(motion["torque_rate"].max()) if len(rate)
                else 0.0}),
            **ratios))
    return Sizing((motors_out[0], motors_out[1]), tuple(violations))
