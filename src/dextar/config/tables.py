"""One frozen dataclass per TOML table, built and validated at the boundary.

Each table declares its keys (:class:`dextar.params.Param`: type, unit, default, bounds) and
holds its values in config units (mm, deg, kg, s, N m) after :func:`read_params` has checked
them; errors name ``[table].key``. The conversion to the run's units happens once, where the
:class:`~dextar.config.scenario.Scenario` builds the run's objects.

The robot's own tables, ``[robot]`` and ``[instrument]``, are in
:mod:`dextar.config.kinematic`; ``[program]`` in :mod:`dextar.config.program`, ``[design]`` in
:mod:`dextar.config.design`; the registry in :mod:`dextar.config.base`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

from ..dynamics import Counterweight, Inertia, Rod
from ..dynamics.friction import DEFAULT_COULOMB_SPEED_DEG_S
from ..errors import ConfigError, DextarError
from ..geometry import FiveBar
from ..kinematics.checker import Tolerances
from ..laws import LawType, law_type
from ..motors import MotorLimits
from ..output.run import FIGURES as FIGURES
from ..params import Param, read_params, to_run_units
from ..paths import Path, PathType, path_type
from ..units import Units
from .base import Table

#: Most samples a run writes (a 200 s motion at 1 kHz).
MAX_SAMPLES = 200_000


@dataclass(frozen=True)
class PathTable(Table):
    """``[path]``: a registered path type and its keys (config units)."""

    NAME: ClassVar[str] = "path"
    #: The keys of every path type.
    COMMON: ClassVar[dict[str, Param]] = {
        "assembly_mode": Param(
            "choice", "", None, "the assembly mode at the path's end, up or down (default: "
            "[robot].assembly_mode, the start's); another one asks the path to cross the "
            "parallel (type 2) singularity curve of the working mode, which the time-optimal "
            "law does under the degeneracy condition", choices=("up", "down"))}

    type: str = "arc"
    values: Mapping[str, Any] = field(default_factory=lambda: {
        "radius": 120.0, "center": (0.0, 0.0), "start_deg": 0.0, "end_deg": 180.0})
    assembly_mode: str | None = None

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> PathTable:
        """Read ``[path]`` against the keys its type registered (and :attr:`COMMON`)."""
        kind = path_type(raw.get("type", "arc"))
        values = read_params(cls.NAME, raw, kind.params, ignore=("type", *cls.COMMON))
        common = read_params(cls.NAME, {k: v for k, v in raw.items() if k in cls.COMMON},
                             cls.COMMON)
        return cls(kind.name, values, common.get("assembly_mode"))

    @property
    def kind(self) -> PathType:
        """The registered path type."""
        return path_type(self.type)

    def build(self, units: Units) -> Path:
        """The path in the run's units."""
        try:
            return self.kind.build(to_run_units(self.values, self.kind.params, units), units)
        except ConfigError:
            raise
        except DextarError as exc:
            raise ConfigError(f"config table [path]: {exc}") from None

    def summary(self) -> dict[str, Any]:
        """The path as configured, JSON-ready (lengths in mm, angles in degrees)."""
        out: dict[str, Any] = {"type": self.type}
        if self.assembly_mode is not None:
            out["assembly_mode"] = self.assembly_mode
        for k, v in self.values.items():
            unit = self.kind.params[k].unit
            name = f"{k}_mm" if unit == "mm" else k
            out[name] = [list(w) for w in v] if isinstance(v, tuple) and v and isinstance(
                v[0], tuple) else list(v) if isinstance(v, tuple) else v
        return out


@dataclass(frozen=True)
class LawTable(Table):
    """``[law]``: a registered law and its keys (config units)."""

    NAME: ClassVar[str] = "law"

    type: str = "optimal"
    values: Mapping[str, Any] = field(default_factory=lambda: {"duration": 1.0, "eta": 0.1})

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> LawTable:
        """Read ``[law]`` against the keys its law registered."""
        if "samples" in raw:
            raise ConfigError("config key [law].samples is not known: use [output].samples "
                              "(the number of samples written)")
        kind = law_type(raw.get("type", "optimal"))
        return cls(kind.name, read_params(cls.NAME, raw, kind.params, ignore=("type",)))

    @property
    def kind(self) -> LawType:
        """The registered law."""
        return law_type(self.type)

    def run_values(self, units: Units) -> dict[str, Any]:
        """The law's keys in the run's units."""
        return to_run_units(self.values, self.kind.params, units)

    @property
    def duration_s(self) -> float:
        """The configured duration in seconds (1 s when the law has none): the time unit of
        the paper's units."""
        d = self.values.get("duration")
        return 1.0 if d is None else float(d)


def _pair(unit: str, help: str, default: float | None = None, **kw: Any) -> Param:
    """A number or [motor A, motor D] key (its default a pair too)."""
    return Param("pair", unit, None if default is None else (default, default), help, **kw)


@dataclass(frozen=True)
class InertiaTable(Table):
    """``[inertia]``: masses (kg), centres of mass (mm), inertias (kg mm^2)."""

    NAME: ClassVar[str] = "inertia"
    PARAMS: ClassVar[dict[str, Param]] = {
        "effector_mass": Param("number", "kg", 1.0, "end-effector mass", positive=True),
        "payload": Param("number", "kg", 0.0, "payload at P", minimum=0.0),
        "proximal_mass": _pair("kg", "proximal rods' masses (default 0.08 x effector_mass)",
                               None, minimum=0.0),
        "distal_mass": _pair("kg", "distal rods' masses (default 0.1 x effector_mass)", None,
                             minimum=0.0),
        "proximal_com": _pair("mm", "proximal centres of mass from the joint (default: half "
                              "the rod)"),
        "distal_com": _pair("mm", "distal centres of mass from the elbow (default: half the "
                            "rod)"),
        "proximal_inertia": _pair("", "proximal inertias about the com, kg mm^2 (default: a "
                                  "uniform rod, m l^2 / 12)", minimum=0.0),
        "distal_inertia": _pair("", "distal inertias about the com, kg mm^2 (default: a "
                                "uniform rod, m L^2 / 12)", minimum=0.0),
        "rotor_inertia": _pair("", "rotor inertias, kg mm^2", 0.0, minimum=0.0),
        "counterweight_mass": _pair("kg", "counterweights on the proximal rods, behind the "
                                    "motor axes (folded exactly into the rods' mass, centre "
                                    "and inertia)", 0.0, minimum=0.0),
        "counterweight_distance": _pair("mm", "distance of each counterweight's centre "
                                        "behind its motor axis, on the rod's axis", None,
                                        minimum=0.0),
        "counterweight_inertia": _pair("", "counterweights' inertias about their own "
                                       "centres, kg mm^2", 0.0, minimum=0.0),
    }

    effector_mass: float = 1.0
    payload: float = 0.0
    proximal_mass: tuple[float, float] | None = None
    distal_mass: tuple[float, float] | None = None
    proximal_com: tuple[float, float] | None = None
    distal_com: tuple[float, float] | None = None
    proximal_inertia: tuple[float, float] | None = None
    distal_inertia: tuple[float, float] | None = None
    rotor_inertia: tuple[float, float] = (0.0, 0.0)
    counterweight_mass: tuple[float, float] = (0.0, 0.0)
    counterweight_distance: tuple[float, float] | None = None
    counterweight_inertia: tuple[float, float] = (0.0, 0.0)

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> InertiaTable:
        """Read ``[inertia]``; a counterweight's mass needs its distance."""
        t = cls(**read_params(cls.NAME, raw, cls.PARAMS))
        if any(m > 0 for m in t.counterweight_mass) and t.counterweight_distance is None:
            raise ConfigError("config key [inertia].counterweight_mass needs "
                              "[inertia].counterweight_distance (mm behind the motor axis)")
        for m, i in zip(t.counterweight_mass, t.counterweight_inertia, strict=True):
            if m == 0 and i > 0:
                raise ConfigError(f"config key [inertia].counterweight_inertia "
                                  f"{list(t.counterweight_inertia)}: a counterweight of no "
                                  "mass has no inertia")
        return t

    def counterweights(self, units: Units) -> tuple[Counterweight, Counterweight]:
        """The proximal rods' counterweights in run units (none without a mass)."""
        r = self.counterweight_distance or (0.0, 0.0)
        cw = [Counterweight(units.mass(self.counterweight_mass[k]), units.length(r[k]),
                            units.inertia(self.counterweight_inertia[k])) for k in range(2)]
        return cw[0], cw[1]

    def build(self, units: Units, g: FiveBar, friction: FrictionTable,
              gravity: GravityTable) -> Inertia:
        """The run's :class:`~dextar.dynamics.Inertia` (uniform rods where not given; the
        paper's Fig. 9 ratios 0.08 and 0.1 of the end-effector mass by default), the
        counterweights folded into the proximal rods."""
        m = self.effector_mass

        def rods(masses: tuple[float, float] | None, coms: tuple[float, float] | None,
                 inert: tuple[float, float] | None, lengths: tuple[float, float],
                 ratio: float) -> tuple[Rod, Rod]:
            ms = masses or (ratio * m, ratio * m)
            out = []
            for k in range(2):
                c = coms[k] if coms else 0.5 * lengths[k]
                i = inert[k] if inert else ms[k] * lengths[k] ** 2 / 12.0
                out.append(Rod(units.mass(ms[k]), units.length(c), units.inertia(i)))
            return out[0], out[1]

        try:
            return Inertia(
                proximal=rods(self.proximal_mass, self.proximal_com, self.proximal_inertia,
                              (g.l1, g.l2), 0.08),
                distal=rods(self.distal_mass, self.distal_com, self.distal_inertia,
                            (g.L1, g.L2), 0.1),
                effector_mass=units.mass(m), payload=units.mass(self.payload),
                rotor=(units.inertia(self.rotor_inertia[0]),
                       units.inertia(self.rotor_inertia[1])),
                viscous=(units.torque(friction.viscous[0]) / units.time_s,
                         units.torque(friction.viscous[1]) / units.time_s),
                coulomb=(units.torque(friction.coulomb[0]), units.torque(friction.coulomb[1])),
                gravity=(units.acceleration(gravity.vector[0]),
                         units.acceleration(gravity.vector[1])),
                coulomb_speed=math.radians(friction.coulomb_speed_deg_s) * units.time_s
            ).with_counterweights(self.counterweights(units))
        except DextarError as exc:
            raise ConfigError(f"config table [inertia]: {exc}") from None


@dataclass(frozen=True)
class FrictionTable(Table):
    """``[friction]``: ``tau_f = viscous qdot + coulomb tanh(qdot / v_s)`` per motor."""

    NAME: ClassVar[str] = "friction"
    PARAMS: ClassVar[dict[str, Param]] = {
        "viscous": _pair("", "viscous coefficients, N m s/rad", 0.0, minimum=0.0),
        "coulomb": _pair("N m", "Coulomb torques", 0.0, minimum=0.0),
        "coulomb_speed_deg_s": Param("number", "", DEFAULT_COULOMB_SPEED_DEG_S,
                                     "regularisation speed v_s, deg/s", positive=True),
    }

    viscous: tuple[float, float] = (0.0, 0.0)
    coulomb: tuple[float, float] = (0.0, 0.0)
    coulomb_speed_deg_s: float = DEFAULT_COULOMB_SPEED_DEG_S


@dataclass(frozen=True)
class GravityTable(Table):
    """``[gravity]``: the in-plane gravity vector, mm/s^2."""

    NAME: ClassVar[str] = "gravity"
    PARAMS: ClassVar[dict[str, Param]] = {
        "vector": Param("point", "", (0.0, 0.0), "gravity [gx, gy] in mm/s^2")}

    vector: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class ControlTable(Table):
    """``[control]``: the computed-torque simulation (``dextar simulate``)."""

    NAME: ClassVar[str] = "control"
    PARAMS: ClassVar[dict[str, Param]] = {
        "natural_frequency_hz": Param("number", "", 10.0, "closed-loop natural frequency, Hz",
                                      positive=True, maximum=1000.0),
        "damping": Param("number", "", 1.0, "damping ratio", positive=True, maximum=100.0),
        "mass_error": Param("number", "", 0.2, "the plant's masses are (1 + this) times the "
                            "model's", minimum=-0.99, maximum=100.0),
        "payload": Param("number", "kg", None, "payload unknown to the controller (default "
                         "0.1 of the end-effector mass)", minimum=0.0, maximum=1e4),
        "torque_limit": Param("number", "N m", None, "saturation of each motor",
                              positive=True, maximum=1e6),
        "initial_error_deg": Param("point", "", (0.0, 0.0), "initial joint error [deg, deg], "
                                   "each within +-90"),
        "tolerance_mm": Param("number", "mm", None, "the task error within which the motion "
                              "is followed (default 3 % of the robot's reach); past it "
                              "simulate exits 1", positive=True, maximum=1e9),
    }

    natural_frequency_hz: float = 10.0
    damping: float = 1.0
    mass_error: float = 0.2
    payload: float | None = None
    torque_limit: float | None = None
    initial_error_deg: tuple[float, float] = (0.0, 0.0)
    tolerance_mm: float | None = None

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> ControlTable:
        """Read ``[control]``; the initial error is at most 90 deg per joint."""
        t = cls(**read_params(cls.NAME, raw, cls.PARAMS))
        if any(abs(v) > 90.0 for v in t.initial_error_deg):
            raise ConfigError(f"config key [control].initial_error_deg "
                              f"{list(t.initial_error_deg)} must be within +-90 deg per joint")
        return t

    def run_values(self, units: Units, effector_kg: float) -> dict[str, Any]:
        """The controller's settings in run units (and their config values)."""
        payload = 0.1 * effector_kg if self.payload is None else self.payload
        return {
            "natural_frequency": 2 * math.pi * self.natural_frequency_hz * units.time_s,
            "natural_frequency_hz": self.natural_frequency_hz, "damping": self.damping,
            "mass_error": self.mass_error, "payload": units.mass(payload),
            "payload_kg": payload,
            "torque_limit": None if self.torque_limit is None else units.torque(
                self.torque_limit),
            "torque_limit_nm": self.torque_limit,
            "initial_error": tuple(math.radians(v) for v in self.initial_error_deg),
            "tolerance": None if self.tolerance_mm is None else units.length(
                self.tolerance_mm),
            "tolerance_mm": self.tolerance_mm,
        }


@dataclass(frozen=True)
class PaperTable(Table):
    """``[paper]``: the interpretation of the paper's model and its Fig. 7."""

    NAME: ClassVar[str] = "paper"
    PARAMS: ClassVar[dict[str, Param]] = {
        "beta0_time": Param("number", "", 0.5, "beta0 at this fraction of the motion time",
                            minimum=0.0, maximum=1.0),
        "fig7_distal_mass_ratio": Param("number", "", 0.5, "Fig. 7: mL / m", minimum=0.0),
        "fig7_lambda": Param("number", "", 0.5, "Fig. 7: lambda", minimum=0.0, maximum=1.0),
    }

    beta0_time: float = 0.5
    fig7_distal_mass_ratio: float = 0.5
    fig7_lambda: float = 0.5


@dataclass(frozen=True)
class OutputTable(Table):
    """``[output]``: the run's unit system and what is written."""

    NAME: ClassVar[str] = "output"
    PARAMS: ClassVar[dict[str, Param]] = {
        "units": Param("choice", "", "paper", "paper or si", choices=("paper", "si")),
        "samples": Param("integer", "", 1001, "samples written", minimum=2,
                         maximum=MAX_SAMPLES),
        "figures": Param("text", "", None, "figures to draw (default: all that apply: the "
                         "paper's example all; another task without fig3 and fig7, which "
                         "are about the paper's own example)"),  # a list: read below
        "animation_frames": Param("integer", "", 41, "frames of the animation at most (it "
                                  "plays in real time, 20 ms a frame at least)", minimum=2,
                                  maximum=1000),
        "servo_rate_hz": Param("number", "", 1000.0, "setpoint rate of a program, Hz",
                               positive=True, maximum=100_000.0),
    }

    units: str = "paper"
    samples: int = 1001
    figures: tuple[str, ...] | None = None
    animation_frames: int = 41
    servo_rate_hz: float = 1000.0

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> OutputTable:
        """Read ``[output]``; ``figures`` is a list of figure names."""
        rest = {k: v for k, v in raw.items() if k != "figures"}
        t = read_params(cls.NAME, rest, cls.PARAMS)
        figures = raw.get("figures")
        if figures is None:
            return cls(**t)
        if not isinstance(figures, list):
            raise ConfigError(f"config key [output].figures must be a list, got "
                              f"{type(figures).__name__} {figures!r}")
        for f in figures:
            if f not in FIGURES:
                raise ConfigError(f"config key [output].figures: unknown figure {f!r}; known: "
                                  f"{', '.join(FIGURES)}")
        t.pop("figures", None)
        return cls(figures=tuple(figures), **t)


@dataclass(frozen=True)
class TolerancesTable(Table):
    """``[tolerances]``: the geometry checker's tolerances (see
    :class:`dextar.kinematics.checker.Tolerances`)."""

    NAME: ClassVar[str] = "tolerances"
    PARAMS: ClassVar[dict[str, Param]] = {
        "type1": Param("number", "", Tolerances.type1, "smallest normalised distance to a "
                       "serial singularity", minimum=0.0, maximum=1.0),
        "type2": Param("number", "", Tolerances.type2, "smallest normalised distance to a "
                       "parallel singularity", minimum=0.0, maximum=1.0),
    }

    type1: float = Tolerances.type1
    type2: float = Tolerances.type2

    def tolerances(self) -> Tolerances:
        """The checker's :class:`Tolerances`."""
        return Tolerances(type1=self.type1, type2=self.type2)


@dataclass(frozen=True)
class MotorsTable(Table):
    """``[motors]``: the motors at the joints (motor at A first; a number means both):
    peak torque, continuous (RMS) rating, maximum speed and the knee of the torque-speed
    envelope (full torque up to the knee, then linear to zero at the maximum speed), and the
    limits a drive sets on the motion: joint acceleration, joint jerk and torque rate (a jerk
    or torque-rate limit makes the time-optimal law third order)."""

    NAME: ClassVar[str] = "motors"
    PARAMS: ClassVar[dict[str, Param]] = {
        "peak_torque": _pair("N m", "peak torques (required when the table is given)", None,
                             positive=True),
        "rms_torque": _pair("N m", "continuous (RMS) torque ratings", None, positive=True),
        "max_speed_rpm": _pair("", "maximum speeds, rpm", None, positive=True),
        "knee_speed_rpm": _pair("", "end of full torque, rpm (< max_speed_rpm)", None,
                                positive=True),
        "max_acceleration": _pair("", "joint accelerations, rad/s^2", None, positive=True),
        "max_jerk": _pair("", "joint jerks, rad/s^3", None, positive=True),
        "max_torque_rate": _pair("", "rates of change of the torques, N m/s", None,
                                 positive=True),
    }

    peak_torque: tuple[float, float] | None = None
    rms_torque: tuple[float, float] | None = None
    max_speed_rpm: tuple[float, float] | None = None
    knee_speed_rpm: tuple[float, float] | None = None
    max_acceleration: tuple[float, float] | None = None
    max_jerk: tuple[float, float] | None = None
    max_torque_rate: tuple[float, float] | None = None

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> MotorsTable:
        """Read ``[motors]``: ``peak_torque`` is required when the table is given; a knee
        needs a maximum speed above it."""
        t = cls(**read_params(cls.NAME, raw, cls.PARAMS))
        if raw and t.peak_torque is None:
            given = [k for k in ("max_jerk", "max_torque_rate", "max_acceleration") if k in raw]
            if given:
                raise ConfigError(f"config key [motors].{given[0]} needs peak_torque: a "
                                  "time-optimal law plans within the torques too (config key "
                                  "[motors].peak_torque is required)")
            raise ConfigError("config key [motors].peak_torque is required")
        if t.knee_speed_rpm is not None:
            if t.max_speed_rpm is None:
                raise ConfigError("config key [motors].knee_speed_rpm needs max_speed_rpm")
            if any(k >= w for k, w in zip(t.knee_speed_rpm, t.max_speed_rpm, strict=True)):
                raise ConfigError(f"config key [motors].knee_speed_rpm {list(t.knee_speed_rpm)} "
                                  f"must be below max_speed_rpm {list(t.max_speed_rpm)}")
        return t

    def limits(self, units: Units) -> MotorLimits | None:
        """The motors' limits in run units (None without a ``[motors]`` table)."""
        if self.peak_torque is None:
            return None
        rad = 2 * math.pi / 60 * units.time_s

        def pair(v: tuple[float, float] | None, scale: float) -> tuple[float, float]:
            return (math.inf, math.inf) if v is None else (v[0] * scale, v[1] * scale)

        def opt(v: tuple[float, float] | None, scale: float) -> tuple[float, float] | None:
            return None if v is None else (v[0] * scale, v[1] * scale)

        ts = units.time_s
        return MotorLimits((units.torque(self.peak_torque[0]), units.torque(self.peak_torque[1])),
                           pair(self.max_speed_rpm, rad), opt(self.knee_speed_rpm, rad),
                           opt(self.max_acceleration, ts**2), opt(self.max_jerk, ts**3),
                           opt(self.max_torque_rate, units.torque(1.0) * ts))


@dataclass(frozen=True)
class DriveTable(Table):
    """``[drive]`` (optional): the drives behind the joints (motor at A first; a number means
    both): the gearbox, the encoders, the rated torque (for the torque feedforward in
    per-mille, CiA 402) and the period of the PVT points. With it ``dextar program`` also
    writes ``csp.csv`` and ``pvt.csv``, whose counts start at the encoders' zero: the joint
    angle ``[robot].encoder_offset_deg`` (which ``dextar calibrate`` identifies; one key for
    one angle)."""

    NAME: ClassVar[str] = "drive"
    PARAMS: ClassVar[dict[str, Param]] = {
        "gear_ratio": _pair("", "motor turns per joint turn", 1.0, positive=True),
        "encoder_counts": _pair("", "counts per motor turn", 4096.0, positive=True),
        "rated_torque_Nm": _pair("", "motor-side rated torque, N m (0x6076)", None,
                                 positive=True),
        "pvt_period_ms": Param("number", "", 10.0, "period of the PVT points, ms (a whole "
                               "number of servo ticks)", positive=True, maximum=1000.0),
        "max_torque_permille": _pair("", "largest torque the drive gives, per-mille of the "
                                     "rated torque (0x6072); a torque feedforward beyond it "
                                     "does not fit (exit 1)", None, positive=True),
    }

    gear_ratio: tuple[float, float] = (1.0, 1.0)
    encoder_counts: tuple[float, float] = (4096.0, 4096.0)
    rated_torque_Nm: tuple[float, float] | None = None
    pvt_period_ms: float = 10.0
    given: bool = False
    max_torque_permille: tuple[float, float] | None = None

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> DriveTable:
        """Read ``[drive]``; encoder counts are whole numbers."""
        if "encoder_offset_deg" in raw:
            raise ConfigError("config key [drive].encoder_offset_deg is not known: the "
                              "encoders' offsets are [robot].encoder_offset_deg (the joint "
                              "angle at each encoder's zero, as dextar calibrate writes it)")
        t = cls(**read_params(cls.NAME, raw, cls.PARAMS), given=bool(raw))
        if any(c != int(c) for c in t.encoder_counts):
            raise ConfigError(f"config key [drive].encoder_counts {list(t.encoder_counts)} "
                              "must be whole numbers")
        if t.max_torque_permille is not None and t.rated_torque_Nm is None:
            raise ConfigError("config key [drive].max_torque_permille needs "
                              "[drive].rated_torque_Nm (the torque it is a per-mille of)")
        return t


