"""Resource limits: sizes of a request, body size, concurrency and run time.

Policy (documented in the README "Service" section):

* a request body over ``max_body_bytes`` answers **413**, checked on ``Content-Length``
  and again on the bytes actually streamed (chunked uploads);
* a well-formed request whose work exceeds a size bound (``max_samples``,
  ``max_frequencies``, ``max_points``, ``max_elements``) answers **422** with
  ``type: "limit_exceeded"``, naming the bound and its environment variable;
* an analysis whose estimated peak memory (:func:`stochcable.estimate_cost`) exceeds
  ``max_memory_bytes`` answers **422** ``limit_exceeded`` before any work starts, naming
  the estimate and the inputs to reduce;
* analyses run in worker processes (:mod:`service.workers`): at their run limit the
  worker is killed and replaced (**504**), a full queue answers **503**;
* the light computations (spectra, realizations) run in threads, at most
  ``max_concurrency`` at once per process (the rest queue); a request whose queueing
  plus computation exceeds ``max_run_seconds`` answers **504** ``type:
  "run_time_exceeded"``.  Python cannot stop a thread: the computation finishes in the
  background but keeps its concurrency slot until then, so an overloaded server sheds
  load instead of piling up work (these are bounded by ``max_samples`` and
  ``max_frequencies`` to well under a second).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import math
import time
from collections.abc import Callable
from typing import Any, TypeVar

import anyio
import numpy as np
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from stochcable.cost import estimate_cost
from stochcable.errors import StochcableError

from .errors import BodyTooLarge, LimitExceeded, NumericalError, RunTimeExceeded, error_response
from .settings import Settings

__all__ = [
    "BodySizeLimitMiddleware",
    "ServerTimingMiddleware",
    "check_samples",
    "check_frequencies",
    "check_points",
    "check_elements",
    "check_scene",
    "check_memory",
    "sample_count",
    "Runner",
    "checked_call",
]

T = TypeVar("T")
_log = logging.getLogger("stochcable.service")


# ----------------------------------------------------------------- size checks


def sample_count(duration: float, dt: float) -> int:
    """Number of samples duration/dt of a record, rounded to the nearest integer. [-]"""
    return int(round(duration / dt)) if math.isfinite(duration / dt) else 2**63


def check_samples(duration: float, dt: float, n_points: int, settings: Settings) -> int:
    """Raise LimitExceeded when duration/dt (× points) exceeds ``max_samples``."""
    n = sample_count(duration, dt)
    if n > settings.max_samples:
        raise LimitExceeded(
            "duration", duration, settings.max_samples, "max_samples", f"duration/dt = {n} samples"
        )
    if n_points > 1 and n * n_points > settings.max_samples:
        raise LimitExceeded(
            "points",
            n_points,
            settings.max_samples,
            "max_samples",
            f"duration/dt × points = {n} × {n_points} = {n * n_points} kinematics samples",
        )
    return n


def check_frequencies(count: int, settings: Settings, parameter: str = "omega.count") -> None:
    """Raise LimitExceeded when a frequency grid is larger than ``max_frequencies``."""
    if count > settings.max_frequencies:
        raise LimitExceeded(
            parameter,
            count,
            settings.max_frequencies,
            "max_frequencies",
            f"{parameter} = {count} frequencies",
        )


def check_points(count: int, settings: Settings) -> None:
    """Raise LimitExceeded when more than ``max_points`` kinematics points are asked."""
    if count > settings.max_points:
        raise LimitExceeded("points", count, settings.max_points, "max_points", f"{count} points")


def check_elements(count: int, settings: Settings) -> None:
    """Raise LimitExceeded when a scene has more finite elements than ``max_elements``.

    For ``POST /v1/analyses``: ``check_elements(sum(line.elements for line in
    scene.lines), settings)``.
    """
    if count > settings.max_elements:
        raise LimitExceeded(
            "lines", count, settings.max_elements, "max_elements", f"{count} finite elements"
        )


def check_scene(scene: Any, settings: Settings) -> None:
    """Raise LimitExceeded when an analysis scene asks for more work than the bounds.

    Checked before solving, in this order: total finite elements of all lines
    (``max_elements``), the analysis frequency count ``analysis.omega.count``
    (``max_frequencies``), the estimated peak memory (``max_memory_bytes``) and the
    time-series length ``analysis.timeseries.duration / dt`` (``max_samples``).
    """
    check_elements(sum(line.elements for line in scene.lines), settings)
    check_frequencies(scene.analysis.omega.count, settings, "analysis.omega.count")
    check_memory(scene, settings)
    ts = scene.analysis.timeseries
    if ts is not None:
        n = sample_count(ts.duration, ts.dt)
        if n > settings.max_samples:
            raise LimitExceeded(
                "analysis.timeseries.duration",
                ts.duration,
                settings.max_samples,
                "max_samples",
                f"analysis.timeseries duration/dt = {n} samples",
            )


RUN_TIME_MARGIN = 10.0
"""An analysis whose estimated run time exceeds this many times ``max_run_seconds`` is
refused before it starts (the estimate is of the calibration machine; the margin covers
slower machines and the estimate's spread, so only hopeless requests are refused). [-]"""


def check_memory(scene: Any, settings: Settings) -> None:
    """Raise LimitExceeded when the scene's estimated cost exceeds the budgets.

    The estimate is :func:`stochcable.estimate_cost` (sizes only, nothing allocated):
    its peak memory against ``max_memory_bytes`` (:attr:`Settings.memory_budget`), then
    its run time against :data:`RUN_TIME_MARGIN` × ``max_run_seconds``.
    """
    estimate = estimate_cost(scene)
    budget = settings.memory_budget
    if estimate.memory_bytes > budget:
        raise LimitExceeded(
            estimate.parameter,
            None,
            budget,
            "max_memory_bytes",
            f"the analysis's {estimate.describe()} = {estimate.memory_bytes} bytes",
            hint=estimate.reduce_hint(),
        )
    limit = settings.max_run_seconds
    if estimate.seconds > RUN_TIME_MARGIN * limit:
        raise LimitExceeded(
            estimate.parameter,
            None,
            limit,
            "max_run_seconds",
            "",
            message=f"the analysis's estimated run time {estimate.seconds:.3g} s is more "
            f"than {RUN_TIME_MARGIN:g} times the run limit of {limit:g} s "
            f"({Settings.env_name('max_run_seconds')}); {estimate.reduce_hint()}",
        )


# ------------------------------------------------------------------ body size


class BodySizeLimitMiddleware:
    """ASGI middleware answering 413 to bodies over ``max_bytes``.

    ``Content-Length`` is checked before the application runs; the streamed size is
    counted while the application reads, so a chunked or lying upload is cut at the
    limit too (the application sees :class:`BodyTooLarge`, mapped to 413).
    """

    def __init__(self, app: ASGIApp, max_bytes: int) -> None:
        self.app = app
        self.max_bytes = max_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        for key, value in scope.get("headers", ()):
            if key == b"content-length":
                try:
                    size = int(value)
                except ValueError:
                    size = None
                if size is not None and size > self.max_bytes:
                    exc = BodyTooLarge(size, self.max_bytes)
                    resp = error_response(
                        413,
                        ["body"],
                        str(exc),
                        "body_too_large",
                        limit=self.max_bytes,
                        setting=exc.env,
                    )
                    await resp(scope, receive, send)
                    return
        received = 0
        started = False
        limit = self.max_bytes

        async def limited_receive() -> Message:
            nonlocal received
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > limit:
                    raise BodyTooLarge(None, limit)
            return message

        async def watched_send(message: Message) -> None:
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, limited_receive, watched_send)
        except BodyTooLarge as exc:  # read outside FastAPI's handlers: answer here
            if started:
                raise
            resp = error_response(
                413, ["body"], str(exc), "body_too_large", limit=exc.limit, setting=exc.env
            )
            await resp(scope, receive, send)


class ServerTimingMiddleware:
    """ASGI middleware adding ``Server-Timing: app;dur=<ms>`` to every answer.

    The duration runs from the request's arrival to the start of the answer: body
    reading, validation, queueing, computation and encoding; what a client measures
    beyond it is transfer and its own decoding (benchmarks/bench_service.py).
    """

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        t0 = time.perf_counter()

        async def timed_send(message: Message) -> None:
            if message["type"] == "http.response.start":
                ms = 1e3 * (time.perf_counter() - t0)
                headers = list(message.get("headers", ()))
                headers.append((b"server-timing", f"app;dur={ms:.2f}".encode()))
                message = {**message, "headers": headers}
            await send(message)

        await self.app(scope, receive, timed_send)


# ------------------------------------------------------------- run time bound


class Runner:
    """Runs blocking computations in threads, ``max_concurrency`` at a time, bounded in time.

    One runner per application (``app.state.runner``).  :meth:`run` awaits the result
    or raises :class:`RunTimeExceeded` after ``max_run_seconds`` (queueing included).
    A computation still queued at its deadline never starts; one already running
    finishes in the background, holding its slot.  Computations given the same
    ``exclusive`` name run one at a time, queueing *before* they take a slot, so they
    never hold slots the other endpoints need while they wait for each other.
    """

    def __init__(self, settings: Settings) -> None:
        self.max_concurrency = settings.max_concurrency
        self.max_run_seconds = settings.max_run_seconds
        self._limiter: anyio.CapacityLimiter | None = None
        self._threads: anyio.CapacityLimiter | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._background: set[asyncio.Future[Any]] = set()
        self._gates: dict[str, anyio.Lock] = {}

    @property
    def limiter(self) -> anyio.CapacityLimiter:
        # created lazily inside the event loop that uses it (again if the loop changed,
        # as when one app serves several TestClient sessions)
        loop = asyncio.get_running_loop()
        if self._limiter is None or self._loop is not loop:
            self._loop = loop
            self._limiter = anyio.CapacityLimiter(self.max_concurrency)
            # the worker threads get their own pool of the same size, apart from the
            # default one FastAPI uses for sync dependencies
            self._threads = anyio.CapacityLimiter(self.max_concurrency)
            self._gates = {}
        return self._limiter

    def _gate(self, name: str | None) -> Any:
        if name is None:
            return contextlib.nullcontext()
        if name not in self._gates:
            self._gates[name] = anyio.Lock()
        return self._gates[name]

    async def run(
        self,
        func: Callable[..., T],
        *args: Any,
        strict_fp: bool = True,
        exclusive: str | None = None,
    ) -> T:
        """``func(*args)`` in a worker thread, bounded in concurrency and time.

        ``exclusive``: computations of the same name run one at a time (see the class).

        ``strict_fp`` (default) makes floating-point overflow, invalid operations and
        division by zero raise (see :func:`checked_call`); with False the computation runs
        under numpy's default error state, exactly as the library runs it locally (the
        analyses: their results must equal ``analyze()``'s, and the core handles its
        own non-finite intermediates).
        """
        deadline = time.monotonic() + self.max_run_seconds
        limiter, threads = self.limiter, self._threads
        gate = self._gate(exclusive)

        async def job() -> Any:
            async with gate, limiter:
                if time.monotonic() >= deadline:  # timed out while queued: skip
                    return None
                return await anyio.to_thread.run_sync(
                    checked_call, strict_fp, func, *args, limiter=threads
                )

        task = asyncio.ensure_future(job())
        self._background.add(task)
        task.add_done_callback(self._finished)
        try:
            return await asyncio.wait_for(asyncio.shield(task), self.max_run_seconds)
        except asyncio.TimeoutError:
            raise RunTimeExceeded(self.max_run_seconds) from None

    def _finished(self, task: asyncio.Future[Any]) -> None:
        self._background.discard(task)
        if not task.cancelled():
            task.exception()  # retrieved: an abandoned failure is not "never retrieved"


def checked_call(strict_fp: bool, func: Callable[..., T], *args: Any) -> T:
    """Call ``func`` in the numerical policy of the service (threads and workers alike).

    With ``strict_fp``, floating-point overflow, invalid operations and division by
    zero raise instead of producing inf/NaN silently (underflow to zero stays allowed);
    numpy's errstate is context-local, so this does not leak into other threads.
    Arithmetic and plain ValueErrors escaping the core from accepted input (extreme
    magnitudes such as denormal periods) become :class:`~service.errors.NumericalError`
    (HTTP 422), logged with their traceback: a client input never answers 500.  Domain
    errors
    (:class:`~stochcable.errors.StochcableError`, including InputError) pass unchanged.
    """
    try:
        if not strict_fp:
            return func(*args)
        with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
            return func(*args)
    except StochcableError:
        raise
    except (ArithmeticError, ValueError) as exc:
        _log.warning("numerical failure on accepted input", exc_info=True)
        raise NumericalError(f"{type(exc).__name__}: {exc}") from exc
