"""A run's scenario from a TOML config: robot, path, law, inertia, control and output, in the
run's units.

Config files speak millimetres, degrees, kilograms and seconds (torques in N m, inertias in
kg mm^2, gravity in mm/s^2). The run itself computes in one of two unit systems:

* ``"paper"`` (default): the paper's dimensionless units, length ``L`` (the distal rod
  ``L1``), mass ``m`` (the end-effector mass), time ``T`` (the motion's duration); energies and
  torques in ``m L^2 / T^2``.
* ``"si"``: metres, kilograms, seconds; torques in N m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from .config import (
    NUMBER,
    TABLES,
    ConfigError,
    check_tables,
    load_toml,
    robot_from_table,
    take,
)
from .dynamics import Inertia, Model, Rod
from .dynamics.friction import DEFAULT_COULOMB_SPEED_DEG_S
from .errors import DextarError
from .geometry import FiveBar
from .laws import Law, MinimumJerkLaw, TrapezoidalLaw, UniformLaw, solve_optimal_law
from .paths import Arc, ExpressionPath, Line, Path, Spline
from .trajectory import Trajectory, check_path, sample_trajectory
from .units import Units

FIGURES = ("fig3", "fig4", "fig5", "fig6", "fig7", "fig8", "fig9", "workspace", "animation")
PAIR = (int, float, list)
#: Most samples a run writes (a 200 s motion at 1 kHz).
MAX_SAMPLES = 200_000
#: Finest time-optimal grid.
MAX_GRID = 100_000


@dataclass(frozen=True)
class Scenario:
    """Everything a run needs, in run units (see :class:`Units`)."""

    units: Units
    robot_mm: FiveBar
    robot: FiveBar
    mode: str
    assembly: str
    path: Path
    path_spec: dict[str, Any]
    law_spec: dict[str, Any]
    inertia: Inertia
    control: dict[str, Any]
    paper: dict[str, Any]
    output: dict[str, Any]
    source: str = "defaults (the paper's example)"

    @property
    def effector_mass(self) -> float:
        return self.inertia.point_mass

    def law(self, kind: str | None = None) -> Law:
        """The configured law (or another ``kind`` with the same duration)."""
        spec = self.law_spec
        kind = kind or spec["type"]
        check_path(self.robot, self.path, mode=self.mode, units=self.units)
        S, T = self.path.length, spec["duration"]
        if kind == "uniform":
            return UniformLaw(S, T)
        if kind == "min-jerk":
            return MinimumJerkLaw(S, T)
        if kind == "time-optimal":
            from .time_optimal import solve_time_optimal_law

            return solve_time_optimal_law(self.model(), self.path,
                                          torque_limit=spec["torque_limit"],
                                          speed_limit=spec.get("speed_limit"), mode=self.mode,
                                          grid=spec["grid"], units=self.units)
        if kind == "trapezoid":
            if "vmax" not in spec or "amax" not in spec:
                raise ConfigError("config keys [law].vmax and [law].amax are required for a "
                                  "trapezoid law")
            return TrapezoidalLaw(S, spec["vmax"], spec["amax"], spec.get("fixed_duration"))
        return solve_optimal_law(self.path, duration=T, eta=spec["eta"],
                                 mass=self.effector_mass)

    def trajectory(self, law: Law | None = None, samples: int | None = None) -> Trajectory:
        return sample_trajectory(self.robot, self.path, law or self.law(), mode=self.mode,
                                 samples=samples or self.output["samples"], units=self.units)

    def model(self, assembly: str | None = None) -> Model:
        return Model(self.robot, self.inertia, assembly or self.assembly)


def _pair(table: dict[str, Any], name: str, key: str, default: float) -> tuple[float, float]:
    v = table.get(key, default)
    if isinstance(v, list):
        if len(v) != 2 or not all(isinstance(x, NUMBER) and not isinstance(x, bool) for x in v):
            raise ConfigError(f"config key [{name}].{key} must be a number or a pair of numbers")
        return float(v[0]), float(v[1])
    return float(v), float(v)


def _point(table: dict[str, Any], name: str, key: str) -> tuple[float, float]:
    v = table.get(key)
    if not (isinstance(v, list) and len(v) == 2
            and all(isinstance(x, NUMBER) and not isinstance(x, bool) for x in v)):
        raise ConfigError(f"config key [{name}].{key} must be a point [x, y] in mm")
    return float(v[0]), float(v[1])


def load_scenario(path: str | None = None) -> Scenario:
    """Read a config file (or none: the paper's example) into a :class:`Scenario`."""
    doc = {} if path is None else load_toml(path)
    try:
        sc = scenario_from_dict(doc)
    except ConfigError:
        raise
    except DextarError as exc:
        raise ConfigError(f"config {path or '(defaults)'}: {exc}") from None
    return sc if path is None else replace(sc, source=str(path))


def scenario_from_dict(doc: dict[str, Any]) -> Scenario:
    """Build a :class:`Scenario` from a parsed config (tables as in ``examples/paper.toml``)."""
    check_tables(doc, TABLES)
    rc = robot_from_table(doc.get("robot"))
    out = take(doc.get("output", {}), "output",
               {"units": str, "samples": int, "figures": list, "animation_frames": int})
    system = out.get("units", "paper")
    if system not in ("paper", "si"):
        raise ConfigError(f"config key [output].units must be 'paper' or 'si', got {system!r}")
    figures = out.get("figures", list(FIGURES))
    for f in figures:
        if f not in FIGURES:
            raise ConfigError(f"config key [output].figures: unknown figure {f!r}; known: "
                              f"{', '.join(FIGURES)}")
    law_t = take(doc.get("law", {}), "law", {
        "type": str, "duration": NUMBER, "eta": NUMBER, "vmax": NUMBER,
        "amax": NUMBER, "torque_limit": PAIR, "speed_limit_deg_s": PAIR, "grid": int})
    inert_t = take(doc.get("inertia", {}), "inertia", {
        "effector_mass": NUMBER, "payload": NUMBER, "proximal_mass": PAIR, "distal_mass": PAIR,
        "proximal_com": PAIR, "distal_com": PAIR, "proximal_inertia": PAIR,
        "distal_inertia": PAIR, "rotor_inertia": PAIR})
    duration_s = float(law_t.get("duration", 1.0))
    effector_kg = float(inert_t.get("effector_mass", 1.0))
    if not duration_s > 0:
        raise ConfigError(f"config key [law].duration must be positive, got {duration_s}")
    if not effector_kg > 0:
        raise ConfigError(f"config key [inertia].effector_mass must be positive, got "
                          f"{effector_kg}")
    g_mm = rc.geometry_mm
    units = (Units("si", 1000.0, 1.0, 1.0) if system == "si"
             else Units("paper", g_mm.L1, effector_kg, duration_s))
    robot = g_mm.scaled(1.0 / units.length_mm)
    path, path_spec = _path(doc.get("path", {}), units)
    samples = int(out.get("samples", 1001))
    if not 2 <= samples <= MAX_SAMPLES:
        raise ConfigError(f"config key [output].samples must be between 2 and {MAX_SAMPLES}, "
                          f"got {samples}")
    law_spec = _law(law_t, units)
    inertia = _inertia(inert_t, doc, units, g_mm, effector_kg)
    control = _control(doc.get("control", {}), units, effector_kg)
    paper = take(doc.get("paper", {}), "paper", {
        "beta0_time": NUMBER, "fig7_distal_mass_ratio": NUMBER, "fig7_lambda": NUMBER,
        "fig9_proximal_mass_ratio": NUMBER, "fig9_distal_mass_ratio": NUMBER})
    paper = {"beta0_time": 0.5, "fig7_distal_mass_ratio": 0.5, "fig7_lambda": 0.5, **paper}
    frames = int(out.get("animation_frames", 41))
    if not 2 <= frames <= 1000:
        raise ConfigError(f"config key [output].animation_frames must be between 2 and 1000, "
                          f"got {frames}")
    output = {"units": system, "samples": samples, "figures": list(figures),
              "animation_frames": frames}
    return Scenario(units, g_mm, robot, rc.working_mode, rc.assembly_mode, path, path_spec,
                    law_spec, inertia, control, paper, output)


def _path(t: dict[str, Any], units: Units) -> tuple[Path, dict[str, Any]]:
    kind = t.get("type", "arc")
    common = {"type": str}
    if kind == "arc":
        t = take(t, "path", {**common, "radius": NUMBER, "center": list, "start_deg": NUMBER,
                             "end_deg": NUMBER})
        center = _point(t, "path", "center") if "center" in t else (0.0, 0.0)
        radius = float(t.get("radius", 120.0))
        start, end = float(t.get("start_deg", 0.0)), float(t.get("end_deg", 180.0))
        path: Path = Arc(units.length(radius), math.radians(start), math.radians(end),
                         center=(units.length(center[0]), units.length(center[1])))
        spec = {"type": "arc", "radius_mm": radius, "center_mm": list(center),
                "start_deg": start, "end_deg": end}
    elif kind == "line":
        t = take(t, "path", {**common, "start": list, "end": list}, ("start", "end"))
        a, b = _point(t, "path", "start"), _point(t, "path", "end")
        path = Line(tuple(map(units.length, a)), tuple(map(units.length, b)))
        spec = {"type": "line", "start_mm": list(a), "end_mm": list(b)}
    elif kind == "spline":
        t = take(t, "path", {**common, "waypoints": list}, ("waypoints",))
        pts = [_point({"w": w}, "path", "w") for w in t["waypoints"]]
        path = Spline(tuple((units.length(x), units.length(y)) for x, y in pts))
        spec = {"type": "spline", "waypoints_mm": [list(p) for p in pts]}
    elif kind == "expression":
        t = take(t, "path", {**common, "x": str, "y": str, "p0": NUMBER, "p1": NUMBER},
                 ("x", "y"))
        path = ExpressionPath(t["x"], t["y"], float(t.get("p0", 0.0)), float(t.get("p1", 1.0)),
                              scale=1.0 / units.length_mm)
        spec = {"type": "expression", "x_mm": t["x"], "y_mm": t["y"],
                "p0": float(t.get("p0", 0.0)), "p1": float(t.get("p1", 1.0))}
    else:
        raise ConfigError(f"config key [path].type must be arc, line, spline or expression, "
                          f"got {kind!r}")
    return path, spec


def _law(t: dict[str, Any], units: Units) -> dict[str, Any]:
    kind = t.get("type", "optimal")
    if kind not in ("uniform", "min-jerk", "trapezoid", "optimal", "time-optimal"):
        raise ConfigError(f"config key [law].type must be uniform, min-jerk, trapezoid, "
                          f"optimal or time-optimal, got {kind!r}")
    eta_si = float(t.get("eta", 0.1))
    if not eta_si > 0:
        raise ConfigError(f"config key [law].eta must be positive, got {eta_si}")
    spec: dict[str, Any] = {
        "type": kind, "duration": units.time(float(t.get("duration", 1.0))),
        "duration_s": float(t.get("duration", 1.0)),
        "eta": eta_si * units.mass_kg / units.time_s**2, "eta_s2_per_kg": eta_si}
    for key, conv in (("vmax", units.speed), ("amax", units.acceleration)):
        if key in t:
            if not t[key] > 0:
                raise ConfigError(f"config key [law].{key} must be positive")
            spec[key] = conv(float(t[key]))
    if kind == "trapezoid" and "duration" in t:
        spec["fixed_duration"] = spec["duration"]
    if kind == "time-optimal":
        if "torque_limit" not in t:
            raise ConfigError("config key [law].torque_limit is required for a time-optimal law")
        limits = _pair(t, "law", "torque_limit", 0.0)
        if min(limits) <= 0:
            raise ConfigError("config key [law].torque_limit must be positive")
        spec["torque_limit"] = tuple(units.torque(v) for v in limits)
        spec["torque_limit_nm"] = list(limits)
        if "speed_limit_deg_s" in t:
            w = _pair(t, "law", "speed_limit_deg_s", 0.0)
            if min(w) <= 0:
                raise ConfigError("config key [law].speed_limit_deg_s must be positive")
            spec["speed_limit"] = tuple(math.radians(v) * units.time_s for v in w)
            spec["speed_limit_deg_s"] = list(w)
        spec["grid"] = int(t.get("grid", 400))
        if not 10 <= spec["grid"] <= MAX_GRID:
            raise ConfigError(f"config key [law].grid must be between 10 and {MAX_GRID}, got "
                              f"{spec['grid']}")
    return spec


def _inertia(t: dict[str, Any], doc: dict[str, Any], units: Units, g: FiveBar,
             effector_kg: float) -> Inertia:
    def rods(prefix: str, lengths: tuple[float, float], ratio: float) -> tuple[Rod, Rod]:
        masses = _pair(t, "inertia", f"{prefix}_mass", ratio * effector_kg)
        coms = _pair(t, "inertia", f"{prefix}_com", float("nan"))
        inert = _pair(t, "inertia", f"{prefix}_inertia", float("nan"))
        out = []
        for k in range(2):
            m, L = masses[k], lengths[k]
            c = coms[k] if not math.isnan(coms[k]) else 0.5 * L
            i = inert[k] if not math.isnan(inert[k]) else m * L * L / 12.0
            out.append(Rod(units.mass(m), units.length(c), units.inertia(i)))
        return out[0], out[1]

    fr = take(doc.get("friction", {}), "friction", {"viscous": PAIR, "coulomb": PAIR,
                                                    "coulomb_speed_deg_s": NUMBER})
    speed = float(fr.get("coulomb_speed_deg_s", DEFAULT_COULOMB_SPEED_DEG_S))
    if not speed > 0:
        raise ConfigError(f"config key [friction].coulomb_speed_deg_s must be positive, got "
                          f"{speed!r}")
    gr = take(doc.get("gravity", {}), "gravity", {"vector": list})
    gvec = _point(gr, "gravity", "vector") if "vector" in gr else (0.0, 0.0)
    rotor = _pair(t, "inertia", "rotor_inertia", 0.0)
    visc = _pair(fr, "friction", "viscous", 0.0)
    coul = _pair(fr, "friction", "coulomb", 0.0)
    try:
        return Inertia(
            proximal=rods("proximal", (g.l1, g.l2), 0.08),
            distal=rods("distal", (g.L1, g.L2), 0.1),
            effector_mass=units.mass(effector_kg),
            payload=units.mass(float(t.get("payload", 0.0))),
            rotor=tuple(units.inertia(v) for v in rotor),  # type: ignore[arg-type]
            viscous=tuple(units.torque(v) / units.time_s for v in visc),  # type: ignore[arg-type]
            coulomb=tuple(units.torque(v) for v in coul),  # type: ignore[arg-type]
            gravity=tuple(units.acceleration(v) for v in gvec),  # type: ignore[arg-type]
            coulomb_speed=math.radians(speed) * units.time_s)
    except DextarError as exc:
        raise ConfigError(f"config table [inertia]: {exc}") from None


def _control(t: dict[str, Any], units: Units, effector_kg: float) -> dict[str, Any]:
    t = take(t, "control", {"natural_frequency_hz": NUMBER, "damping": NUMBER,
                            "mass_error": NUMBER, "payload": NUMBER, "torque_limit": NUMBER,
                            "initial_error_deg": list})
    freq = float(t.get("natural_frequency_hz", 10.0))
    if not freq > 0:
        raise ConfigError("config key [control].natural_frequency_hz must be positive")
    init = _pair(t, "control", "initial_error_deg", 0.0)
    limit = t.get("torque_limit")
    return {
        "natural_frequency": 2 * math.pi * freq * units.time_s,
        "natural_frequency_hz": freq,
        "damping": float(t.get("damping", 1.0)),
        "mass_error": float(t.get("mass_error", 0.2)),
        "payload": units.mass(float(t.get("payload", 0.1 * effector_kg))),
        "payload_kg": float(t.get("payload", 0.1 * effector_kg)),
        "torque_limit": None if limit is None else units.torque(float(limit)),
        "torque_limit_nm": limit,
        "initial_error": tuple(math.radians(v) for v in init),
    }


def default_scenario() -> Scenario:
    return load_scenario(None)
