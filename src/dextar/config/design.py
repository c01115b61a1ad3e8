"""The ``[design]`` table of a design sweep or search (``dextar design``): ranges of the
geometry and of the counterweights, the rods' mass per length, the motor catalogue and gear
ratios, the sweep's sampling or the adaptive search, and the objectives."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from ..design.search import BATCH, SEARCHES, SearchSettings
from ..design.space import (
    COUNTERWEIGHTS,
    LENGTHS,
    MOTOR_COLUMNS,
    MOTOR_METRICS,
    SAMPLINGS,
    DesignSpace,
    check_objectives,
)
from ..errors import ConfigError
from ..geometry import FiveBar
from ..motors import ORDERS, Catalogue
from ..params import Param, read_params
from .base import Table

#: How each design's motor and gear ratio are chosen from a catalogue.
MOTOR_CHOICES = (*ORDERS, "search")
#: The counterweight ranges: config name -> the design columns it sets (indices into
#: LENGTHS + COUNTERWEIGHTS).
COUNTERWEIGHT_KEYS = {"counterweight_mass": (5, 6), "counterweight_mass1": (5,),
                      "counterweight_mass2": (6,), "counterweight_distance": (7, 8),
                      "counterweight_distance1": (7,), "counterweight_distance2": (8,)}

#: Objectives when ``[design].objectives`` is not given.
DEFAULT_OBJECTIVES = ("cycle_time_s", "footprint_mm", "-min_type2_distance")

#: Designs per unit of work by default: a sweep's, a search's (:attr:`DesignTable.chunk`).
SWEEP_CHUNK, SEARCH_CHUNK = 8, BATCH


def _range(what: str) -> Param:
    return Param("point", "", None, f"range [low, high] of {what}, mm")


@dataclass(frozen=True)
class DesignTable(Table):
    """``[design]``: what a sweep varies (ranges in mm), samples and minimises."""

    NAME: ClassVar[str] = "design"
    PARAMS: ClassVar[dict[str, Param]] = {
        "l": _range("both proximal rods (the same length)"),
        "L": _range("both distal rods (the same length)"),
        **{k: _range(f"{k}") for k in LENGTHS},
        "mass_per_length": Param("point", "", None, "kg/m of the proximal and distal rods "
                                 "(uniform rods whose masses follow the lengths)"),
        "search": Param("choice", "", None, "sobol, grid or random (a sweep of [design].samples "
                        "designs) or nsga2 or smsemoa (an adaptive multi-objective search of "
                        "[design].evaluations designs; smsemoa keeps the designs that add most "
                        "to the front's hypervolume); default sobol",
                        choices=(*SAMPLINGS, *SEARCHES)),
        "samples": Param("integer", "", 1000, "designs of a sweep", minimum=1,
                         maximum=1_000_000),
        "sampling": Param("choice", "", None, "a sweep's sampling, sobol, grid or random (the "
                          "older name of [design].search)", choices=SAMPLINGS),
        "population": Param("integer", "", 20, "designs a search (nsga2, smsemoa) keeps from "
                            "one batch to the next (its first sample, scrambled Sobol, has as "
                            "many); about evaluations / 20 or less",
                            minimum=4, maximum=100_000),
        "evaluations": Param("integer", "", 2000, "designs a search evaluates in all",
                             minimum=4, maximum=1_000_000),
        "seed": Param("integer", "", 0, "seed of the sampling and of the search", minimum=0,
                      maximum=2**31 - 1),
        "objectives": Param("text", "", None, "metrics to minimise (a leading - maximises)"),
        "chunk": Param("integer", "", None, "designs per unit of work (a search proposes as "
                       "many at a time): default 8 for a sweep, 4 for a search (5 batches in "
                       "flight at the population of 20: two workers kept busy)", minimum=1,
                       maximum=10_000),
        "grid": Param("integer", "", 100, "time-optimal segments per motion in the sweep",
                      minimum=10, maximum=100_000),
        "counterweight_mass": Param("point", "", None, "range [low, high] of both proximal "
                                    "rods' counterweights, kg"),
        "counterweight_mass1": Param("point", "", None, "range of rod AB's counterweight, kg"),
        "counterweight_mass2": Param("point", "", None, "range of rod DC's counterweight, kg"),
        "counterweight_distance": Param("point", "", None, "range [low, high] of both "
                                        "counterweights' distances behind the motor axes, mm"),
        "counterweight_distance1": Param("point", "", None, "range of rod AB's counterweight "
                                         "distance, mm"),
        "counterweight_distance2": Param("point", "", None, "range of rod DC's counterweight "
                                         "distance, mm"),
        "motors": Param("text", "", None, "a motor catalogue (TOML, relative to the task "
                        "file): each design gets its motors and gear ratio from it"),
        "ratios": Param("text", "", None, "gear ratios the catalogue's motors may take, motor "
                        "turns per joint turn (default [1]: direct drive)"),  # a list: below
        "motor_choice": Param("choice", "", "lightest", "lightest or cheapest: the smallest "
                              "motor that fits (each with its best ratio); search: motor and "
                              "ratio are design variables", choices=MOTOR_CHOICES),
    }

    values: Mapping[str, Any] | None = None
    objectives: tuple[str, ...] = DEFAULT_OBJECTIVES
    ratios: tuple[float, ...] = (1.0,)

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> DesignTable:
        """Read ``[design]`` (``objectives`` is a list of metric names)."""
        if not raw:
            return cls()
        rest = {k: v for k, v in raw.items() if k not in ("objectives", "ratios")}
        values = read_params(cls.NAME, rest, cls.PARAMS)
        values.pop("objectives", None)
        values.pop("ratios", None)
        ratios = _ratios(raw.get("ratios", [1.0]))
        if "ratios" in raw and "motors" not in values:
            raise ConfigError("config key [design].ratios needs [design].motors (the "
                              "catalogue whose motors take them)")
        if "motor_choice" in raw and "motors" not in values:
            raise ConfigError("config key [design].motor_choice needs [design].motors")
        objectives = raw.get("objectives", list(DEFAULT_OBJECTIVES))
        if not isinstance(objectives, list) or not all(isinstance(o, str) for o in objectives):
            raise ConfigError(f"config key [design].objectives must be a list of metric names, "
                              f"got {objectives!r}")
        check_objectives(objectives)
        kind = values.get("search") or values.get("sampling") or "sobol"
        if "search" in values and "sampling" in values and values["sampling"] != kind:
            raise ConfigError(f"config keys [design].search = {kind!r} and [design].sampling = "
                              f"{values['sampling']!r} disagree: give search alone")
        values["search"] = kind
        if kind in SEARCHES and "samples" in raw:
            raise ConfigError(f"config key [design].samples is a sweep's: a search = {kind!r} "
                              "evaluates [design].evaluations designs")
        for key in ("population", "evaluations"):
            if kind not in SEARCHES and key in raw:
                raise ConfigError(f"config key [design].{key} is a search's (search = "
                                  f"\"nsga2\" or \"smsemoa\"), not a {kind} sweep's")
        if "motors" not in values:
            for o in objectives:
                if o.lstrip("-") in MOTOR_METRICS:
                    raise ConfigError(f"config key [design].objectives: {o!r} needs a motor "
                                      "catalogue ([design].motors)")
        for a, b in (("l", "l1"), ("l", "l2"), ("L", "L1"), ("L", "L2"),
                     *((f"counterweight_{q}", f"counterweight_{q}{k}") for q in
                       ("mass", "distance") for k in (1, 2))):
            if a in values and b in values:
                raise ConfigError(f"config keys [design].{a} and [design].{b} both set "
                                  f"{b}: give {a} (both legs) or {b} and its twin")
        return cls(values, tuple(objectives), ratios)

    def space(self, robot_mm: FiveBar, *, samples: int | None = None,
              seed: int | None = None,
              counterweights: tuple[tuple[float, float], tuple[float, float]] = (
                  (0.0, 0.0), (0.0, 0.0)),
              catalogue: Catalogue | None = None) -> DesignSpace:
        """The design space around the task's robot (its lengths where no range is given,
        its counterweights' masses in kg and distances in mm, ``counterweights``, where the
        ranges give none); ``samples`` and ``seed`` override the table's; ``catalogue`` (read
        from ``motors``) sizes the motor's dimensions of ``motor_choice = "search"``."""
        if self.values is None:
            raise ConfigError("the task has no [design] table: give the ranges to sweep, e.g. "
                              "[design] l = [50.0, 120.0]")
        v = self.values
        searching = self.search_kind in SEARCHES
        cols: dict[str, tuple[int, ...]] = {
            "l": (0, 1), "L": (2, 3), "l1": (0,), "l2": (1,), "L1": (2,), "L2": (3,),
            "d": (4,), **COUNTERWEIGHT_KEYS}
        dims = [(k, float(v[k][0]), float(v[k][1]), cols[k]) for k in cols if k in v]
        g = robot_mm
        columns: tuple[str, ...] = LENGTHS
        fixed: tuple[float, ...] = (g.l1, g.l2, g.L1, g.L2, g.d)
        if any(k in v for k in COUNTERWEIGHT_KEYS):
            (m1, m2), (r1, r2) = counterweights
            columns, fixed = columns + COUNTERWEIGHTS, fixed + (m1, m2, r1, r2)
            self._check_counterweights(dims, fixed)
        if self.motor_choice == "search":
            if catalogue is None:
                raise ConfigError("config key [design].motor_choice = \"search\" needs "
                                  "[design].motors")
            at = len(columns)
            columns, fixed = columns + MOTOR_COLUMNS, fixed + (0.0, 0.0)
            dims += [("motor", 0.0, float(len(catalogue.motors)), (at,)),
                     ("ratio", 0.0, float(len(catalogue.ratios)), (at + 1,))]
        mpl = v.get("mass_per_length")
        return DesignSpace(
            tuple(dims), fixed,
            None if mpl is None else (float(mpl[0]), float(mpl[1])),
            int(v["population"]) if searching else
            samples if samples is not None else int(v["samples"]),
            "sobol" if searching else self.search_kind,
            seed if seed is not None else int(v["seed"]), self.objectives, columns)

    @property
    def search_kind(self) -> str:
        """``sobol``, ``grid`` or ``random`` (a sweep) or ``nsga2``, ``smsemoa`` (a search)."""
        return str((self.values or {}).get("search", "sobol"))

    def search(self, *, evaluations: int | None = None,
               seed: int | None = None) -> SearchSettings | None:
        """The adaptive search's settings (None for a sweep); ``evaluations`` and ``seed``
        override the table's."""
        if self.search_kind not in SEARCHES:
            return None
        v = self.values or {}
        return SearchSettings(self.search_kind, int(v["population"]),
                              evaluations if evaluations is not None else int(v["evaluations"]),
                              seed if seed is not None else int(v["seed"]), self.chunk)

    @staticmethod
    def _check_counterweights(dims: list[tuple[str, float, float, tuple[int, ...]]],
                              fixed: tuple[float, ...]) -> None:
        """Refuse counterweights that cannot act: a mass range for rods with no distance, a
        distance range for rods with no mass (neither varied nor in ``[inertia]``)."""
        varied = {c for _, _, _, cs in dims for c in cs}
        for name, _, _, cs in dims:
            if not name.startswith("counterweight_"):
                continue
            mass = name.startswith("counterweight_mass")
            other = [c + 2 if mass else c - 2 for c in cs]  # the same legs' other column
            if not any(o in varied or fixed[o] > 0 for o in other):
                need = ("a distance: [design].counterweight_distance or "
                        "[inertia].counterweight_distance" if mass else
                        "a mass: [design].counterweight_mass or [inertia].counterweight_mass")
                raise ConfigError(f"config key [design].{name} needs {need}")

    @property
    def motors(self) -> str | None:
        """The motor catalogue's file as written (None without one)."""
        m = (self.values or {}).get("motors")
        return None if m is None else str(m)

    @property
    def motor_choice(self) -> str:
        """``lightest``, ``cheapest`` or ``search``."""
        return str((self.values or {}).get("motor_choice", "lightest"))

    @property
    def chunk(self) -> int:
        """Designs per unit of work: ``[design].chunk``, else 8 for a sweep and 4 for a search
        (batches in flight are ``population // chunk``: at 8, two, and a worker of two waited
        at each batch's return: 2-worker efficiency 0.71; at 4, five: 0.87, program task,
        benchmarks/bench_design_search.py)."""
        c = (self.values or {}).get("chunk")
        if c is not None:
            return int(c)
        return SEARCH_CHUNK if self.search_kind in SEARCHES else SWEEP_CHUNK

    @property
    def grid(self) -> int:
        """Time-optimal grid of the sweep's plans."""
        return int((self.values or {}).get("grid", 100))


def _ratios(raw: object) -> tuple[float, ...]:
    """``[design].ratios``: a non-empty list of positive finite numbers, each once."""
    if not (isinstance(raw, list) and raw and all(
            isinstance(r, (int, float)) and not isinstance(r, bool) for r in raw)):
        raise ConfigError(f"config key [design].ratios must be a list of gear ratios (motor "
                          f"turns per joint turn), got {raw!r}")
    out = tuple(float(r) for r in raw)
    for r, given in zip(out, raw, strict=True):
        if not (math.isfinite(r) and 0 < r <= 1e6):
            raise ConfigError(f"config key [design].ratios: {given!r} must be a positive "
                              "number (at most 1e6)")
    if len(set(out)) != len(out):
        raise ConfigError(f"config key [design].ratios {list(raw)} lists a ratio twice")
    return out
