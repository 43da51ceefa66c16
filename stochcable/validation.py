"""Boundary validation helpers (scipy.signal style: validate once, name the parameter).

Each helper returns the value converted (float or float ndarray) or raises
:class:`stochcable.errors.InputError` naming parameter, value, unit and constraint.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stochcable.errors import InputError

__all__ = [
    "finite_scalar",
    "positive",
    "nonnegative",
    "in_range",
    "positive_int",
    "float_array",
]


def finite_scalar(name: str, value: Any, unit: str) -> float:
    """Return ``value`` as a finite float or raise InputError."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(name, value, unit, "must be a real number") from None
    if not math.isfinite(x):
        raise InputError(name, value, unit, "must be finite (not NaN or inf)")
    return x


def positive(name: str, value: Any, unit: str) -> float:
    """Return ``value`` as a finite float > 0 or raise InputError."""
    x = finite_scalar(name, value, unit)
    if x <= 0.0:
        raise InputError(name, value, unit, "must be > 0")
    return x


def nonnegative(name: str, value: Any, unit: str) -> float:
    """Return ``value`` as a finite float >= 0 or raise InputError."""
    x = finite_scalar(name, value, unit)
    if x < 0.0:
        raise InputError(name, value, unit, "must be >= 0")
    return x


def in_range(
    name: str,
    value: Any,
    unit: str,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    hi_open: bool = False,
) -> float:
    """Return ``value`` as a finite float inside the given (half-)open interval."""
    x = finite_scalar(name, value, unit)
    if lo is not None and (x < lo or (lo_open and x == lo)):
        raise InputError(name, value, unit, f"must be {'>' if lo_open else '>='} {lo:g}")
    if hi is not None and (x > hi or (hi_open and x == hi)):
        raise InputError(name, value, unit, f"must be {'<' if hi_open else '<='} {hi:g}")
    return x


def positive_int(name: str, value: Any, minimum: int = 1, even: bool = False) -> int:
    """Return ``value`` as an int >= ``minimum`` (and even, if asked)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        else:
            raise InputError(name, value, "-", "must be an integer")
    n = int(value)
    if n < minimum:
        raise InputError(name, value, "-", f"must be an integer >= {minimum}")
    if even and n % 2:
        raise InputError(name, value, "-", "must be an even integer")
    return n


def float_array(
    name: str,
    value: Any,
    unit: str,
    *,
    ndim: int | None = 1,
    positive: bool = False,
    nonnegative: bool = False,
    increasing: bool = False,
    min_size: int = 1,
) -> np.ndarray:
    """Return ``value`` as a finite float ndarray checked against the given constraints."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(name, value, unit, "must be an array of real numbers") from None
    if ndim is not None and arr.ndim != ndim:
        if ndim == 1 and arr.ndim == 0:
            arr = arr.reshape(1)
        else:
            raise InputError(name, value, unit, f"must be a {ndim}-D array (got {arr.ndim}-D)")
    if arr.size < min_size:
        raise InputError(name, value, unit, f"must have at least {min_size} entries")
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.flatnonzero(bad.ravel())[0])
        raise InputError(name, value, unit, f"must be finite (entry {i} is {arr.ravel()[i]})")
    if positive and (arr <= 0).any():
        i = int(np.flatnonzero((arr <= 0).ravel())[0])
        raise InputError(name, value, unit, f"must be > 0 (entry {i} is {arr.ravel()[i]:g})")
    if nonnegative and (arr < 0).any():
        i = int(np.flatnonzero((arr < 0).ravel())[0])
        raise InputError(name, value, unit, f"must be >= 0 (entry {i} is {arr.ravel()[i]:g})")
    if increasing and arr.size > 1 and not (np.diff(arr) > 0).all():
        i = int(np.flatnonzero(np.diff(arr) <= 0)[0])
        raise InputError(
            name,
            value,
            unit,
            f"must be strictly increasing (entry {i + 1} = {arr[i + 1]:g} follows {arr[i]:g})",
        )
    return arr
