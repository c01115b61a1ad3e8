"""A motor catalogue file (``[design].motors = "catalogue.toml"``): motors to choose from,
read into a :class:`dextar.motors.Catalogue` in SI.

The file (TOML, config units)::

    currency = "EUR"          # optional: the unit of the prices

    [[motor]]
    name = "BL-40-50W"        # unique
    rated_torque = 0.12       # N m, continuous (RMS), at the motor's shaft
    peak_torque = 0.40        # N m
    max_speed_rpm = 6000
    knee_speed_rpm = 4500     # optional: full torque up to here, then linear to 0
    rotor_inertia = 2.4       # kg mm^2
    mass = 0.30               # kg
    price = 180               # in the currency above

The gear ratios the motors may take are ``[design].ratios``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ..errors import ConfigError, DextarError
from ..motors import Catalogue, Motor
from ..params import Param, read_params
from .toml import read_config

#: The keys of one ``[[motor]]`` entry.
MOTOR_PARAMS: dict[str, Param] = {
    "name": Param("text", "", help="the motor's name (unique in the catalogue)"),
    "rated_torque": Param("number", "N m", help="continuous (RMS) torque at the motor's shaft",
                          positive=True, maximum=1e6),
    "peak_torque": Param("number", "N m", help="peak torque at the motor's shaft",
                         positive=True, maximum=1e6),
    "max_speed_rpm": Param("number", "", help="maximum speed, rpm", positive=True,
                           maximum=1e7),
    "knee_speed_rpm": Param("number", "", None, "end of full torque, rpm (below "
                            "max_speed_rpm; then linear to zero at it)", positive=True),
    "rotor_inertia": Param("number", "", help="rotor inertia, kg mm^2", minimum=0.0,
                           maximum=1e12),
    "mass": Param("number", "kg", help="the motor's mass", minimum=0.0, maximum=1e6),
    "price": Param("number", "", help="its price, in the catalogue's currency", minimum=0.0),
}


def read_catalogue(path: str | Path, ratios: Sequence[float] = (1.0,)) -> Catalogue:
    """The catalogue at ``path`` with the gear ratios ``ratios``, in SI.

    Raises
    ------
    ConfigError
        A missing or unreadable file, a key missing or out of range, a duplicate name; the
        message names the file and the entry (``[[motor]] 2 (NAME)``).
    """
    label = f"motor catalogue {str(path)!r}"
    doc, _ = read_config(path)
    return catalogue_from_dict(doc, ratios, label)


def catalogue_from_dict(doc: Mapping[str, Any], ratios: Sequence[float],
                        label: str = "the motor catalogue") -> Catalogue:
    """A parsed catalogue file (see the module doc) as a :class:`Catalogue` in SI."""
    unknown = [k for k in doc if k not in ("motor", "currency")]
    if unknown:
        raise ConfigError(f"{label}: {unknown[0]!r} is not known; a catalogue holds "
                          "currency and [[motor]] tables")
    currency = doc.get("currency", "")
    if not isinstance(currency, str):
        raise ConfigError(f"{label}: currency must be a string, got {currency!r}")
    entries = doc.get("motor")
    if not isinstance(entries, list) or not entries or not all(
            isinstance(e, dict) for e in entries):
        raise ConfigError(f"{label} lists no motor: give [[motor]] tables")
    rpm = 2.0 * math.pi / 60.0
    motors = []
    for i, raw in enumerate(entries, start=1):
        name = raw.get("name")
        where = f"[[motor]] {i}" + (f" ({name})" if isinstance(name, str) else "")
        try:
            v = read_params(where, raw, MOTOR_PARAMS)
            knee = v.get("knee_speed_rpm")
            if knee is not None and not knee < v["max_speed_rpm"]:
                raise ConfigError(f"config key {where}.knee_speed_rpm {knee:g} must be below "
                                  f"max_speed_rpm {v['max_speed_rpm']:g}")
            motors.append(Motor(v["name"], v["rated_torque"], v["peak_torque"],
                                v["max_speed_rpm"] * rpm, v["rotor_inertia"] * 1e-6,
                                v["mass"], v["price"], None if knee is None else knee * rpm))
        except ConfigError as exc:
            raise ConfigError(f"{label}: {exc}".replace("config key ", "key ")) from None
        except DextarError as exc:  # the motor's own check: it names the motor
            raise ConfigError(f"{label}: [[motor]] {i}: {exc}") from None
    try:
        return Catalogue(tuple(motors), tuple(float(r) for r in ratios), label, currency)
    except DextarError as exc:
        raise ConfigError(f"{exc}") from None
