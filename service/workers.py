"""Analyses in worker processes: a pool that replaces single workers.

Every analysis runs in a worker process, one analysis per worker at a time; the HTTP
process sends the scene document (the validated model, pickled) and gets back the
encoded result document (bytes) or the error answer, never arrays.  At most
``analysis_workers`` analyses run at once; up to ``max_queue`` more wait for a worker
(beyond that :class:`~service.errors.QueueFull`, 503 with ``Retry-After``).

Why a pool of its own rather than :class:`concurrent.futures.ProcessPoolExecutor` or
:class:`multiprocessing.pool.Pool`: the service must (1) stop one analysis at its run
limit by ending its process, (2) survive a worker killed by the kernel's OOM killer or
an operator, failing only that worker's request, and (3) replace that one worker.  A
ProcessPoolExecutor whose worker dies becomes *broken*: every pending and running
future fails with ``BrokenProcessPool`` and the executor must be rebuilt, so one
death costs every in-flight request; and it has no way to end one running task.
``multiprocessing.Pool`` replaces a dead worker but never fails the task it was
running (its ``AsyncResult`` waits forever), and cannot end one task either.  The pool
here is built from the well-kept parts those two are built from:
:class:`multiprocessing.Process` workers in the ``forkserver`` context, one
:func:`multiprocessing.Pipe` each, and :func:`multiprocessing.connection.wait` on the
pipe and the process sentinel.

How a request runs (:meth:`WorkerPool.run`): the event loop takes an idle worker (or
waits, bounded by the queue and the deadline); a thread sends the job and waits on the
worker's pipe and its sentinel with the remaining time as timeout.  An answer is
returned; the sentinel firing first means the worker died (:class:`WorkerLost`, 503);
the timeout means the run limit: the worker is killed (SIGKILL: the operating system
ends the work wherever it is, and its memory returns to the system) and the request
answers 504.  A dead or killed worker, or one that hit ``MemoryError`` or keeps more
than ``worker_recycle_bytes`` resident after an analysis, is replaced by a new
process; the other workers and their requests are untouched.

Warm workers: the fork server imports the engine once (``_PRELOAD``) and forks every
worker from it, so a new worker starts in milliseconds with the imports done; each
worker then calls :func:`stochcable.runtime.configure`, limits BLAS to one thread
(the pool is the parallelism) and sets its address-space limit (``RLIMIT_AS``: its
imported size plus twice the memory budget) as the last line of defence behind the
cost estimate: an allocation beyond it is a ``MemoryError`` in the worker (answered
422, the worker replaced), not the OOM killer.
"""

from __future__ import annotations

import asyncio
import logging
import multiprocessing
import os
import signal
import threading
import time
import warnings
from collections import deque
from collections.abc import Callable
from multiprocessing.connection import Connection, wait
from typing import Any

import anyio

from .errors import JobFailed, QueueFull, RunTimeExceeded, WorkerLost, error_answer

__all__ = ["WorkerPool", "WORKER_NICENESS"]

_log = logging.getLogger("stochcable.service")

_PRELOAD = [
    "numpy",
    "scipy.linalg",
    "scipy.sparse",
    "scipy.sparse.linalg",
    "scipy.special",
    "scipy.interpolate",
    "stochcable.analysis",
    "stochcable.dynamics.engine",
    "stochcable.statics",
    "service.jobs",
]
"""Modules the fork server imports once, so that every worker starts with them."""

WORKER_NICENESS = 5
"""CPU priority step of the workers below the HTTP process (``os.nice``): on a machine
whose cores the workers fill, the event loop answering /health and small requests is
scheduled first."""

_ONE_THREAD = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def _worker_main(
    conn: Connection, address_space_extra: int, recycle_bytes: int, niceness: int
) -> None:
    """The loop of one worker process: receive ``(func, args)``, answer, repeat."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the server ends its workers itself
    if niceness > 0:
        os.nice(niceness)  # the HTTP process (light requests, answers) goes first
    import psutil
    import threadpoolctl

    from stochcable import runtime

    runtime.configure()
    threadpoolctl.threadpool_limits(1)
    # the warnings of an analysis are in its result document, not the server's log
    warnings.simplefilter("ignore")
    _warm_up()
    proc = psutil.Process()
    conn.send("ready")
    if address_space_extra > 0:
        import resource

        limit = proc.memory_info().vms + address_space_extra
        _, hard = resource.getrlimit(resource.RLIMIT_AS)
        if hard != resource.RLIM_INFINITY:
            limit = min(limit, hard)
        resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        func, args = message
        recycle = False
        try:
            answer: tuple[Any, ...] = ("ok", func(*args))
        except BaseException as exc:  # noqa: BLE001 - every failure becomes an answer
            recycle = isinstance(exc, MemoryError)
            status, item, headers = error_answer(exc)
            if status >= 500:
                _log.error("analysis failed in a worker", exc_info=True)
            answer = ("error", status, item, headers)
            del exc
        recycle = recycle or proc.memory_info().rss > recycle_bytes
        try:
            conn.send((answer, recycle))
        except (OSError, ValueError):
            return
        if recycle:
            return


def _warm_up() -> None:
    """One small analysis: the first request finds caches, plans and lazy imports ready."""
    try:
        from stochcable.analysis import analyze
        from stochcable.examples import load_example

        analyze(load_example("tuah_1982_single_leg")).to_document()
    except Exception:  # noqa: BLE001 - a failed warm-up only costs the first request time
        _log.warning("worker warm-up failed", exc_info=True)


class _Worker:
    """One worker process and the parent's end of its pipe."""

    def __init__(self, ctx: Any, address_space_extra: int, recycle_bytes: int) -> None:
        self.conn, child = ctx.Pipe(duplex=True)
        self.process = ctx.Process(
            target=_worker_main,
            args=(child, address_space_extra, recycle_bytes, WORKER_NICENESS),
            name="stochcable-worker",
            daemon=True,
        )
        self.process.start()
        child.close()
        self.ready = False

    def wait_ready(self, timeout: float) -> bool:
        """Wait for the worker's "ready" (imports and warm-up done); False if it died."""
        if not self.ready:
            if not wait([self.conn, self.process.sentinel], timeout):
                return False
            try:
                self.ready = self.conn.recv() == "ready"
            except (EOFError, OSError):
                return False
        return self.ready

    @property
    def pid(self) -> int | None:
        return self.process.pid

    def stop(self, kill: bool = False) -> None:
        """End the process (ask, then kill) and release its pipe."""
        if self.process.is_alive():
            if kill:
                self.process.kill()
            else:
                try:
                    self.conn.send(None)
                except (OSError, ValueError):
                    pass
                self.process.join(1.0)
                if self.process.is_alive():
                    self.process.kill()
        self.process.join(5.0)
        self.conn.close()


_FIRST_START = threading.Lock()
_FORKSERVER_STARTED = False


def _first_worker(ctx: Any, address_space_extra: int, recycle_bytes: int) -> _Worker:
    """The first worker of the process: it starts the fork server, which inherits the
    environment then; with one BLAS thread it holds no OpenBLAS threads when it forks."""
    global _FORKSERVER_STARTED
    saved = {k: os.environ.get(k) for k in _ONE_THREAD}
    os.environ.update(_ONE_THREAD)
    try:
        worker = _Worker(ctx, address_space_extra, recycle_bytes)
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    _FORKSERVER_STARTED = True
    return worker


class WorkerPool:
    """Worker processes running one computation each, replaced one at a time.

    Parameters
    ----------
    size : int
        Number of worker processes (analyses running at once). [-]
    max_queue : int
        Requests that may wait for a worker; more answer 503. [-]
    memory_budget : int
        Budget of one analysis; a worker's address-space limit is its imported size
        plus twice this. [bytes]
    recycle_bytes : int
        A worker keeping more than this resident after a computation is replaced. [bytes]
    retry_after : int
        ``Retry-After`` of a 503 for a full queue. [s]
    start_method : {"forkserver", "fork"}
        How workers start: from the warm fork server (clean imports), or forked from
        this process (they inherit its state: tests that patch the library).
    """

    def __init__(
        self,
        size: int,
        max_queue: int,
        memory_budget: int,
        recycle_bytes: int,
        retry_after: int = 1,
        start_method: str = "forkserver",
    ) -> None:
        self.start_method = start_method
        self.size = size
        self.max_queue = max_queue
        self.address_space_extra = 2 * memory_budget
        self.recycle_bytes = recycle_bytes
        self.retry_after = retry_after
        self._lock = threading.Lock()
        self._workers: list[_Worker] = []
        self._idle: list[_Worker] = []
        self._waiters: deque[asyncio.Future[_Worker]] = deque()
        self._ctx: Any = None
        self._closed = False
        self._threads = anyio.CapacityLimiter(max(size, 1))
        self.replaced = 0
        """Workers replaced so far (died, killed at the run limit or recycled)."""

    @property
    def busy(self) -> int:
        """Workers not idle: running a computation, or starting (on first demand, for
        a request then counted in :attr:`waiting` until it is handed over). [-]"""
        with self._lock:
            return len(self._workers) - len(self._idle)

    @property
    def waiting(self) -> int:
        """Requests queued for a worker. [-]"""
        with self._lock:
            return len(self._waiters)

    # ------------------------------------------------------------ processes

    def _context(self) -> Any:
        if self._ctx is None:
            ctx = multiprocessing.get_context(self.start_method)
            if self.start_method == "forkserver":
                ctx.set_forkserver_preload(_PRELOAD)
            self._ctx = ctx
        return self._ctx

    def _spawn(self) -> _Worker:
        """A new worker (the first one starts the fork server, with one BLAS thread)."""
        ctx = self._context()
        with _FIRST_START:
            if _FORKSERVER_STARTED or self.start_method != "forkserver":
                worker = _Worker(ctx, self.address_space_extra, self.recycle_bytes)
            else:
                worker = _first_worker(ctx, self.address_space_extra, self.recycle_bytes)
        with self._lock:
            self._workers.append(worker)
        return worker

    def start(self) -> None:
        """Start every worker now and wait until they are warm (else they start on
        first demand); the workers warm up in parallel."""
        with self._lock:
            missing = 0 if self._closed else self.size - len(self._workers)
        started = [self._spawn() for _ in range(missing)]
        for worker in started:
            worker.wait_ready(120.0)
            self._release(worker)

    def close(self) -> None:
        """Stop every worker (idle ones asked to end, busy ones killed); a later
        computation starts new ones."""
        with self._lock:
            self._closed = True
            workers, idle = list(self._workers), list(self._idle)
            self._workers, self._idle = [], []
        for w in workers:
            w.stop(kill=w not in idle)
        with self._lock:
            self._closed = False  # a later demand starts new workers

    def pids(self) -> list[int]:
        """Process ids of the current workers."""
        with self._lock:
            return [w.pid for w in self._workers if w.pid is not None]

    # ------------------------------------------------------------ scheduling

    def _release(self, worker: _Worker) -> None:
        """Give a free worker to the first waiting request, or mark it idle."""
        with self._lock:
            if worker not in self._workers:  # of a closed pool: end it, hand nothing over
                threading.Thread(target=worker.stop, daemon=True).start()
                return
            while self._waiters:
                fut = self._waiters.popleft()
                if not fut.done():
                    fut.get_loop().call_soon_threadsafe(_hand_over, fut, worker, self)
                    return
            self._idle.append(worker)

    def _retire(self, worker: _Worker, kill: bool) -> None:
        """Stop a worker and start its replacement (in a thread: process start blocks)."""
        with self._lock:
            current = worker in self._workers  # not if the pool was closed meanwhile
            if current:
                self._workers.remove(worker)
            self.replaced += 1
        worker.stop(kill=kill)
        if current and not self._closed:
            self._release(self._spawn())

    async def _acquire(self, deadline: float, limit: float) -> _Worker:
        grow = False
        with self._lock:
            if self._idle:
                return self._idle.pop()
            if len(self._workers) < self.size:
                grow = True
            elif len(self._waiters) >= self.max_queue:
                raise QueueFull(self.max_queue, self.retry_after)
            fut: asyncio.Future[_Worker] = asyncio.get_running_loop().create_future()
            self._waiters.append(fut)
        if grow:
            await anyio.to_thread.run_sync(lambda: self._release(self._spawn()))
        try:
            return await asyncio.wait_for(fut, max(deadline - time.monotonic(), 0.0))
        except BaseException as exc:  # timed out, or the request was cancelled
            with self._lock:
                if fut in self._waiters:
                    self._waiters.remove(fut)
            if fut.done() and not fut.cancelled() and fut.exception() is None:
                self._release(fut.result())  # handed over as the wait ended: pass it on
            if isinstance(exc, asyncio.TimeoutError):
                raise RunTimeExceeded(limit) from None
            raise

    # ------------------------------------------------------------ running

    async def run(self, func: Callable[..., Any], *args: Any, deadline: float, limit: float) -> Any:
        """``func(*args)`` in a worker process, by ``deadline`` (time.monotonic()).

        Returns what ``func`` returned.  Raises JobFailed (the worker's error answer),
        WorkerLost (503), QueueFull (503) or RunTimeExceeded (504, ``limit`` seconds).
        """
        worker = await self._acquire(deadline, limit)
        outcome = await anyio.to_thread.run_sync(
            _exchange, worker, func, args, deadline, limiter=self._threads
        )
        kind = outcome[0]
        if kind == "done":
            (answer, recycle) = outcome[1]
            if recycle:
                await anyio.to_thread.run_sync(self._retire, worker, False)
            else:
                self._release(worker)
            if answer[0] == "ok":
                return answer[1]
            raise JobFailed(answer[1], answer[2], answer[3])
        await anyio.to_thread.run_sync(self._retire, worker, True)
        if kind == "timeout":
            raise RunTimeExceeded(limit)
        raise WorkerLost(outcome[1])


def _hand_over(fut: asyncio.Future[_Worker], worker: _Worker, pool: WorkerPool) -> None:
    if fut.done():  # the waiter timed out meanwhile: the worker goes to the next one
        pool._release(worker)
    else:
        fut.set_result(worker)


def _exchange(
    worker: _Worker, func: Callable[..., Any], args: tuple[Any, ...], deadline: float
) -> tuple[Any, ...]:
    """Send the job and wait for the answer, the worker's death or the deadline."""
    worker.wait_ready(max(deadline - time.monotonic(), 0.0))
    try:
        worker.conn.send((func, args))
    except (OSError, ValueError):
        worker.process.join(1.0)
        return ("dead", worker.process.exitcode)
    timeout = max(deadline - time.monotonic(), 0.0)
    ready = wait([worker.conn, worker.process.sentinel], timeout)
    if worker.conn in ready:
        try:
            return ("done", worker.conn.recv())
        except (EOFError, OSError):
            pass
    if not ready:
        worker.process.kill()  # the run limit: the OS ends the work, memory returns
        worker.process.join(5.0)
        return ("timeout",)
    worker.process.join(5.0)
    return ("dead", worker.process.exitcode)
