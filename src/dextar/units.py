"""The unit systems of a run and the conversions from config units (mm, deg, kg, s, N m).

The maths is unit-agnostic; a run computes in one of two systems:

* ``"paper"``: the paper's dimensionless units, length ``L`` (the distal rod ``L1``), mass
  ``m`` (the end-effector mass), time ``T`` (the motion's duration); energies and torques in
  ``m L^2 / T^2``.
* ``"si"``: metres, kilograms, seconds; torques in N m.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ._arrays import Array


@dataclass(frozen=True)
class Units:
    """The run's unit system: how many mm, kg and s one run unit is."""

    system: str
    length_mm: float
    mass_kg: float
    time_s: float

    @property
    def names(self) -> dict[str, str]:
        """Unit names of the run (length, mass, time, energy, torque, angle)."""
        if self.system == "si":
            return {"length": "m", "mass": "kg", "time": "s", "energy": "J", "torque": "N m",
                    "angle": "rad"}
        return {"length": "L", "mass": "m", "time": "T", "energy": "m L^2/T^2",
                "torque": "m L^2/T^2", "angle": "rad"}

    def describe(self) -> dict[str, Any]:
        """The unit system as JSON-ready fields."""
        return {"system": self.system, **{f"{k}_unit": v for k, v in self.names.items()},
                "length_unit_in_mm": self.length_mm, "mass_unit_in_kg": self.mass_kg,
                "time_unit_in_s": self.time_s}

    # conversions from config units to run units
    def length(self, mm: float) -> float:
        """Millimetres to run length units."""
        return mm / self.length_mm

    def mass(self, kg: float) -> float:
        """Kilograms to run mass units."""
        return kg / self.mass_kg

    def time(self, s: float) -> float:
        """Seconds to run time units."""
        return s / self.time_s

    def inertia(self, kg_mm2: float) -> float:
        """Kg mm^2 to run inertia units."""
        return kg_mm2 / (self.mass_kg * self.length_mm**2)

    def torque(self, n_m: float) -> float:
        """N m to run torque units."""
        return n_m * 1e6 / (self.mass_kg * self.length_mm**2 / self.time_s**2)

    def acceleration(self, mm_s2: float) -> float:
        """mm/s^2 to run acceleration units."""
        return mm_s2 / (self.length_mm / self.time_s**2)

    def speed(self, mm_s: float) -> float:
        """mm/s to run speed units."""
        return mm_s / (self.length_mm / self.time_s)

    def torque_in_nm(self, run: Array | float) -> Array | float:
        """Run torque units to N m."""
        return run * (self.mass_kg * self.length_mm**2 / self.time_s**2) / 1e6

    # ------------------------------------------------------------------ words for messages
    def mm(self, run_length: float) -> float:
        """A run length in mm."""
        return float(run_length) * self.length_mm

    def point_text(self, P: Any) -> str:
        """A point in run units as ``"(x, y) mm"``."""
        return f"({self.mm(P[0]):.6g}, {self.mm(P[1]):.6g}) mm"

    def time_text(self, t: float) -> str:
        """A run time as ``"t = 0.25 s"``."""
        return f"t = {float(t) * self.time_s:.6g} s"

    def torque_text(self, run_torque: float) -> str:
        """A run torque as ``"0.5 N m"``."""
        return f"{float(self.torque_in_nm(run_torque)):.4g} N m"


#: Units in which run values are already SI (m, kg, s): messages then convert m to mm.
SI = Units("si", 1000.0, 1.0, 1.0)


