"""Errors and warnings raised by stochcable.

Every error a user can cause is an :class:`InputError` whose message names the
parameter, its value, its unit and the constraint it broke.  Solvers that do not
converge raise :class:`ConvergenceError` with the residual they reached.  The service
maps :class:`StochcableError` subclasses to HTTP 422 answers.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "StochcableError",
    "InputError",
    "ConvergenceError",
    "SolverError",
    "PhysicsWarning",
    "ResolutionWarning",
]


class StochcableError(Exception):
    """Base class of every error stochcable raises on purpose."""


def _fmt_value(value: Any) -> str:
    try:
        import numpy as np

        if isinstance(value, np.ndarray):
            if value.size > 6:
                return f"array(shape={value.shape})"
            return repr(value.tolist())
    except ImportError:  # pragma: no cover
        pass
    return repr(value)


class InputError(StochcableError, ValueError):
    """A parameter outside its domain.

    Parameters
    ----------
    parameter : str
        Name of the parameter as the caller spelled it (``"hs"``,
        ``"lines[0].segments[1].ea"``).
    value : object
        The offending value.
    unit : str
        Unit of the parameter (``"m"``, ``"rad/s"``, ``"-"`` for dimensionless).
    constraint : str
        What the value must satisfy (``"must be > 0"``).
    """

    _NO_VALUE = object()

    def __init__(self, parameter: str, value: Any, unit: str, constraint: str) -> None:
        self.parameter = parameter
        self.value = value
        self.unit = unit
        self.constraint = constraint
        unit_txt = f" [{unit}]" if unit and unit != "-" else ""
        if value is InputError._NO_VALUE:
            # a constraint between several fields: the message itself names them
            self.value = None
            super().__init__(f"{parameter}: {constraint}")
        else:
            super().__init__(f"{parameter} = {_fmt_value(value)}{unit_txt}: {constraint}")


class ConvergenceError(StochcableError):
    """An iterative solver stopped before meeting its tolerance.

    Parameters
    ----------
    solver : str
        Which solver (``"statics Newton"``, ``"drag linearization"``).
    iterations : int
        Iterations performed.
    residual : float
        Residual (or relative change) reached.
    tolerance : float
        Tolerance asked for.
    hint : str, optional
        What the user can change.
    partial : object, optional
        The last iterate, for callers that want to inspect it.
    """

    def __init__(
        self,
        solver: str,
        iterations: int,
        residual: float,
        tolerance: float,
        hint: str = "",
        partial: Any = None,
    ) -> None:
        self.solver = solver
        self.iterations = iterations
        self.residual = residual
        self.tolerance = tolerance
        self.partial = partial
        msg = (
            f"{solver} did not converge: residual {residual:.3e} after "
            f"{iterations} iterations (tolerance {tolerance:.1e})"
        )
        if hint:
            msg += f"; {hint}"
        super().__init__(msg)


class SolverError(StochcableError):
    """A solve that cannot produce a finite answer (singular system, undamped resonance)."""


class PhysicsWarning(UserWarning):
    """The model is used outside the range where it is trustworthy."""


class ResolutionWarning(UserWarning):
    """A discretization (time step, frequency grid, elements) is too coarse for the input."""
