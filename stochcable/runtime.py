"""Per-line work of a coupled group on a small thread pool (issue 6, bodies speed).

The lines of a coupled group are independent inside one drag-linearization
evaluation until the body solve.  :func:`line_map` can run such per-line work on a
module-level thread pool, created on first use.  It is used for the lines' Foss
decompositions (:func:`stochcable.dynamics.coupled._foss_state`): LAPACK ``geev``
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
- BLAS runs single-threaded (inside :func:`stochcable.dynamics.line._single_blas_thread`,
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

import os
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any, TypeVar

from stochcable import errors as _errors

__all__ = ["line_map", "thread_count"]

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
    from stochcable.dynamics import line as analysis

    # the entry count of analysis._single_blas_thread (OpenBLAS's limit is
    # process-wide while any thread is inside)
    if getattr(analysis, "_blas_state", {}).get("depth", 0) > 0:
        return True
    return any(os.environ.get(k, "").strip() == "1"
               for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"))


def _executor(n: int) -> ThreadPoolExecutor:
    global _pool, _pool_size
    with _pool_lock:
        if _pool is None or _pool_size < n:
            old = _pool
            _pool = ThreadPoolExecutor(max_workers=n, thread_name_prefix="stochcable-line")
            _pool_size = n
            if old is not None:
                old.shutdown(wait=False)
        return _pool


def _drain(fn: Callable[[T], R], items: list[T], out: list[Any], state: dict[str, Any],
           lock: threading.Lock) -> None:
    """Take the next unstarted item until none is left (the caller and the workers
    share the items dynamically); each result is (value, exception, warnings)."""
    was = getattr(_worker, "active", False)
    _worker.active = True
    # the caller's own collectors get every item's warnings once, in item order, after
    # the map: hide them while the caller runs items here
    sinks = getattr(_errors._local, "sinks", None)
    _errors._local.sinks = []
    try:
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
        _errors._local.sinks = sinks


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
    sinks = getattr(_errors._local, "sinks", None) or ()
    for _, _, caught in out:
        for sink in sinks:
            sink.extend(caught)
    for _, exc, _ in out:
        if exc is not None:
            raise exc
    return [r for r, _, _ in out]


def pool_active() -> bool:
    """True while this thread runs an item of a pooled map (for tests). [-]"""
    return bool(getattr(_worker, "active", False))

