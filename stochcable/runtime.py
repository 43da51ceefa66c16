"""Process-wide runtime settings, explicit: BLAS threads, the allocator, OpenMP's wait
policy, and the thread pool for per-line work.

The library changes nothing in the process by itself.  :func:`configure` applies the
settings that make small frequency-domain analyses fast; the command line
(``stochcable ...``) and the HTTP service call it once at start, a library user calls it
(or not) when the host application agrees::

    import stochcable.runtime
    stochcable.runtime.configure()          # the CLI's and the service's settings

What :func:`configure` does (each switch can be turned off):

- ``small_model_blas``: every :func:`stochcable.analyze` of a scene whose largest line
  has at most :data:`SMALL_MODEL_DOF` degrees of freedom runs with one BLAS thread
  (:func:`single_blas_thread`, restored when the analysis returns).  The engine's dense
  linear algebra is small (eigenproblems, LU and products of at most a few hundred
  rows, per line); multi-threaded OpenBLAS makes such calls slower even on a quiet
  machine and 5–10× slower when the cores are busy (docs/BENCHMARKS.md).
- ``allocator``: glibc's heap top pad and mmap threshold (``mallopt``) are set to
  :data:`MALLOC_TOP_PAD` and :data:`MALLOC_MMAP_THRESHOLD` so that the freed temporaries
  of one drag iteration stay mapped for the next instead of being zero-filled again by
  the kernel (page faults were a third of the chain analysis; in a Dask worker, whose
  nanny sets ``MALLOC_TRIM_THRESHOLD_``, ≈ 400 faults a case and 10–30 % of its time).
  Linux/glibc only; ``STOCHCABLE_MALLOC_TUNING=0`` leaves the allocator alone, an
  explicit ``MALLOC_TOP_PAD_`` or ``MALLOC_MMAP_THRESHOLD_`` that setting.
- ``omp_wait_policy``: ``OMP_WAIT_POLICY=PASSIVE`` unless the environment chose one.
  pyfftw's FFTW threads run through OpenMP (libgomp); with the default policy the worker
  thread spins after every parallel transform and takes the second core from the
  caller's next NumPy work (a 2^20-sample realization: 10.9–12 ms median instead of
  9.1–9.8 ms on a 2-core machine).  It takes effect only if no OpenMP runtime is loaded
  yet: call :func:`configure` before the first realization.

Without :func:`configure`, analyses run with the process's BLAS threads, the default
allocator and the default OpenMP policy: the same numbers (round-off apart: a BLAS
thread count changes summation orders at ≈ 1e-13 relative), possibly slower.

Thread pool for per-line work
-----------------------------
Per-line work of a coupled group on a small thread pool (the speed of scenes with bodies).

The lines of a coupled group are independent inside one drag-linearization
evaluation until the body solve.  :func:`line_map` can run such per-line work on a
module-level thread pool, created on first use.  It is used for the lines' Foss
decompositions (:func:`stochcable.dynamics.groups.modal_parts.foss_state`): LAPACK ``geev``
through NumPy releases the GIL, so two cores overlap the lines' eigenproblems.

Opt-in
------
``STOCHCABLE_THREADS`` (environment variable, read at every call) is the number of
threads per map, the caller included; default 1: no pool.  Measured on the 2-core
benchmark machine (docs/BENCHMARKS.md "Bodies", pass E4): with 2 threads the
three-leg analysis is ≈ 3–9 % faster in wall time when the other core is idle, for
≈ 15 % more CPU time, and slower when the machine is busy (the pool threads then
share one core); pooling the rest of the per-line work (many small NumPy steps that
hold the GIL) or the lines' models did not pay.  Set ``STOCHCABLE_THREADS=2`` on a
machine with idle cores.

When the pool is used
---------------------
Only when all of these hold (else the plain loop, in the calling thread):

- more than one item and ``STOCHCABLE_THREADS`` > 1 (at most that many threads);
- BLAS runs single-threaded (inside :func:`single_blas_thread`,
  where ``analyze()`` runs small models, or ``OPENBLAS_NUM_THREADS`` /
  ``OMP_NUM_THREADS`` = 1): a large model parallelizes inside BLAS instead, and
  pool threads each running multi-threaded BLAS would oversubscribe the cores;
- the caller is not itself running an item of a map (no nesting).

The calling thread takes items too (with ``n − 1`` pool workers, n the allowed
threads): no thread idles while an item is left, and no hand-off latency before the
first item.

The service runs one analysis at a time per process (``service/routers/analyses.py``,
``_ANALYSIS_LOCK``), so one process never runs more than ``STOCHCABLE_THREADS``
threads of this pool; with several worker processes (``STOCHCABLE_WORKERS``) leave
it at 1.

Results
-------
Each item is computed by the same code on the same inputs as in the loop, BLAS with
one thread: the results are the same bits as the serial loop (tested).  Results come
back in item order; an exception is raised as the loop would raise it (the first
failing item's, after every item finished).  Warnings issued by
:func:`stochcable.errors.warn` inside an item are shown as usual and reach the
calling thread's :func:`stochcable.errors.collect_warnings` blocks once, in item
order.
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

from stochcable import errors as _errors

if TYPE_CHECKING:
    from concurrent.futures import ThreadPoolExecutor

__all__ = [
    "configure",
    "configured",
    "analysis_blas",
    "single_blas_thread",
    "line_map",
    "thread_count",
    "SMALL_MODEL_DOF",
    "MALLOC_TOP_PAD",
    "MALLOC_MMAP_THRESHOLD",
]

_settings = {"small_model_blas": False, "configured": False}


def configure(
    *, small_model_blas: bool = True, allocator: bool = True, omp_wait_policy: bool = True
) -> None:
    """Apply the process-wide settings of the command line and the service.

    Parameters
    ----------
    small_model_blas : bool
        Run analyses of small models (:data:`SMALL_MODEL_DOF`) with one BLAS thread.
    allocator : bool
        Keep freed temporaries mapped: :data:`MALLOC_TOP_PAD` and
        :data:`MALLOC_MMAP_THRESHOLD` (glibc only).
    omp_wait_policy : bool
        Set ``OMP_WAIT_POLICY=PASSIVE`` unless the environment has a policy.

    Notes
    -----
    Idempotent; a later call with a switch off turns the small-model BLAS limit off
    again (the allocator and environment settings stay as set).
    """
    _settings["small_model_blas"] = bool(small_model_blas)
    _settings["configured"] = True
    if omp_wait_policy:
        os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    if allocator:
        _tune_allocator()


def configured() -> dict[str, bool]:
    """The settings in force: ``{"configured", "small_model_blas"}``."""
    return dict(_settings)


def analysis_blas(small: bool) -> contextlib.AbstractContextManager[None]:
    """The BLAS context of one analysis: one thread when :func:`configure` asked for it
    and the model is ``small``, else the process's setting unchanged."""
    return single_blas_thread(small and _settings["small_model_blas"])


# ------------------------------------------------------------------ BLAS threads
#
# The engine's dense linear algebra is small (eigenproblems, LU and products of at most
# a few hundred rows, per line).  Multi-threaded OpenBLAS makes such calls slower even on
# a quiet machine and 5-10x slower when the cores are busy (docs/BENCHMARKS.md
# "Response analysis"), so the analysis of small models runs with one BLAS thread
# (threadpoolctl, applied to numpy's and scipy's OpenBLAS alike).

#: Largest model (degrees of freedom of the largest line, 3 per node) analysed with
#: one BLAS thread under :func:`configure`.
SMALL_MODEL_DOF = 2000

_blas_lock = threading.Lock()
_blas_state: dict[str, Any] = {"depth": 0, "limiter": None, "controller": None, "modules": -1}


def _blas_controller() -> Any:
    """The BLAS libraries of the process (a ``threadpoolctl.ThreadpoolController``
    restricted to user_api "blas"), cached; re-scanned when modules were imported
    since the last scan (an extension module may load another BLAS copy).  The scan
    reads /proc/self/maps (≈ 1.3 ms on the reference chain, 5 % of an analysis), the
    cached controller's limit costs ≈ 15 µs.  Call with ``_blas_lock`` held."""
    import sys

    n_mod = len(sys.modules)
    if _blas_state["controller"] is None or _blas_state["modules"] != n_mod:
        from threadpoolctl import ThreadpoolController

        _blas_state["controller"] = ThreadpoolController().select(user_api="blas")
        _blas_state["modules"] = n_mod
    return _blas_state["controller"]


def _release_openblas(ctl: Any) -> None:
    """Let any thread set the OpenBLAS limits again: threadpoolctl >= 3.8 gives one
    thread at a time control of OpenBLAS's process-wide pool and releases it only in
    ``__exit__`` of its own context managers; ``single_blas_thread`` counts its entries
    across threads itself, so it takes and releases control explicitly (before, the
    first thread that ever limited kept control for good and analyses in service
    worker threads silently ran with all BLAS threads)."""
    for lib in ctl.lib_controllers:
        clear = getattr(type(lib), "clear_controlling_thread", None)
        if clear is not None:
            clear(force=True)


def _limit_blas() -> Any:
    """Limit every BLAS library to one thread; returns the limiter (None when they
    all ran single-threaded already or without threadpoolctl).  Call with
    ``_blas_lock`` held."""
    try:
        ctl = _blas_controller()
        if all(lib.num_threads == 1 for lib in ctl.lib_controllers):
            return None  # nothing to limit (e.g. OPENBLAS_NUM_THREADS=1)
        _release_openblas(ctl)
        limiter = ctl.limit(limits=1, user_api="blas")
        if any(lib.num_threads != 1 for lib in ctl.lib_controllers):
            # the cached controller could not limit (unexpected): the previous,
            # slower way, a fresh scan of the loaded libraries
            limiter.restore_original_limits()
            _release_openblas(ctl)
            from threadpoolctl import threadpool_limits

            limiter = threadpool_limits(limits=1, user_api="blas")
            _blas_state["controller"] = None
        return limiter
    except Exception:  # noqa: BLE001 - no (usable) threadpoolctl: run unlimited
        return None


@contextlib.contextmanager
def single_blas_thread(active: bool = True) -> Iterator[None]:
    """Limit BLAS to one thread inside the block (re-entrant and thread-safe: the first
    entrant sets the limit, the last one to leave restores the previous setting).

    OpenBLAS's pool is process-wide, so the limit holds while any thread is inside;
    the entries are counted here across threads.  History: a fresh
    ``threadpoolctl.threadpool_limits`` per outermost entry (≈ 1.3 ms) used to replace
    a cached controller that "failed to apply the limit from a worker thread"; the
    cause was threadpoolctl's controlling-thread rule (see :func:`_release_openblas`),
    which defeated the fresh limiter too.  Now: a cached controller
    (:func:`_blas_controller`), control taken and released explicitly, the limit
    checked after setting it (tests/test_runtime.py, main and worker threads)."""
    if not active:
        yield
        return
    with _blas_lock:
        if _blas_state["depth"] == 0:
            _blas_state["limiter"] = _limit_blas()
        _blas_state["depth"] += 1
    try:
        yield
    finally:
        with _blas_lock:
            _blas_state["depth"] -= 1
            if _blas_state["depth"] == 0 and _blas_state["limiter"] is not None:
                limiter = _blas_state["limiter"]
                _blas_state["limiter"] = None
                try:
                    ctl = _blas_state["controller"]
                    if ctl is not None:
                        _release_openblas(ctl)
                    limiter.restore_original_limits()
                    if ctl is not None:
                        _release_openblas(ctl)
                except Exception:  # noqa: BLE001 - leave the limit rather than fail
                    pass


# ------------------------------------------------------------------ allocator
#
# The solve works on complex arrays of n_nodes·dim·n_omega·n_channels entries (≈ 0.5 MB
# on the reference chain), fresh temporaries in every iteration.  glibc's malloc hands
# such blocks back to the kernel whenever the top of the heap is freed (trim threshold
# ≈ 2 × the dynamic mmap threshold) and the kernel zero-fills the pages again on the
# next allocation: on the reference chain those page faults were a third of the analysis
# time (≈ 42 → 28 ms, docs/BENCHMARKS.md "Response analysis").  A heap top pad of
# ``MALLOC_TOP_PAD`` keeps that much freed memory mapped instead (process-wide, set once
# by :func:`configure`; glibc only; the environment variable ``STOCHCABLE_MALLOC_TUNING=0``
# or an explicit ``MALLOC_TOP_PAD_`` leaves the allocator alone).
#
# Blocks above the mmap threshold bypass the heap: mapped on allocation, unmapped on
# free, faulted in again every time.  glibc raises the threshold as such blocks are
# freed — unless any malloc parameter was set, by ``mallopt`` (the top pad above) or by
# the environment (a Dask nanny starts its workers with ``MALLOC_TRIM_THRESHOLD_``):
# then it stays wherever it was, 128 KiB in a fresh worker, and a chain case cost ≈ 400
# page faults and 10–30 % more time in a Dask worker than in the main process.  So it is
# set explicitly, to glibc's own ceiling of the dynamic threshold on 64-bit systems.

#: Heap top pad set by :func:`_tune_allocator`. [bytes]
MALLOC_TOP_PAD = 32 * 1024 * 1024
#: mmap threshold set by :func:`_tune_allocator` (glibc's DEFAULT_MMAP_THRESHOLD_MAX on
#: 64-bit systems, the largest value ``mallopt`` accepts). [bytes]
MALLOC_MMAP_THRESHOLD = 32 * 1024 * 1024
_M_TOP_PAD = -2  # mallopt parameter numbers (glibc malloc.h)
_M_MMAP_THRESHOLD = -3
_allocator_state = {"done": False}


def _tune_allocator() -> None:
    """Set glibc's M_TOP_PAD once per process (no effect elsewhere or when disabled)."""
    if _allocator_state["done"]:
        return
    _allocator_state["done"] = True
    import sys

    if not sys.platform.startswith("linux") or os.environ.get("STOCHCABLE_MALLOC_TUNING") == "0":
        return
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
        for env, param, value in (
            ("MALLOC_TOP_PAD_", _M_TOP_PAD, MALLOC_TOP_PAD),
            ("MALLOC_MMAP_THRESHOLD_", _M_MMAP_THRESHOLD, MALLOC_MMAP_THRESHOLD),
        ):
            if env not in os.environ:
                libc.mallopt(ctypes.c_int(param), ctypes.c_int(value))
    except (OSError, AttributeError):  # not glibc (musl, ...): leave malloc alone
        pass


# ------------------------------------------------------------------ thread pool

T = TypeVar("T")
R = TypeVar("R")

_pool: ThreadPoolExecutor | None = None
_pool_size = 0
_pool_lock = threading.Lock()
_worker = threading.local()


def thread_count() -> int:
    """Threads allowed for per-line work: ``STOCHCABLE_THREADS`` (default 1, no pool;
    values < 1 or unreadable mean 1). [-]"""
    raw = os.environ.get("STOCHCABLE_THREADS", "").strip()
    try:
        return max(int(raw), 1) if raw else 1
    except ValueError:
        return 1


def _blas_single() -> bool:
    """BLAS is limited to one thread (process-wide) right now."""
    # the entry count of single_blas_thread (OpenBLAS's limit is process-wide while
    # any thread is inside)
    if _blas_state["depth"] > 0:
        return True
    return any(
        os.environ.get(k, "").strip() == "1" for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")
    )


def _executor(n: int) -> ThreadPoolExecutor:
    global _pool, _pool_size
    # (imported with the first pool: concurrent.futures loads logging, ≈ 4 ms)
    from concurrent.futures import ThreadPoolExecutor

    with _pool_lock:
        if _pool is None or _pool_size < n:
            old = _pool
            _pool = ThreadPoolExecutor(max_workers=n, thread_name_prefix="stochcable-line")
            _pool_size = n
            if old is not None:
                old.shutdown(wait=False)
        return _pool


def _drain(
    fn: Callable[[T], R],
    items: list[T],
    out: list[Any],
    state: dict[str, Any],
    lock: threading.Lock,
) -> None:
    """Take the next unstarted item until none is left (the caller and the workers
    share the items dynamically); each result is (value, exception, warnings)."""
    was = getattr(_worker, "active", False)
    _worker.active = True
    # the caller's own collectors get every item's warnings once, in item order, after
    # the map: hide them while the caller runs items here
    try:
        with _errors.isolated_warnings():
            while True:
                with lock:
                    i = state["next"]
                    state["next"] = i + 1
                if i >= len(items):
                    return
                with _errors.collect_warnings() as caught:
                    try:
                        out[i] = (fn(items[i]), None, caught)
                    except Exception as exc:  # noqa: BLE001 - re-raised by the caller
                        out[i] = (None, exc, caught)
    finally:
        _worker.active = was


def line_map(fn: Callable[[T], R], items: Sequence[T]) -> list[R]:
    """``[fn(x) for x in items]``, on the thread pool when it can pay (module
    docstring: same results, same order, same exceptions, warnings forwarded).

    The calling thread works too: it and ``n − 1`` pool workers (n the allowed
    threads, at most the item count) take the items one by one, so no thread idles
    while an item is left."""
    items = list(items)
    n = min(thread_count(), len(items))
    if n <= 1 or getattr(_worker, "active", False) or not _blas_single():
        return [fn(x) for x in items]
    out: list[Any] = [None] * len(items)
    state = {"next": 0}
    lock = threading.Lock()
    pool = _executor(n - 1)
    futures = [pool.submit(_drain, fn, items, out, state, lock) for _ in range(n - 1)]
    _drain(fn, items, out, state, lock)
    for f in futures:
        f.result()
    for _, _, caught in out:
        _errors.forward_warnings(caught)
    for _, exc, _ in out:
        if exc is not None:
            raise exc
    return [r for r, _, _ in out]


def pool_active() -> bool:
    """True while this thread runs an item of a pooled map (for tests). [-]"""
    return bool(getattr(_worker, "active", False))
