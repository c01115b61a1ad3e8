"""The design space of a sweep: ranges of the rod lengths and base distance (and of the
counterweights, and the motor), how they are sampled, and what is minimised.

A design is a row of :attr:`DesignSpace.columns`: always the lengths ``(l1, l2, L1, L2, d)``
in mm; then, when ``[design]`` varies them, the proximal rods' counterweights
(:data:`COUNTERWEIGHTS`: masses in kg, distances behind the motor axes in mm); then, when the
motor is a design variable (``motor_choice = "search"``), the catalogue's motor and gear ratio
by their index (:data:`MOTOR_COLUMNS`, whole numbers). ``l`` (or ``L``) as one range gives
both legs the same length (a symmetric robot, one dimension); ``l1`` and ``l2`` as two ranges
make two dimensions; ``counterweight_mass`` and ``counterweight_distance`` likewise. A column
without a range keeps the task's value.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..errors import ConfigError

qmc = lazy_module("scipy.stats.qmc")

#: The columns of a design, in mm.
LENGTHS = ("l1", "l2", "L1", "L2", "d")
#: The counterweights' columns of a design that varies them: kg, kg, mm, mm (rod AB, rod DC).
COUNTERWEIGHTS = ("counterweight_mass1", "counterweight_mass2", "counterweight_distance1",
                  "counterweight_distance2")
#: The motor's columns of a design that searches it: indices into the catalogue's motors and
#: its gear ratios.
MOTOR_COLUMNS = ("motor_index", "ratio_index")
#: Every column a design may have, with its unit (the CSV header's suffix).
UNITS = {**dict.fromkeys(LENGTHS, "mm"), "counterweight_mass1": "kg",
         "counterweight_mass2": "kg", "counterweight_distance1": "mm",
         "counterweight_distance2": "mm", "motor_index": "", "ratio_index": ""}


def columns_of_width(width: int) -> tuple[str, ...]:
    """The columns of a design of ``width`` values: the lengths, then the counterweights and
    the motor's indices as a space adds them (5, 7, 9 or 11 values)."""
    for cols in (LENGTHS, LENGTHS + MOTOR_COLUMNS, LENGTHS + COUNTERWEIGHTS,
                 LENGTHS + COUNTERWEIGHTS + MOTOR_COLUMNS):
        if len(cols) == width:
            return cols
    raise ValueError(f"no design has {width} columns")


def row_columns(row: Mapping[str, object]) -> tuple[str, ...]:
    """The design columns a row holds (in the order of :func:`columns_of_width`)."""
    return tuple(k for k in (*LENGTHS, *COUNTERWEIGHTS, *MOTOR_COLUMNS) if k in row)


#: The axis labels of the dimensions not named by their columns.
AXIS_LABELS = {"counterweight_mass": "counterweight mass, AB = DC",
               "counterweight_mass1": "counterweight mass, AB",
               "counterweight_mass2": "counterweight mass, DC",
               "counterweight_distance": "counterweight distance, AB = DC",
               "counterweight_distance1": "counterweight distance, AB",
               "counterweight_distance2": "counterweight distance, DC",
               "motor": "motor (catalogue index)", "ratio": "gear ratio (index)"}
#: The dimensions (config names) whose values are whole numbers (indices).
INTEGER_DIMS = ("motor", "ratio")
#: The metrics a design has (``-`` before one in ``objectives`` maximises it). The shaking
#: force and moment (about the middle of AD) are the peaks and RMS of their magnitudes over
#: the task; the motors' mass and price are both motors' (None without a catalogue).
METRICS = ("cycle_time_s", "footprint_mm", "min_type1_distance", "min_type2_distance", "gci",
           "peak_torque_A_Nm", "peak_torque_D_Nm", "rms_torque_A_Nm", "rms_torque_D_Nm",
           "workspace_area_mm2", "shaking_force_N", "rms_shaking_force_N", "shaking_moment_Nm",
           "rms_shaking_moment_Nm", "motor_mass_kg", "motor_price", "gear_ratio")
#: The metrics only a task with a motor catalogue has.
MOTOR_METRICS = ("motor_mass_kg", "motor_price", "gear_ratio")
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
        Each dimension: its config name, its range (in the unit of its columns; for
        :data:`INTEGER_DIMS`, ``[0, count]``: the whole numbers below ``count``) and the
        indices of the design columns it sets.
    fixed : tuple of float
        The task's value of every column (the lengths in mm, ...), for the columns no
        dimension sets.
    mass_per_length : (float, float), optional
        kg/m of the proximal and distal rods (uniform rods whose masses follow the lengths);
        None keeps the task's rods.
    samples : int
    sampling : str
    seed : int
    objectives : tuple of str
    columns : tuple of str
        The design's columns: :data:`LENGTHS`, then :data:`COUNTERWEIGHTS` and
        :data:`MOTOR_COLUMNS` when they are varied.
    """

    dims: tuple[tuple[str, float, float, tuple[int, ...]], ...]
    fixed: tuple[float, ...]
    mass_per_length: tuple[float, float] | None
    samples: int
    sampling: str
    seed: int
    objectives: tuple[str, ...]
    columns: tuple[str, ...] = LENGTHS

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
            if name in INTEGER_DIMS:
                continue
            length = name in (*LENGTHS, "l", "L")
            if lo < 0 or (lo == 0 and length and name != "d"):
                unit = "kg" if name.startswith("counterweight_mass") else "mm"
                raise ConfigError(f"config key [design].{name} = [{lo:g}, {hi:g}] must be "
                                  f"{'positive' if length and name != 'd' else '>= 0'} {unit}")
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
        if len(self.fixed) != len(self.columns):
            raise ConfigError(f"a design space of columns {self.columns} needs a value of "
                              f"each, got {len(self.fixed)}")

    def from_unit(self, u: object) -> Array:
        """The designs (n, len(columns)) at the points ``u`` (n, len(dims)) of the unit cube:
        each dimension's range scaled, whole numbers for :data:`INTEGER_DIMS` (the range
        ``[0, count]`` cut in ``count`` equal parts), the task's values elsewhere. What a
        sampling or a search maps its points through."""
        u = np.atleast_2d(np.asarray(u, float))
        out = np.tile(np.asarray(self.fixed, float), (len(u), 1))
        for j, (name, lo, hi, cols) in enumerate(self.dims):
            v = lo + (hi - lo) * u[:, j]
            if name in INTEGER_DIMS:
                v = np.clip(np.floor(v), lo, hi - 1)
            for c in cols:
                out[:, c] = v
        return out

    def designs(self) -> Array:
        """The sampled designs, shape (n, len(columns)) (lengths in mm; ``n = samples``; for
        ``grid``, the smallest full grid with at least ``samples`` points, cut to
        ``samples``)."""
        return self.from_unit(self.unit_sample())

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

    @property
    def varied_axes(self) -> list[tuple[int, str]]:
        """One ``(column, label)`` per varied dimension: columns tied to one range (``l``:
        both proximal rods) are one axis, ``"l1 = l2"``; the counterweights and the motor in
        words (``"counterweight mass, AB = DC"``)."""
        return sorted((cs[0], AXIS_LABELS.get(name) or " = ".join(self.columns[c] for c in cs))
                      for name, _, _, cs in self.dims)

    def objective_values(self, rows: list[dict[str, float]]) -> Array:
        """The objectives of ``rows`` to minimise, shape (n, n_objectives)."""
        F = np.empty((len(rows), len(self.objectives)))
        for j, obj in enumerate(self.objectives):
            sign = -1.0 if obj.startswith("-") else 1.0
            F[:, j] = [sign * float(r[obj.lstrip("-")]) for r in rows]
        return F
