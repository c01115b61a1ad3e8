"""The robot's own config tables, ``[robot]`` and ``[instrument]``, and what reads only them:
the kinematics commands (``ik``, ``fk``, ``workspace``) and the calibration (``poses``,
``calibrate``) read a config without its motion, laws or dynamics.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path as FilePath
from typing import Any, ClassVar

from ..calibration.data import check_readings_deg
from ..calibration.model import KinematicModel
from ..calibration.poses import checked_region
from ..errors import ConfigError, DextarError
from ..geometry import DEXTAR_MM, FiveBar, canonical_working_mode, parse_assembly_mode, preset
from ..params import Param, read_params
from .base import TABLES, Table
from .toml import check_tables, read_config

#: A robot whose longest length is below this (mm) looks written in metres: the DexTAR in
#: metres is 0.087 at most, the smallest five-bars built are tens of millimetres.
METRES_LIKE_MM = 1.0

#: Where a robot-only config of no file comes from.
KINEMATIC_DEFAULT_SOURCE = "defaults (the DexTAR)"


def config_notes(source: str | None, doc: Mapping[str, Any], geometry_mm: FiveBar,
                 defaults: str) -> tuple[str, ...]:
    """What the user may not have meant in a config, in words: every command that reads a
    config says them on stderr and beside its error (:class:`KinematicConfig` and
    :class:`~dextar.config.Scenario` alike). A config file with no table (``source``, None
    without a file) gives ``defaults`` (words: what the command then uses); a robot whose
    lengths are all below :data:`METRES_LIKE_MM` looks written in metres."""
    out = []
    if not doc and source is not None:
        out.append(f"{source} has no table: {defaults}")
    g = geometry_mm
    longest = max(g.l1, g.l2, g.L1, g.L2, g.d)
    if longest < METRES_LIKE_MM:
        shown = ", ".join(f"{k} = {getattr(g, k):g}" for k in ("l1", "l2", "L1", "L2", "d"))
        out.append(f"the robot's lengths ({shown}) are read in mm: its longest, "
                   f"{longest:g} mm, looks like metres ({longest:g} m = "
                   f"{longest * 1e3:g} mm); config lengths are in mm")
    return tuple(out)


@dataclass(frozen=True)
class RobotTable(Table):
    """``[robot]``: the geometry in mm (a preset, lengths overriding it) and the modes."""

    NAME: ClassVar[str] = "robot"
    PARAMS: ClassVar[dict[str, Param]] = {
        "preset": Param("text", "", None, "a named geometry: dextar"),
        **{k: Param("number", "mm", None, f"length {k}", positive=True)
           for k in ("l1", "l2", "L1", "L2", "d")},
        "working_mode": Param("text", "", "+-", "++, +-, -+ or -- (aliases pp, pm, mp, mm)"),
        "assembly_mode": Param("choice", "", "up", "up or down", choices=("up", "down")),
        "encoder_offset_deg": Param("pair", "deg", (0.0, 0.0), "encoder offsets [phi, psi]: "
                                    "geometric angle = reading + offset", minimum=-180.0,
                                    maximum=180.0),
        "encoder_counts": Param("number", "", None, "encoder counts per turn of a joint",
                                positive=True, maximum=1e12),
    }

    geometry_mm: FiveBar = DEXTAR_MM
    working_mode: str = "+-"
    assembly_mode: str = "up"
    #: ``(phi, psi)`` offsets in degrees: geometric angle = encoder reading + offset.
    encoder_offset_deg: tuple[float, float] = (0.0, 0.0)
    encoder_counts: float | None = None

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> RobotTable:
        """Read ``[robot]``: without a preset, all five lengths are required;
        ``encoder_offset_deg`` is a pair ``[phi, psi]`` (degrees)."""
        off = raw.get("encoder_offset_deg")
        if off is not None and not (isinstance(off, list) and len(off) == 2):
            raise ConfigError("config key [robot].encoder_offset_deg must be a pair [phi, psi] "
                              f"in degrees, got {type(off).__name__} {off!r}")
        t = read_params(cls.NAME, raw, cls.PARAMS)
        lengths: dict[str, float] = {k: t[k] for k in ("l1", "l2", "L1", "L2", "d") if k in t}
        try:
            if "preset" in t:
                merged: dict[str, float] = {**preset(t["preset"]).as_dict(), **lengths}
                geom = FiveBar(**merged)
            elif lengths:
                missing = [k for k in ("l1", "l2", "L1", "L2", "d") if k not in lengths]
                if missing:
                    raise ConfigError(f"config key [robot].{missing[0]} is required when no "
                                      "preset is given")
                geom = FiveBar(**lengths)
            else:
                geom = DEXTAR_MM
            mode = canonical_working_mode(t["working_mode"])
            parse_assembly_mode(t["assembly_mode"])
        except ConfigError:
            raise
        except DextarError as exc:
            raise ConfigError(f"config table [robot]: {exc}") from None
        return cls(geom, mode, t["assembly_mode"], t["encoder_offset_deg"],
                   t.get("encoder_counts"))

    def geometric_deg(self, readings_deg: tuple[float, float]) -> tuple[float, float]:
        """Geometric angles (deg) of encoder readings (deg): reading + offset; readings that
        are NaN, infinite or beyond degrees' range are refused by name
        (:func:`~dextar.calibration.data.check_readings_deg`)."""
        check_readings_deg(readings_deg)
        a, b = self.encoder_offset_deg
        return (readings_deg[0] + a, readings_deg[1] + b)


@dataclass(frozen=True)
class InstrumentTable(Table):
    """``[instrument]``: the measuring instrument (a laser tracker, a camera, a CMM) that
    sees the robot: the pose of the robot frame in the instrument's frame (a point ``P`` of
    the robot frame is measured at ``R(theta0) P + (x0, y0)``) and the instrument's noise.
    It converts measured points only; every command works in the robot frame. ``region``
    ``[xmin, xmax, ymin, ymax]`` (mm, robot frame) is where it can measure: ``dextar poses``
    chooses every pose inside."""

    NAME: ClassVar[str] = "instrument"
    PARAMS: ClassVar[dict[str, Param]] = {
        "x0_mm": Param("number", "mm", 0.0, "origin of the robot frame, instrument x",
                       minimum=-1e6, maximum=1e6),
        "y0_mm": Param("number", "mm", 0.0, "origin of the robot frame, instrument y",
                       minimum=-1e6, maximum=1e6),
        "theta0_deg": Param("number", "deg", 0.0, "angle of the robot frame's x axis in the "
                            "instrument's frame", minimum=-360.0, maximum=360.0),
        "sigma_mm": Param("number", "mm", None, "standard deviation of a measured point per "
                          "axis (rows without sigma_mm)", positive=True, maximum=1e3),
    }

    x0_mm: float = 0.0
    y0_mm: float = 0.0
    theta0_deg: float = 0.0
    sigma_mm: float | None = None
    region_mm: tuple[float, float, float, float] | None = None

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> InstrumentTable:
        """Read ``[instrument]``; ``region`` is four numbers ``[xmin, xmax, ymin, ymax]``
        (mm, robot frame), each minimum below its maximum."""
        unknown = [k for k in raw if k not in cls.PARAMS and k != "region"]
        if unknown:
            raise ConfigError(f"config key [instrument].{unknown[0]} is not known; known "
                              f"keys: {', '.join([*cls.PARAMS, 'region'])}")
        t = read_params(cls.NAME, raw, cls.PARAMS, ignore=("region",))
        region = None
        if "region" in raw:
            try:
                region = checked_region(raw["region"], "config key [instrument].region")
            except DextarError as exc:
                raise ConfigError(str(exc)) from None
            if max(abs(v) for v in region) > 1e6:
                raise ConfigError(f"config key [instrument].region {list(region)} must be "
                                  "within 1e6 mm")
        return cls(**t, region_mm=region)

    @property
    def frame(self) -> tuple[float, float, float]:
        """``(x0_mm, y0_mm, theta0_deg)``."""
        return (self.x0_mm, self.y0_mm, self.theta0_deg)

    def to_robot_mm(self, point_mm: tuple[float, float]) -> tuple[float, float]:
        """A point measured in the instrument's frame (mm) in the robot frame (mm)."""
        c, s = math.cos(math.radians(self.theta0_deg)), math.sin(math.radians(self.theta0_deg))
        x, y = point_mm[0] - self.x0_mm, point_mm[1] - self.y0_mm
        return (c * x + s * y, -s * x + c * y)

    def to_instrument_mm(self, point_mm: tuple[float, float]) -> tuple[float, float]:
        """A point of the robot frame (mm) in the instrument's frame (mm)."""
        c, s = math.cos(math.radians(self.theta0_deg)), math.sin(math.radians(self.theta0_deg))
        x, y = point_mm
        return (c * x - s * y + self.x0_mm, s * x + c * y + self.y0_mm)


@dataclass(frozen=True)
class KinematicConfig:
    """A config file's ``[robot]`` and ``[instrument]``, and its other tables as written
    (unread: a calibration writes them back as given).

    Attributes
    ----------
    robot : RobotTable
    instrument : InstrumentTable
        The file's, or the default (no frame, no noise) when it has none.
    has_instrument : bool
        The file has an ``[instrument]`` table.
    doc : mapping
        The whole file as parsed.
    source : str
        The file's path, or the defaults' name.
    """

    robot: RobotTable = field(default_factory=RobotTable)
    instrument: InstrumentTable = field(default_factory=InstrumentTable)
    has_instrument: bool = False
    doc: Mapping[str, Any] = field(default_factory=dict)
    source: str = KINEMATIC_DEFAULT_SOURCE

    @property
    def notes(self) -> tuple[str, ...]:
        """What the user may not have meant (:func:`config_notes`): a file with no table (the
        robot is then the DexTAR), a robot that looks written in metres."""
        g = DEXTAR_MM
        return config_notes(None if self.source == KINEMATIC_DEFAULT_SOURCE else self.source,
                            self.doc, self.robot.geometry_mm,
                            f"the robot is the DexTAR (l1 = l2 = {g.l1:g}, L1 = L2 = "
                            f"{g.L1:g}, d = {g.d:g} mm)")

    @property
    def model(self) -> KinematicModel:
        """The robot (SI), its encoder offsets and the instrument frame as a calibration
        model."""
        return kinematic_model(self.robot, self.instrument)

    def other_tables(self) -> dict[str, Any]:
        """The file's tables other than ``[robot]`` and ``[instrument]``, as written."""
        return {k: v for k, v in self.doc.items() if k not in ("robot", "instrument")}


def load_kinematic_config(path: str | FilePath | None) -> KinematicConfig:
    """``[robot]`` and ``[instrument]`` of a config file, read once, every table's name
    checked (the other tables are not read); the DexTAR without a file."""
    if path is None:
        return KinematicConfig()
    doc, _ = read_config(path)
    check_tables({k: v for k, v in doc.items() if k != "move"}, set(TABLES) | {"move"})
    inst = doc.get("instrument")
    return KinematicConfig(RobotTable.from_toml(doc.get("robot", {})),
                           InstrumentTable() if inst is None else InstrumentTable.from_toml(inst),
                           inst is not None, doc, str(path))


def load_robot_table(path: str | FilePath | None) -> RobotTable:
    """``[robot]`` of a config file (every table's name checked; the DexTAR without a
    file)."""
    return load_kinematic_config(path).robot


def load_kinematics(path: str | FilePath | None
                    ) -> tuple[RobotTable, InstrumentTable | None]:
    """``[robot]`` and ``[instrument]`` (None when the file has none) of a config file, the
    file read once, every table's name checked; the DexTAR without a file."""
    kc = load_kinematic_config(path)
    return kc.robot, kc.instrument if kc.has_instrument else None


def kinematic_model(robot: RobotTable, instrument: InstrumentTable | None = None
                    ) -> KinematicModel:
    """The calibration model (SI) of config tables: the geometry, the encoder offsets and
    the instrument frame."""
    return KinematicModel.from_config_units(
        robot.geometry_mm, encoder_offset_deg=robot.encoder_offset_deg,
        instrument=(instrument or InstrumentTable()).frame)
