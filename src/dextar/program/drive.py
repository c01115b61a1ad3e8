"""A program in the drives' own units: the motor side of a gearbox, encoder counts and the
torque feedforward in per-mille of the rated torque (CiA 402), per servo tick (cyclic
synchronous position, ``csp.csv``) and as position-velocity-time points at a coarser period
whose cubic interpolation follows the planned motion (``pvt.csv``).

Conventions: motor at A first; ``counts = (q - encoder_offset) * gear_ratio * encoder_counts /
(2 pi)`` (from the encoders' zero, ``encoder_offset`` the joint angle at which an encoder
reads zero), the motor-side speed ``gear_ratio * qdot`` and torque ``tau / gear_ratio`` (an
ideal gearbox: no loss), the torque feedforward ``round(1000 tau_motor / rated_torque)``
(object 0x60B2, torque offset, in per-mille of the rated torque 0x6076). A torque
feedforward above 1000 per-mille runs the motor above its rating (named, a warning); above
the drive's own limit ``max_torque_permille`` (0x6072) the drive cannot give it (a
violation: the program does not fit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from ..errors import ParameterError
from .plan import ProgramResult
from .sizing import Violation

#: The rated torque in per-mille of itself (CiA 402's unit of the torque objects).
RATED_PERMILLE = 1000.0


@dataclass(frozen=True)
class DriveUnits:
    """The drives (SI).

    Attributes
    ----------
    gear_ratio : (float, float)
        Motor turns per joint turn.
    encoder_counts : (int, int)
        Counts per motor turn.
    rated_torque : (float, float), optional
        Motor-side rated torque (N m); the torque feedforward needs it.
    encoder_offset : (float, float)
        The joint angle (rad) at which each encoder reads zero.
    pvt_period : float
        The period of the PVT points (s).
    max_torque_permille : (float, float), optional
        The largest torque each drive gives, in per-mille of its rated torque (0x6072);
        needs the rated torque.
    """

    gear_ratio: tuple[float, float] = (1.0, 1.0)
    encoder_counts: tuple[int, int] = (4096, 4096)
    rated_torque: tuple[float, float] | None = None
    encoder_offset: tuple[float, float] = (0.0, 0.0)
    pvt_period: float = 0.01
    max_torque_permille: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        for name in ("gear_ratio", "encoder_counts"):
            v = np.asarray(getattr(self, name), float)
            if v.shape != (2,) or not np.all(np.isfinite(v) & (v > 0)):
                raise ParameterError(f"{name.replace('_', ' ')} {getattr(self, name)!r} must "
                                     "be two positive numbers")
        if self.rated_torque is not None:
            v = np.asarray(self.rated_torque, float)
            if v.shape != (2,) or not np.all(np.isfinite(v) & (v > 0)):
                raise ParameterError(f"rated torque {self.rated_torque!r} must be two positive "
                                     "numbers")
        if not (math.isfinite(self.pvt_period) and self.pvt_period > 0):
            raise ParameterError(f"PVT period {self.pvt_period!r} must be positive")
        if self.max_torque_permille is not None:
            v = np.asarray(self.max_torque_permille, float)
            if v.shape != (2,) or not np.all(np.isfinite(v) & (v > 0)):
                raise ParameterError(f"max torque {self.max_torque_permille!r} must be two "
                                     "positive numbers (per-mille of the rated torque)")
            if self.rated_torque is None:
                raise ParameterError("a max torque in per-mille needs the rated torque "
                                     "(rated_torque_Nm)")

    @property
    def counts_per_rad(self) -> Array:
        """Encoder counts per joint radian (2,)."""
        return np.asarray(np.asarray(self.gear_ratio, float)
                          * np.asarray(self.encoder_counts, float) / (2 * np.pi))

    def counts(self, q: Array) -> Array:
        """Joint angles (n, 2) to encoder counts from the encoders' zero (unrounded)."""
        return np.asarray((q - np.asarray(self.encoder_offset, float)) * self.counts_per_rad)

    def angles(self, counts: Array) -> Array:
        """Encoder counts (n, 2) back to joint angles (rad)."""
        return np.asarray(np.asarray(counts, float) / self.counts_per_rad
                          + np.asarray(self.encoder_offset, float))

    def motor_torque(self, tau: Array) -> Array:
        """Joint torques (n, 2) to motor-side torques (N m)."""
        return np.asarray(tau / np.asarray(self.gear_ratio, float))

    def permille(self, tau: Array) -> Array:
        """Joint torques (n, 2) to the torque feedforward in per-mille of the rated torque
        (rounded); needs the rated torque."""
        if self.rated_torque is None:
            raise ParameterError("the torque feedforward needs [drive].rated_torque_Nm")
        return np.asarray(np.round(1000.0 * self.motor_torque(tau)
                                   / np.asarray(self.rated_torque, float)))


def csp_columns(res: ProgramResult, drive: DriveUnits) -> dict[str, Array]:
    """``csp.csv``: per servo tick the target positions (counts, rounded), the velocities
    (counts/s) and the torque feedforward (per-mille of the rated torque, rounded; columns
    left out without a rated torque)."""
    pos = np.round(drive.counts(res.q))
    vel = res.dq * drive.counts_per_rad
    out = {"t_s": res.t, "pos1_counts": pos[:, 0], "pos2_counts": pos[:, 1],
           "vel1_counts_s": vel[:, 0], "vel2_counts_s": vel[:, 1]}
    if drive.rated_torque is not None:
        pm = drive.permille(res.tau)
        out |= {"torque1_permille": pm[:, 0], "torque2_permille": pm[:, 1]}
    return out


@dataclass(frozen=True)
class PvtPoints:
    """Position-velocity-time points and how closely their cubic follows the plan.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Every ``pvt_period`` from the first servo tick to the first multiple at or after the
        last (a whole number of servo ticks; the final pose held at rest after the last
        tick, as the setpoints hold it).
    pos, vel : ndarray, shape (m, 2)
        Counts (rounded) and counts/s.
    max_error_counts : float
        Largest distance, in counts, between the cubic Hermite interpolation of the points
        and the planned motion at every servo tick (the final pose held to the last point).
    """

    t: Array
    pos: Array
    vel: Array
    max_error_counts: float

    def columns(self) -> dict[str, Array]:
        """``pvt.csv``."""
        return {"t_s": self.t, "pos1_counts": self.pos[:, 0], "pos2_counts": self.pos[:, 1],
                "vel1_counts_s": self.vel[:, 0], "vel2_counts_s": self.vel[:, 1]}


def hermite(t: Array, tk: Array, pk: Array, vk: Array) -> Array:
    """The cubic Hermite interpolation of points ``(tk, pk, vk)`` (m,), (m, 2) at ``t`` (n,),
    (n, 2): what a drive's PVT mode runs between its points."""
    k = np.clip(np.searchsorted(tk, t, side="right") - 1, 0, len(tk) - 2)
    h = (tk[k + 1] - tk[k])[:, None]
    u = ((t - tk[k])[:, None]) / h
    h00, h10 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u
    h01, h11 = -2 * u**3 + 3 * u**2, u**3 - u**2
    return np.asarray(h00 * pk[k] + h10 * h * vk[k] + h01 * pk[k + 1] + h11 * h * vk[k + 1])


def pvt_points(res: ProgramResult, drive: DriveUnits) -> PvtPoints:
    """The PVT points every ``drive.pvt_period`` from the setpoints, to the first multiple of
    the period at or after the last servo tick (the final pose held at rest there, as the
    setpoints hold it after the cycle), and the largest error of their cubic against the
    planned motion (in counts, over every servo tick, the held ones included).

    Raises
    ------
    ParameterError
        A period that is not a whole number of servo ticks (named with the tick).
    """
    t = res.t
    tick = float(np.median(np.diff(t))) if len(t) > 1 else drive.pvt_period
    step = max(1, int(round(drive.pvt_period / tick)))
    if abs(step * tick - drive.pvt_period) > 1e-6 * drive.pvt_period:
        raise ParameterError(f"PVT period {1e3 * drive.pvt_period:g} ms is not a whole number "
                             f"of servo ticks ({1e3 * tick:.6g} ms): make [drive].pvt_period_ms "
                             f"a multiple of it (e.g. {1e3 * step * tick:.6g} ms)")
    idx = np.arange(0, len(t), step)
    pos = np.round(drive.counts(res.q[idx]))
    vel = res.dq[idx] * drive.counts_per_rad
    # every time from its whole number of servo ticks, as the setpoints' own (k / rate): a
    # sum of rounded times had written 1.7080000000000002 s for the 7 ms period's 1.708 s
    rate = res.servo_rate_hz or 1.0 / tick
    planned = drive.counts(res.q)
    ticks = idx
    if idx[-1] != len(t) - 1:  # one period more: the final pose, held at rest
        hold = step - (len(t) - 1 - idx[-1])
        ticks = np.append(idx, idx[-1] + step)
        pos = np.vstack([pos, np.round(planned[-1:])])
        vel = np.vstack([vel, np.zeros((1, 2))])
        planned = np.vstack([planned, np.repeat(planned[-1:], hold, axis=0)])
    tk = ticks / rate
    ts = np.arange(len(planned)) / rate
    err = float(np.abs(hermite(ts, tk, pos, vel) - planned).max()) if len(tk) > 1 else 0.0
    return PvtPoints(tk, pos, vel, err)


def torque_checks(res: ProgramResult, drive: DriveUnits) -> tuple[list[Violation], list[str]]:
    """The torque feedforward against the drives: a :class:`Violation` per motor whose
    peak (per-mille of its rated torque) exceeds the drive's ``max_torque_permille``, and a
    warning per motor above its rating (1000 per-mille) within that limit (or without one);
    the motor, the peak, the rated torque, the move and the time named. Nothing without a
    rated torque."""
    if drive.rated_torque is None:
        return [], []
    pm = np.abs(drive.permille(res.tau))
    violations: list[Violation] = []
    warnings: list[str] = []
    for i, name in enumerate(("A", "D")):
        k = int(np.argmax(pm[:, i]))
        peak = float(pm[k, i])
        rated = float(drive.rated_torque[i])
        limit = None if drive.max_torque_permille is None else float(
            drive.max_torque_permille[i])
        if limit is not None and peak > limit:
            violations.append(Violation(
                name, f"torque feedforward (per-mille of the rated torque {rated:g} N m)",
                peak, limit, int(res.move_index[k]), float(res.t[k]),
                note=" ([drive].max_torque_permille)", limit_of="drive"))
        elif peak > RATED_PERMILLE:
            within = f", within the drive's {limit:g}" if limit is not None else ""
            warnings.append(
                f"motor {name}'s torque feedforward reaches {peak:g} per-mille of its rated "
                f"torque {rated:g} N m ({1e-3 * peak * rated:.4g} N m at the motor) at t = "
                f"{float(res.t[k]):.4g} s in move {int(res.move_index[k])}: above its rating "
                f"(1000 per-mille){within}")
    return violations, warnings


def drive_report(res: ProgramResult, drive: DriveUnits, rotor_inertia: tuple[float, float]
                 ) -> dict[str, object]:
    """The motor side of the program: per motor the peak speed (rpm) and the peak and RMS
    torques (N m, and against the rated torque), and the reflected rotor inertia's share of
    the torques (its RMS torque ``I_r qddot`` over the RMS torque; ``rotor_inertia`` the
    joint-side rotor inertias, kg m^2, as the model has them)."""
    g = np.asarray(drive.gear_ratio, float)
    w = np.abs(res.dq).max(axis=0) * g * 60.0 / (2 * np.pi)
    tm = drive.motor_torque(res.tau)
    t = res.t
    dt = np.diff(t)

    def rms(x: Array) -> Array:
        return np.asarray(np.sqrt(np.sum(0.5 * (x[1:] ** 2 + x[:-1] ** 2) * dt[:, None], axis=0)
                                  / max(float(t[-1]), 1e-300)))

    rotor = res.ddq * np.asarray(rotor_inertia, float)
    share = rms(rotor) / np.maximum(rms(res.tau), 1e-300)
    motors = []
    for i, name in enumerate(("A", "D")):
        m: dict[str, object] = {
            "motor": name, "peak_speed_rpm": float(w[i]),
            "peak_torque_Nm": float(np.abs(tm[:, i]).max()),
            "rms_torque_Nm": float(rms(tm)[i]),
            "reflected_rotor_inertia_kg_m2": float(rotor_inertia[i]),
            "motor_rotor_inertia_kg_m2": float(rotor_inertia[i] / g[i] ** 2),
            "rotor_torque_share_rms": float(share[i])}
        if drive.rated_torque is not None:
            m["peak_torque_permille"] = float(1000 * np.abs(tm[:, i]).max()
                                              / drive.rated_torque[i])
        if drive.max_torque_permille is not None:
            m["max_torque_permille"] = float(drive.max_torque_permille[i])
        motors.append(m)
    return {"gear_ratio": list(drive.gear_ratio), "encoder_counts": list(drive.encoder_counts),
            "encoder_offset_deg": [math.degrees(v) for v in drive.encoder_offset],
            "pvt_period_s": drive.pvt_period, "motors": motors}
