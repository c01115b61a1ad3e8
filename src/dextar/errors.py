"""The dextar error hierarchy, rooted in :class:`DextarError`.

Every error names the thing and the place: the point, the leg, the time, the config key.
The command line turns any :class:`DextarError` into one line on stderr and exit status 2.
"""

from __future__ import annotations


class DextarError(Exception):
    """Base class of every error raised on purpose by dextar."""


class GeometryError(DextarError, ValueError):
    """A robot geometry (lengths) that is not valid or can never close."""


class ParameterError(DextarError, ValueError):
    """An invalid parameter value (inertia, law, path, option)."""


class ReachError(DextarError, ValueError):
    """A point out of reach of a leg (inverse kinematics)."""


class AssemblyError(DextarError, ValueError):
    """The distal rods cannot meet for the given actuator angles (direct kinematics)."""


class SingularityError(DextarError, ArithmeticError):
    """A configuration at or near a serial (type 1) or parallel (type 2) singularity."""


class ConvergenceError(DextarError, RuntimeError):
    """A numerical solver (BVP, integrator) that did not converge."""


class ConfigError(DextarError, ValueError):
    """A configuration file or command-line value that is malformed; names the key."""


class InfeasibleError(DextarError, ValueError):
    """No motion exists within the given limits (names the point, the motor and the torque)."""


class NumericalError(DextarError, ArithmeticError):
    """A result that is not finite (parameters so large or small that they overflow double
    precision); names the quantity and the sample."""
