"""The ``[design]`` table of a design sweep (``dextar design``): ranges of the geometry, the
rods' mass per length, the sampling and the objectives."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

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
        "samples": Param("integer", "", 1000, "designs", minimum=1, maximum=1_000_000),
        "sampling": Param("choice", "", "sobol", "sobol, grid or random", choices=SAMPLINGS),
        "seed": Param("integer", "", 0, "seed of the sampling", minimum=0, maximum=2**31 - 1),
        "objectives": Param("text", "", None, "metrics to minimise (a leading - maximises)"),
        "chunk": Param("integer", "", 8, "designs per unit of work", minimum=1,
                       maximum=10_000),
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
        cols = {"l": (0, 1), "L": (2, 3), "l1": (0,), "l2": (1,), "L1": (2,), "L2": (3,),
                "d": (4,)}
        dims = tuple((k, float(v[k][0]), float(v[k][1]), cols[k]) for k in
                     ("l", "l1", "l2", "L", "L1", "L2", "d") if k in v)
        g = robot_mm
        mpl = v.get("mass_per_length")
        return DesignSpace(
            dims, (g.l1, g.l2, g.L1, g.L2, g.d),
            None if mpl is None else (float(mpl[0]), float(mpl[1])),
            samples if samples is not None else int(v["samples"]),
            str(v["sampling"]), seed if seed is not None else int(v["seed"]), self.objectives)

    @property
    def chunk(self) -> int:
        """Designs per unit of work."""
        return int((self.values or {}).get("chunk", 8))

    @property
    def grid(self) -> int:
        """Time-optimal grid of the sweep's plans."""
        return int((self.values or {}).get("grid", 100))
