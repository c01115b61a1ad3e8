"""The design space of a sweep: ranges of the rod lengths and base distance, how they are
sampled, and what is minimised.

A design is a row ``(l1, l2, L1, L2, d)`` in mm. ``l`` (or ``L``) as one range gives both
legs the same length (a symmetric robot, one dimension); ``l1`` and ``l2`` as two ranges make
two dimensions. A length without a range keeps the task's value.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..errors import ConfigError

qmc = lazy_module("scipy.stats.qmc")

#: The columns of a design, in mm.
LENGTHS = ("l1", "l2", "L1", "L2", "d")
#: The metrics a design has (``-`` before one in ``objectives`` maximises it).
METRICS = ("cycle_time_s", "footprint_mm", "min_type1_distance", "min_type2_distance", "gci",
           "peak_torque_A_Nm", "peak_torque_D_Nm", "rms_torque_A_Nm", "rms_torque_D_Nm",
           "workspace_area_mm2")
SAMPLINGS = ("sobol", "grid", "random")
#: Most designs a sweep samples.
MAX_SAMPLES = 1_000_000


def check_objectives(objectives: Sequence[str]) -> None:
    """Raise :class:`ConfigError` for an empty list or an unknown metric name."""
    for obj in objectives:
        if obj.lstrip("-") not in METRICS:
            raise ConfigError(f"config key [design].objectives: unknown objective {obj!r}; "
                              f"known: {', '.join(METRICS)} (a leading - maximises)")
    if not objectives:
        raise ConfigError("config key [design].objectives is empty")


@dataclass(frozen=True)
class DesignSpace:
    """What a sweep varies and minimises.

    Attributes
    ----------
    dims : tuple of (name, lo, hi, columns)
        Each dimension: its config name, its range in mm and the design columns it sets.
    fixed : (float, float, float, float, float)
        The task's lengths (mm), for the columns no dimension sets.
    mass_per_length : (float, float), optional
        kg/m of the proximal and distal rods (uniform rods whose masses follow the lengths);
        None keeps the task's rods.
    samples : int
    sampling : str
    seed : int
    objectives : tuple of str
    """

    dims: tuple[tuple[str, float, float, tuple[int, ...]], ...]
    fixed: tuple[float, float, float, float, float]
    mass_per_length: tuple[float, float] | None
    samples: int
    sampling: str
    seed: int
    objectives: tuple[str, ...]

    def __post_init__(self) -> None:
        if not self.dims:
            raise ConfigError("config table [design] varies nothing: give a range for l, L, "
                              "l1, l2, L1, L2 or d")
        for name, lo, hi, _ in self.dims:
            if not (math.isfinite(lo) and math.isfinite(hi)):
                raise ConfigError(f"config key [design].{name} = [{lo}, {hi}] must be finite")
            if lo > hi:
                raise ConfigError(f"config key [design].{name} = [{lo:g}, {hi:g}] is inverted "
                                  "(the low end first)")
            if lo == hi:
                raise ConfigError(f"config key [design].{name} = [{lo:g}, {hi:g}] is empty: "
                                  "leave the key out to keep the task's value")
            if lo < 0 or (lo == 0 and name != "d"):
                raise ConfigError(f"config key [design].{name} = [{lo:g}, {hi:g}] must be "
                                  f"{'>= 0' if name == 'd' else 'positive'} mm")
        if not (isinstance(self.samples, int) and 1 <= self.samples <= MAX_SAMPLES):
            raise ConfigError(f"samples = {self.samples!r} ([design].samples or --samples) must "
                              f"be an integer from 1 to {MAX_SAMPLES}")
        if not (isinstance(self.seed, int) and 0 <= self.seed < 2**31):
            raise ConfigError(f"seed = {self.seed!r} ([design].seed or --seed) must be an "
                              "integer from 0 to 2^31 - 1")
        if self.sampling not in SAMPLINGS:
            raise ConfigError(f"config key [design].sampling = {self.sampling!r}: one of "
                              f"{', '.join(SAMPLINGS)}")
        check_objectives(self.objectives)

    def designs(self) -> Array:
        """The sampled designs, shape (n, 5) in mm (``n = samples``; for ``grid``, the
        smallest full grid with at least ``samples`` points, cut to ``samples``)."""
        return self.at(self.unit_sample())

    def unit_sample(self) -> Array:
        """The sample in the unit cube, shape (n, number of dimensions)."""
        k = len(self.dims)
        n = self.samples
        if self.sampling == "sobol":

            with warnings.catch_warnings():  # not a power of 2: balance is not needed here
                warnings.simplefilter("ignore", UserWarning)
                u: Array = qmc.Sobol(d=k, scramble=True, seed=self.seed).random(n)
        elif self.sampling == "random":
            u = np.random.default_rng(self.seed).random((n, k))
        else:
            m = max(2, math.ceil(n ** (1.0 / k) - 1e-9))
            axes = np.meshgrid(*([np.linspace(0.0, 1.0, m)] * k), indexing="ij")
            u = np.stack([a.ravel() for a in axes], -1)[:n]
        return u

    def at(self, u: Array) -> Array:
        """The designs (n, 5) in mm at the points ``u`` (n, number of dimensions) of the unit
        cube (each dimension's range scaled to [0, 1]): what a search proposes."""
        u = np.asarray(u, float)
        out = np.tile(np.asarray(self.fixed, float), (len(u), 1))
        for j, (_name, lo, hi, cols) in enumerate(self.dims):
            for c in cols:
                out[:, c] = lo + (hi - lo) * u[:, j]
        return out

    @property
    def varied_axes(self) -> list[tuple[int, str]]:
        """One ``(column of LENGTHS, label)`` per varied dimension: lengths tied to one range
        (``l``: both proximal rods) are one axis, ``"l1 = l2"``."""
        return sorted((cs[0], " = ".join(LENGTHS[c] for c in cs)) for *_, cs in self.dims)

    def objective_values(self, rows: list[dict[str, float]]) -> Array:
        """The objectives of ``rows`` to minimise, shape (n, n_objectives)."""
        F = np.empty((len(rows), len(self.objectives)))
        for j, obj in enumerate(self.objectives):
            sign = -1.0 if obj.startswith("-") else 1.0
            F[:, j] = [sign * float(r[obj.lstrip("-")]) for r in rows]
        return F
