"""Inertial parameters of the five-bar, in the run's units.

Four rods (proximal AB and DC, distal BP and CP), each with a mass, a centre of mass (distance
along the rod from its proximal joint) and an inertia about the centre of mass; the
end-effector mass and a payload at P; rotor inertia of each motor as seen at the joint; viscous
and Coulomb friction at the motors; an in-plane gravity vector.

Counterweights. A :class:`Counterweight` is a mass on the extension of a rod behind its
proximal joint (on a proximal rod: behind the motor axis), at ``distance`` from the joint,
with an optional inertia about its own centre. It is rigidly fixed to its rod, so rod and
counterweight are one rigid body, and a planar rigid body's dynamics depend on its mass, its
centre of mass and its inertia about that centre only: :meth:`Rod.with_counterweight` folds
the counterweight into those three numbers (mass ``m + m_c``, centre ``(m c - m_c r) / (m +
m_c)``, possibly behind the joint, inertia by the parallel-axis theorem). The folding is exact
(no approximation), so every model that takes a rod (the exact dynamics' kernels, the
regressor, the MuJoCo export, the paper's model) takes a counterweighted rod unchanged.
:attr:`Inertia.proximal` holds the folded rods (what the dynamics see);
:attr:`Inertia.counterweights` records the proximal counterweights folded into them (for the
config files and the MuJoCo export, which show them apart); :meth:`Inertia.with_counterweights`
sets them.
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
class Counterweight:
    """A counterweight on the extension of a rod behind its proximal joint: ``mass``, its
    centre at ``distance`` behind the joint on the rod's axis (>= 0), ``inertia`` about its
    own centre (perpendicular to the plane; 0 for a point mass)."""

    mass: float = 0.0
    distance: float = 0.0
    inertia: float = 0.0

    def check(self, name: str) -> None:
        """Raise :class:`ParameterError`, naming the counterweight, for an invalid value."""
        m = _check(f"{name} mass", self.mass)
        _check(f"{name} distance", self.distance)
        i = _check(f"{name} inertia", self.inertia)
        if m == 0 and i > 0:
            raise ParameterError(f"{name}: a massless counterweight cannot have inertia {i:g}")

    @property
    def none(self) -> bool:
        """True for no counterweight (no mass)."""
        return self.mass == 0.0

    @property
    def first_moment(self) -> float:
        """``m_c r``: what it takes off the rod's first moment about the joint."""
        return self.mass * self.distance

    @property
    def about_joint(self) -> float:
        """Its inertia about the joint, ``I_c + m_c r^2``."""
        return self.inertia + self.mass * self.distance**2

    def scaled(self, factor: float) -> Counterweight:
        """Mass and inertia times ``factor`` (the distance kept)."""
        return Counterweight(self.mass * factor, self.distance, self.inertia * factor)


#: No counterweight.
NO_COUNTERWEIGHT = Counterweight()


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

    @property
    def first_moment(self) -> float:
        """``m c``, about the proximal joint along the rod."""
        return self.mass * self.com

    def with_counterweight(self, cw: Counterweight) -> Rod:
        """The rigid body of this rod and the counterweight ``cw`` (behind the proximal
        joint), exactly: mass ``m + m_c``, centre of mass ``(m c - m_c r) / (m + m_c)``,
        inertia about it by the parallel-axis theorem (``I + I_c + m (c - c')^2 + m_c (r +
        c')^2``, a sum of non-negative terms)."""
        if cw.none:
            return self
        m = self.mass + cw.mass
        c = (self.mass * self.com - cw.mass * cw.distance) / m
        inertia = (self.inertia + cw.inertia + self.mass * (self.com - c) ** 2
                   + cw.mass * (cw.distance + c) ** 2)
        return Rod(m, c, inertia)

    def without_counterweight(self, cw: Counterweight) -> Rod:
        """The rod that :meth:`with_counterweight` of ``cw`` turns into this one (the inverse
        folding; to rounding).

        Raises
        ------
        ParameterError
            This rod is lighter than the counterweight, or has less inertia about its joint
            than it: ``cw`` is not part of it.
        """
        if cw.none:
            return self
        m = self.mass - cw.mass
        J = self.about_joint - cw.about_joint
        scale = max(self.about_joint, cw.about_joint, 1e-300)
        if m < -1e-12 * self.mass or J < -1e-9 * scale:
            raise ParameterError(f"a rod of mass {self.mass:g} and inertia {self.about_joint:g} "
                                 f"about its joint does not hold a counterweight of mass "
                                 f"{cw.mass:g} and inertia {cw.about_joint:g} about it")
        if m <= 1e-12 * self.mass:
            return Rod(0.0, 0.0, 0.0)
        h = self.first_moment + cw.first_moment
        c = h / m
        return Rod(m, c, max(J - m * c * c, 0.0))


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
    counterweights : (Counterweight, Counterweight)
        The counterweights of the proximal rods AB and DC, already folded into
        :attr:`proximal` (a record: the dynamics use :attr:`proximal` only). Set them with
        :meth:`with_counterweights`, which folds them; :attr:`bare_proximal` gives the rods
        without them.
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
    counterweights: tuple[Counterweight, Counterweight] = (NO_COUNTERWEIGHT, NO_COUNTERWEIGHT)

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
        if len(self.counterweights) != 2:
            raise ParameterError("counterweights must be a pair (rod AB, rod DC)")
        for cw, n in zip(self.counterweights, ("AB", "DC"), strict=True):
            cw.check(f"counterweight of rod {n}")

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

    @property
    def has_counterweights(self) -> bool:
        """True when a proximal rod carries a counterweight."""
        return not all(cw.none for cw in self.counterweights)

    @property
    def bare_proximal(self) -> tuple[Rod, Rod]:
        """The proximal rods without their counterweights (:attr:`proximal` unfolded).

        Raises
        ------
        ParameterError
            A rod does not hold its recorded counterweight (the rods were replaced by lighter
            ones after the counterweights were set).
        """
        p, c = self.proximal, self.counterweights
        return p[0].without_counterweight(c[0]), p[1].without_counterweight(c[1])

    def with_counterweights(self, counterweights: tuple[Counterweight, Counterweight]
                            ) -> Inertia:
        """A copy whose proximal rods carry ``counterweights`` (rod AB, rod DC) instead of
        the ones they carry now: the bare rods with the new counterweights folded in
        (:meth:`Rod.with_counterweight`), the record updated."""
        if len(counterweights) != 2:
            raise ParameterError("counterweights must be a pair (rod AB, rod DC)")
        for cw, n in zip(counterweights, ("AB", "DC"), strict=True):
            cw.check(f"counterweight of rod {n}")
        b1, b2 = self.bare_proximal
        return replace(self, proximal=(b1.with_counterweight(counterweights[0]),
                                       b2.with_counterweight(counterweights[1])),
                       counterweights=(counterweights[0], counterweights[1]))

    def frictionless(self) -> Inertia:
        """The same inertia without gravity or friction (the inertial part of the dynamics)."""
        return replace(self, gravity=(0.0, 0.0), viscous=(0.0, 0.0), coulomb=(0.0, 0.0))

    def friction_torques(self, dq: object) -> Array:
        """Friction torques of both motors at joint rates ``dq`` (..., 2), same shape."""
        dq = np.asarray(dq, dtype=float)
        return np.stack([friction_torque(dq[..., k], self.viscous[k], self.coulomb[k],
                                         self.coulomb_speed) for k in range(2)], axis=-1)

    def scaled_masses(self, factor: float) -> Inertia:
        """Every mass and inertia (rods, counterweights, effector, payload, rotors) times
        ``factor``."""
        def rod(r: Rod) -> Rod:
            return Rod(r.mass * factor, r.com, r.inertia * factor)
        p1, p2 = self.proximal
        d1, d2 = self.distal
        c1, c2 = self.counterweights
        return replace(self, proximal=(rod(p1), rod(p2)), distal=(rod(d1), rod(d2)),
                       effector_mass=self.effector_mass * factor, payload=self.payload * factor,
                       rotor=(self.rotor[0] * factor, self.rotor[1] * factor),
                       counterweights=(c1.scaled(factor), c2.scaled(factor)))


def paper_inertia(robot: FiveBar, *, effector_mass: float = 1.0, distal_ratio: float = 0.1,
                  proximal_ratio: float = 0.08) -> Inertia:
    """The paper's Fig. 9 masses: distal rods ``0.1 m``, proximal rods ``0.08 m``, uniform rods,
    no rotor inertia, no friction, no gravity."""
    return Inertia.uniform(robot, proximal_mass=proximal_ratio * effector_mass,
                           distal_mass=distal_ratio * effector_mass, effector_mass=effector_mass)
