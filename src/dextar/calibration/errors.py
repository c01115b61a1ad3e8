"""The calibration's own errors: each a :class:`dextar.errors.DextarError` that carries what
it names (rows, parameters) for the caller, with a one-line message."""

from __future__ import annotations

from ..errors import ParameterError, ReachError


class OutlierError(ParameterError):
    """Measured points farther from their predictions than the stated multiple of the
    residual scale; ``rows`` holds their row numbers."""

    def __init__(self, message: str, rows: tuple[int, ...]) -> None:
        super().__init__(message)
        self.rows = rows


class CouplingError(ParameterError):
    """Poses of a single working mode that leave parameters coupled; ``names`` holds the
    coupled parameters."""

    def __init__(self, message: str, names: tuple[str, ...]) -> None:
        super().__init__(message)
        self.names = names


class OutOfReachError(ReachError):
    """A measured point out of reach of the nominal and the fitted robot; ``rows`` holds its
    row number."""

    def __init__(self, message: str, rows: tuple[int, ...]) -> None:
        super().__init__(message)
        self.rows = rows
