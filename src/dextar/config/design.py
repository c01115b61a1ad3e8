"""The ``[design]`` table of a design sweep or search (``dextar design``): ranges of the
geometry, the rods' mass per length, the sweep's sampling or the adaptive search, and the
objectives."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from ..design.search import SEARCHES, SearchSettings
from ..design.space import LENGTHS, SAMPLINGS, DesignSpace, check_objectives
from ..errors import ConfigError
from ..geometry import FiveBar
from ..params import Param, read_params
from .base import Table

#: Objectives when ``[design].objectives`` is not given.
DEFAULT_OBJECTIVES = ("cycle_time_s", "footprint_mm", "-min_type2_distance")


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
                        "designs) or nsga2 (an adaptive multi-objective search of "
                        "[design].evaluations designs); default sobol",
                        choices=(*SAMPLINGS, *SEARCHES)),
        "samples": Param("integer", "", 1000, "designs of a sweep", minimum=1,
                         maximum=1_000_000),
        "sampling": Param("choice", "", None, "a sweep's sampling, sobol, grid or random (the "
                          "older name of [design].search)", choices=SAMPLINGS),
        "population": Param("integer", "", 40, "designs an nsga2 search keeps from one batch "
                            "to the next (its first sample, scrambled Sobol, has as many)",
                            minimum=4, maximum=100_000),
        "evaluations": Param("integer", "", 2000, "designs an nsga2 search evaluates in all",
                             minimum=4, maximum=1_000_000),
        "seed": Param("integer", "", 0, "seed of the sampling and of the search", minimum=0,
                      maximum=2**31 - 1),
        "objectives": Param("text", "", None, "metrics to minimise (a leading - maximises)"),
        "chunk": Param("integer", "", 8, "designs per unit of work (a search proposes as many "
                       "at a time)", minimum=1, maximum=10_000),
        "grid": Param("integer", "", 100, "time-optimal segments per motion in the sweep",
                      minimum=10, maximum=100_000),
    }

    values: Mapping[str, Any] | None = None
    objectives: tuple[str, ...] = DEFAULT_OBJECTIVES

    @classmethod
    def from_toml(cls, raw: Mapping[str, object]) -> DesignTable:
        """Read ``[design]`` (``objectives`` is a list of metric names)."""
        if not raw:
            return cls()
        rest = {k: v for k, v in raw.items() if k != "objectives"}
        values = read_params(cls.NAME, rest, cls.PARAMS)
        values.pop("objectives", None)
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
                                  f"\"nsga2\"), not a {kind} sweep's")
        for a, b in (("l", "l1"), ("l", "l2"), ("L", "L1"), ("L", "L2")):
            if a in values and b in values:
                raise ConfigError(f"config keys [design].{a} and [design].{b} both set the "
                                  f"length {b}: give {a} (both legs) or {b} and its twin")
        return cls(values, tuple(objectives))

    def space(self, robot_mm: FiveBar, *, samples: int | None = None,
              seed: int | None = None) -> DesignSpace:
        """The design space around the task's robot (its lengths where no range is given);
        ``samples`` and ``seed`` override the table's."""
        if self.values is None:
            raise ConfigError("the task has no [design] table: give the ranges to sweep, e.g. "
                              "[design] l = [50.0, 120.0]")
        v = self.values
        searching = self.search_kind in SEARCHES
        cols = {"l": (0, 1), "L": (2, 3), "l1": (0,), "l2": (1,), "L1": (2,), "L2": (3,),
                "d": (4,)}
        dims = tuple((k, float(v[k][0]), float(v[k][1]), cols[k]) for k in
                     ("l", "l1", "l2", "L", "L1", "L2", "d") if k in v)
        g = robot_mm
        mpl = v.get("mass_per_length")
        return DesignSpace(
            dims, (g.l1, g.l2, g.L1, g.L2, g.d),
            None if mpl is None else (float(mpl[0]), float(mpl[1])),
            int(v["population"]) if searching else
            samples if samples is not None else int(v["samples"]),
            "sobol" if searching else self.search_kind,
            seed if seed is not None else int(v["seed"]), self.objectives)

    @property
    def search_kind(self) -> str:
        """``sobol``, ``grid`` or ``random`` (a sweep) or ``nsga2`` (a search)."""
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

    @property
    def chunk(self) -> int:
        """Designs per unit of work."""
        return int((self.values or {}).get("chunk", 8))

    @property
    def grid(self) -> int:
        """Time-optimal grid of the sweep's plans."""
        return int((self.values or {}).get("grid", 100))
