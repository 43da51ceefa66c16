"""Frequency blocks: the engine's per-evaluation work on slices of the frequency grid,
so that its temporaries stay within a working-memory target.

The drag fixed point needs, per evaluation, only sums over frequency (the element
variances of Tuah (1982), eqs. 5.2.3–5.2.5), and every frequency is solved on its own
(eq. 5.2.6): the load assembly, the direct or Foss solve and the variance sums of one
evaluation run over consecutive blocks of frequencies, each block's temporaries freed
before the next.  The block length comes from the working-memory target
(:func:`working_memory_bytes`) and the bytes one frequency costs in the caller; the
answer is the same for every block length to round-off (the sums over frequency are
only regrouped; tested for blocks of 1, 7 and all frequencies).

Settings: ``STOCHCABLE_WORKING_MEMORY_MB`` (environment variable, read at every call;
default :data:`WORKING_MEMORY_MB`) is the target of one block's temporaries;
:func:`frequency_block` fixes the block length instead (tests, benchmarks).

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
from collections.abc import Iterator

import numpy as np

from stochcable.errors import InputError

#: Frequencies of a grid: a slice or an index array (the last axis of per-frequency
#: arrays).
FrequencyIndex = slice | np.ndarray

__all__ = [
    "FrequencyIndex",
    "WORKING_MEMORY_MB",
    "frequency_block",
    "frequency_slices",
    "whole_grid",
    "working_memory_bytes",
]

#: Default target of one frequency block's temporaries. [MiB]
WORKING_MEMORY_MB = 48

_FORCED: contextvars.ContextVar[int | None] = contextvars.ContextVar(
    "stochcable_frequency_block", default=None
)


def working_memory_bytes() -> int:
    """The working-memory target of one frequency block. [bytes]

    ``STOCHCABLE_WORKING_MEMORY_MB`` (a positive number of MiB) or
    :data:`WORKING_MEMORY_MB`.

    Raises
    ------
    InputError
        The environment variable is not a positive number.
    """
    raw = os.environ.get("STOCHCABLE_WORKING_MEMORY_MB", "").strip()
    if not raw:
        return WORKING_MEMORY_MB * 2**20
    try:
        mb = float(raw)
    except ValueError:
        mb = float("nan")
    if not mb > 0 or mb == float("inf"):
        raise InputError(
            "STOCHCABLE_WORKING_MEMORY_MB", raw, "MiB", "must be a positive finite number"
        )
    return int(mb * 2**20)


@contextlib.contextmanager
def frequency_block(size: int | None) -> Iterator[None]:
    """Fix the number of frequencies per block inside the block (None: from the
    working-memory target).  Context-local: other threads keep their own.

    Raises
    ------
    InputError
        ``size`` is not a positive integer.
    """
    if size is not None and (isinstance(size, bool) or not isinstance(size, int) or size < 1):
        raise InputError("size", size, "-", "must be a positive integer (frequencies per block)")
    token = _FORCED.set(size)
    try:
        yield
    finally:
        _FORCED.reset(token)


def whole_grid(freq: slice | object, n_omega: int) -> bool:
    """Whether ``freq`` (a slice, or an index array: never) selects all ``n_omega``
    frequencies in order (``slice(None)`` or the one block of :func:`frequency_slices`)."""
    if not isinstance(freq, slice):
        return False
    return freq.indices(n_omega) == (0, n_omega, 1)


def frequency_slices(n_omega: int, bytes_per_frequency: float) -> list[slice]:
    """Consecutive slices covering ``range(n_omega)``, each costing at most the
    working-memory target (at least one frequency per slice).

    Parameters
    ----------
    n_omega : int
        Number of frequencies.
    bytes_per_frequency : float
        Temporaries one frequency costs in the caller. [bytes]

    Returns
    -------
    list of slice
    """
    size = _FORCED.get()
    if size is None:
        size = max(1, int(working_memory_bytes() // max(float(bytes_per_frequency), 1.0)))
    return [slice(i, min(i + size, n_omega)) for i in range(0, max(n_omega, 1), size)]
