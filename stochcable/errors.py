"""Errors and warnings raised by stochcable.

Every error a user can cause is an :class:`InputError` whose message names the
parameter, its value, its unit and the constraint it broke.  Solvers that do not
converge raise :class:`ConvergenceError` with the residual they reached.  The service
maps :class:`StochcableError` subclasses to HTTP 422 answers.
"""

from __future__ import annotations

import threading
import warnings
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from typing import Any

__all__ = [
    "StochcableError",
    "InputError",
    "ConvergenceError",
    "SolverError",
    "PhysicsWarning",
    "ResolutionWarning",
    "warn",
    "collect_warnings",
    "forward_warnings",
    "isolated_warnings",
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


# ----------------------------------------------------------------- warning collection
#
# The analysis reports its warnings in the result document as well as through Python's
# warnings machinery.  ``warnings.catch_warnings`` is process-global (before Python
# 3.14), so two analyses in two threads (the service) would lose or swap each other's
# warnings; a thread-local sink does not.

_local = threading.local()


def warn(message: str, category: type[Warning] = PhysicsWarning, stacklevel: int = 2) -> None:
    """Issue a warning and record it in the calling thread's :func:`collect_warnings`.

    Parameters
    ----------
    message : str
        The warning text: the threshold crossed and the fix.
    category : type of Warning, optional
        PhysicsWarning (default), ResolutionWarning or another Warning subclass.
    stacklevel : int, optional
        As for :func:`warnings.warn`, counted from the caller of this function.
    """
    sinks = getattr(_local, "sinks", None)
    if sinks:
        for sink in sinks:
            sink.append(category(message))
    warnings.warn(message, category, stacklevel=stacklevel + 1)


@contextmanager
def collect_warnings() -> Iterator[list[Warning]]:
    """Collect the warnings :func:`warn` issues in this thread inside the block.

    The warnings are still issued normally (shown or filtered by the caller's
    warning filters); the list is an additional, thread-safe record.  Blocks nest:
    an inner block's warnings also reach the outer one.
    """
    sink: list[Warning] = []
    sinks = getattr(_local, "sinks", None)
    if sinks is None:
        sinks = _local.sinks = []
    sinks.append(sink)
    try:
        yield sink
    finally:
        # by identity: nested sinks holding the same warnings compare equal
        del sinks[next(i for i in range(len(sinks) - 1, -1, -1) if sinks[i] is sink)]


def forward_warnings(caught: Iterable[Warning]) -> None:
    """Record warnings in this thread's open :func:`collect_warnings` blocks.

    For warnings :func:`warn` issued (and collected) in another thread on this
    thread's behalf, e.g. by the workers of :func:`stochcable.runtime.line_map`: they
    reach every collector open here, as if issued here, but are not issued again
    through :mod:`warnings` (that happened where they arose).

    Parameters
    ----------
    caught : iterable of Warning
        The warnings, in the order to record them.
    """
    sinks = getattr(_local, "sinks", None)
    if not sinks:
        return
    caught = list(caught)
    for sink in sinks:
        sink.extend(caught)


@contextmanager
def isolated_warnings() -> Iterator[None]:
    """Hide this thread's open :func:`collect_warnings` blocks inside the block.

    :func:`warn` inside reaches only the collectors opened inside; the outer ones are
    restored on exit.  For code that collects per item and forwards the items'
    warnings later, once and in order (:func:`forward_warnings`).
    """
    saved = getattr(_local, "sinks", None)
    _local.sinks = []
    try:
        yield
    finally:
        _local.sinks = saved
