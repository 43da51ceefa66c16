"""Numba kernels compiled once per machine: :func:`jit_cached`.

Kernels are compiled for one explicit signature with ``nogil=True`` and ``cache=True``:
the machine code is stored in ``__pycache__`` next to the kernel's module, in numba's
user cache directory or in ``$NUMBA_CACHE_DIR``, and later processes load it.  Where
none is writable the kernel is compiled in memory in each process (about a second at
its first use) and a :class:`UserWarning` says how to keep it.  Numba is imported here
only, by the modules that hold kernels; those are imported lazily (importing numba
costs ~0.2 s), so ``import stochcable``, the CLI and the service start do not load it.
"""

from __future__ import annotations

import contextlib
import time
import warnings
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from typing import Any

__all__ = [
    "KERNEL_MIN_ENTRIES",
    "SET_KERNEL_MIN_ENTRIES",
    "compile_cpu_seconds",
    "jit_cached",
    "kernel_min_entries",
    "kernels_are_paid",
    "kernels_paid",
    "optional_kernel",
]

#: Problem size (array entries: elements × frequencies × inputs of the variance sums,
#: right-hand-side entries of the banded solves) from which the dynamics use their
#: compiled kernels: loading numba and a kernel costs ≈ 0.3 s once per process, more
#: than NumPy and SciPy spend on the bundled examples (the chain, 40 elements × 200 ω:
#: 10 ms more per analysis without them, against 0.3–0.5 s for the first).
KERNEL_MIN_ENTRIES = 2**16

_PAID: ContextVar[bool] = ContextVar("stochcable_kernels_paid", default=False)


#: The same inside :func:`kernels_paid` (a load-case set's chunk), where numba's import
#: is paid once for every case: the taut wire's banded jobs (its residuals' adjoint rows
#: without the node motions', 64,638 entries; its direct fixed point's solves, 7,600)
#: take the kernels, Tuah's single leg's (3,780 and 800: a few µs a case to gain) do
#: not, and its set loads no numba. [-]
SET_KERNEL_MIN_ENTRIES = 2**12


def kernel_min_entries() -> int:
    """The problem size from which the banded LU takes its compiled kernels here
    (:func:`stochcable.dynamics.model.band_lu.compiled_band_lu`):
    :data:`KERNEL_MIN_ENTRIES`, or :data:`SET_KERNEL_MIN_ENTRIES` inside
    :func:`kernels_paid`. [-]"""
    return SET_KERNEL_MIN_ENTRIES if _PAID.get() else KERNEL_MIN_ENTRIES


def kernels_are_paid() -> bool:
    """Whether this runs inside :func:`kernels_paid` (a load-case set's chunk): the
    drag fixed point's direct solves then take the compiled banded LU too
    (:func:`stochcable.dynamics.solve.line_solve.solve_free`)."""
    return _PAID.get()


@contextlib.contextmanager
def kernels_paid() -> Iterator[None]:
    """The banded LU takes its compiled kernels (where numba is available) from
    :data:`SET_KERNEL_MIN_ENTRIES` on, and the drag fixed point's direct solves take
    them too (:func:`kernels_are_paid`): for work that solves many sea states on one
    engine (a load-case set's chunk, :func:`stochcable.cases.chunk.solve_chunk`), which
    pays numba's import once for all of them.  Set by the caller, never by process
    state, so the same work takes the same path, to the bit, in any process.  (The
    taut wire's computed case in a set: its residuals' adjoint rows, 189 lines × 38
    DOFs × 9 rows without the node motions', just under :data:`KERNEL_MIN_ENTRIES`,
    cost ≈ 1 ms more by LAPACK's stacked ``gbsv``; the variance sums' kernel measured
    no faster at a set's sizes, so it keeps its threshold.)"""
    token = _PAID.set(True)
    try:
        yield
    finally:
        _PAID.reset(token)


_KERNELS: dict[tuple[str, str], Any] = {}
_COMPILE_CPU_S = [0.0]  # (compile_cpu_seconds)


def optional_kernel(module: str, name: str) -> Any:
    """The kernel ``name`` of ``module``, imported on first use (importing numba costs
    ~0.2 s); None without numba or with ``STOCHCABLE_NUMBA=0`` (the caller's NumPy or
    SciPy path then).  The environment variable is read at every call, the import once.
    """
    import os

    if os.environ.get("STOCHCABLE_NUMBA", "").strip() == "0":
        return None
    key = (module, name)
    if key not in _KERNELS:
        import importlib

        try:
            _KERNELS[key] = getattr(importlib.import_module(module), name)
        except ImportError:
            _KERNELS[key] = None
    return _KERNELS[key]


def jit_cached(
    function: Callable[..., Any], signature: Any, what: str
) -> tuple[Callable[..., Any], bool]:
    """``function`` compiled by numba for ``signature``, cached on disk where possible.

    Parameters
    ----------
    function : callable
        A numba-compilable Python function.
    signature : numba signature
        The one signature compiled (arrays declared read-only accept writable ones).
    what : str
        What the kernel computes, for the warning without a cache directory.

    Returns
    -------
    kernel : callable
        The compiled dispatcher.
    cached : bool
        Whether its machine code is kept on disk.
    """
    start = time.process_time()
    import numba

    try:
        return numba.njit(signature, nogil=True, cache=True)(function), True
    except RuntimeError as exc:  # "cannot cache function ...: no locator available ..."
        if "cache" not in str(exc):
            raise
        warnings.warn(
            f"stochcable: no writable numba cache directory ({exc}); the {what} kernel "
            "is compiled in memory in each process (~1 s at its first use); set "
            "NUMBA_CACHE_DIR to a writable directory to keep it",
            UserWarning,
            stacklevel=3,
        )
        return numba.njit(signature, nogil=True)(function), False
    finally:
        _COMPILE_CPU_S[0] += time.process_time() - start


def compile_cpu_seconds() -> float:
    """CPU time this process has spent in :func:`jit_cached`: compiling kernels or
    loading them from the cache (the test suite's fast-tier guard
    leaves it out of a test's cost: it is the machine's first use, not the test's
    work). [s]"""
    return _COMPILE_CPU_S[0]
