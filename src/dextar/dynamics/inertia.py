"""Inertial parameters of the five-bar, in the run's units.

Four rods (proximal AB and DC, distal BP and CP), each with a mass, a centre of mass (distance
along the rod from its proximal joint) and an inertia about the centre of mass; the
end-effector mass and a payload at P; rotor inertia of each motor as seen at the joint; viscous
and Coulomb friction at the motors; an in-plane gravity vector.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .._arrays import Array
from ..errors import ParameterError
from ..geometry import FiveBar
from .friction import friction_torque


def _check(name: str, value: object, *, positive: bool = False) -> float:
    """Check a non-negative (or positive) finite number; returns it as a float."""
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        raise ParameterError(f"{name} = {value!r} is not a number")
    value = float(value)
    if not math.isfinite(value):
        raise ParameterError(f"{name} = {value!r} must be finite")
    if value < 0 or (positive and value == 0):
        raise ParameterError(f"{name} = {value!r} must be {'positive' if positive else '>= 0'}")
    return value


@dataclass(frozen=True)
class Rod:
    """A rod: ``mass``, centre of mass at ``com`` from its proximal joint, ``inertia`` about
    the centre of mass (perpendicular to the plane)."""

    mass: float
    com: float
    inertia: float

    def check(self, name: str) -> None:
        """Raise :class:`ParameterError`, naming the rod, for an invalid value."""
        m = _check(f"{name} mass", self.mass)
        if not (isinstance(self.com, numbers.Real) and math.isfinite(self.com)):
            raise ParameterError(f"{name} centre of mass {self.com!r} must be finite")
        i = _check(f"{name} inertia", self.inertia)
        if m == 0 and (i > 0):
            raise ParameterError(f"{name}: a massless rod cannot have inertia {i:g}")

    @staticmethod
    def uniform(mass: float, length: float) -> Rod:
        """A uniform slender rod: centre at mid-length, inertia ``m L^2 / 12``."""
        return Rod(mass, 0.5 * length, mass * length * length / 12.0)

    @property
    def about_joint(self) -> float:
        """Inertia about the proximal joint, ``I + m c^2``."""
        return self.inertia + self.mass * self.com**2


@dataclass(frozen=True)
class Inertia:
    """All the inertial, friction and gravity parameters of a five-bar.

    Attributes
    ----------
    proximal : (Rod, Rod)
        Rods AB (leg 1) and DC (leg 2).
    distal : (Rod, Rod)
        Rods BP and CP; ``com`` measured from B and C.
    effector_mass, payload : float
        Point masses at P.
    rotor : (float, float)
        Rotor inertia of the motors at A and D (as seen at the joint).
    viscous, coulomb : (float, float)
        Motor friction, ``tau_f = viscous * qdot + coulomb * tanh(qdot / coulomb_speed)``
        (see :mod:`dextar.dynamics.friction`).
    coulomb_speed : float
        Regularisation speed of the Coulomb friction (rad per time unit, > 0).
    gravity : (float, float)
        In-plane gravity vector (zero when the robot lies horizontally).
    """

    proximal: tuple[Rod, Rod]
    distal: tuple[Rod, Rod]
    effector_mass: float = 1.0
    payload: float = 0.0
    rotor: tuple[float, float] = (0.0, 0.0)
    viscous: tuple[float, float] = (0.0, 0.0)
    coulomb: tuple[float, float] = (0.0, 0.0)
    gravity: tuple[float, float] = field(default=(0.0, 0.0))
    coulomb_speed: float = 1e-3

    def __post_init__(self) -> None:
        names = (("proximal rod AB", "proximal rod DC"), ("distal rod BP", "distal rod CP"))
        for attr, labels in zip(("proximal", "distal"), names, strict=True):
            rods = getattr(self, attr)
            if len(rods) != 2:
                raise ParameterError(f"{attr} must hold two rods")
            for r, n in zip(rods, labels, strict=True):
                r.check(n)
        _check("effector mass", self.effector_mass)
        _check("payload", self.payload)
        for attr in ("rotor", "viscous", "coulomb"):
            pair = getattr(self, attr)
            if len(pair) != 2:
                raise ParameterError(f"{attr} must be a pair (motor A, motor D)")
            for k, v in enumerate(pair):
                _check(f"{attr} {k + 1}", v)
        g = self.gravity
        if len(g) != 2 or not all(isinstance(v, numbers.Real) and math.isfinite(v) for v in g):
            raise ParameterError(f"gravity {self.gravity!r} must be a finite 2-vector")
        _check("Coulomb regularisation speed", self.coulomb_speed, positive=True)

    @property
    def point_mass(self) -> float:
        """Mass at P: end-effector plus payload."""
        return self.effector_mass + self.payload

    @property
    def has_friction(self) -> bool:
        """True when a motor has viscous or Coulomb friction."""
        return any(self.viscous) or any(self.coulomb)

    @classmethod
    def uniform(cls, robot: FiveBar, *, proximal_mass: float, distal_mass: float,
                effector_mass: float = 1.0, **kwargs: Any) -> Inertia:
        """Uniform rods of the given masses (the same on both legs)."""
        return cls(
            proximal=(Rod.uniform(proximal_mass, robot.l1), Rod.uniform(proximal_mass, robot.l2)),
            distal=(Rod.uniform(distal_mass, robot.L1), Rod.uniform(distal_mass, robot.L2)),
            effector_mass=effector_mass, **kwargs)

    def with_(self, **changes: Any) -> Inertia:
        """A copy with some fields changed."""
        return replace(self, **changes)

    def frictionless(self) -> Inertia:
        """The same inertia without gravity or friction (the inertial part of the dynamics)."""
        return replace(self, gravity=(0.0, 0.0), viscous=(0.0, 0.0), coulomb=(0.0, 0.0))

    def friction_torques(self, dq: object) -> Array:
        """Friction torques of both motors at joint rates ``dq`` (..., 2), same shape."""
        dq = np.asarray(dq, dtype=float)
        return np.stack([friction_torque(dq[..., k], self.viscous[k], self.coulomb[k],
                                         self.coulomb_speed) for k in range(2)], axis=-1)

    def scaled_masses(self, factor: float) -> Inertia:
        """Every mass and inertia (rods, effector, payload, rotors) times ``factor``."""
        def rod(r: Rod) -> Rod:
            return Rod(r.mass * factor, r.com, r.inertia * factor)
        p1, p2 = self.proximal
        d1, d2 = self.distal
        return replace(self, proximal=(rod(p1), rod(p2)), distal=(rod(d1), rod(d2)),
                       effector_mass=self.effector_mass * factor, payload=self.payload * factor,
                       rotor=(self.rotor[0] * factor, self.rotor[1] * factor))


def paper_inertia(robot: FiveBar, *, effector_mass: float = 1.0, distal_ratio: float = 0.1,
                  proximal_ratio: float = 0.08) -> Inertia:
    """The paper's Fig. 9 masses: distal rods ``0.1 m``, proximal rods ``0.08 m``, uniform rods,
    no rotor inertia, no friction, no gravity."""
    return Inertia.uniform(robot, proximal_mass=proximal_ratio * effector_mass,
                           distal_mass=distal_ratio * effector_mass, effector_mass=effector_mass)
