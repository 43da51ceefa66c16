"""The FastAPI application: ``create_app(settings)`` and the module-level ``app``.

Run it with ``stochcable serve`` or ``uvicorn service.app:app``.  Routers are the
modules of :mod:`service.routers` exposing ``router`` (one per resource), mounted in
name order; error handlers map domain errors (:mod:`service.errors`); limits come from
:class:`service.settings.Settings` (``STOCHCABLE_*`` environment variables).
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager

import anyio
from fastapi import Depends, FastAPI
from starlette.middleware.gzip import DEFAULT_EXCLUDED_CONTENT_TYPES, GZipMiddleware

from stochcable import __version__, runtime

from . import routers
from .batches import BatchService
from .dependencies import get_caller
from .encoding import NPY
from .errors import install_error_handlers
from .limits import BodySizeLimitMiddleware, Runner, ServerTimingMiddleware
from .settings import Settings, insecure_bind_message
from .workers import WorkerPool

__all__ = ["create_app", "app", "GZIP_MINIMUM_BYTES", "GZIP_LEVEL"]

GZIP_MINIMUM_BYTES = 16 * 1024
"""JSON/CSV answers larger than this are gzip-compressed for clients accepting gzip. [bytes]"""

GZIP_LEVEL = 1
"""gzip level: on the float text of the answers level 1 is 4–5x faster than level 5 for
a 4 % larger body (chain_catenary result document, 192 kB: 1.7 ms → 94 kB at level 1,
7.9 ms → 90 kB at level 5; docs/BENCHMARKS.md "Service")."""

_DESCRIPTION = """\
Frequency-domain stochastic response of marine cables in random seas (stochcable).

Conventions: SI units, angular frequency ω in rad/s, one-sided spectra
(m_n = ∫ ωⁿ S dω, Hs = 4√m0), headings in degrees from +x toward +y, z up from the
still-water level.  Every field states its unit in brackets.

Errors answer `{"detail": [{"loc": [...], "msg": ..., "type": ..., "parameter": ...,
"unit": ...}]}`: 422 for invalid input (a body that is not UTF-8 JSON or is nested too
deep to decode: `json_invalid`, parameter `body`), exceeded size limits
(`limit_exceeded`, naming the `STOCHCABLE_*` setting) and solver failures; 413 for bodies over
`STOCHCABLE_MAX_BODY_BYTES`; 504 when queueing plus computation exceed
`STOCHCABLE_MAX_RUN_SECONDS`.

Analyses: `POST /v1/analyses` takes the scene document (the same as
`stochcable analyze SCENE.json`; examples at `GET /v1/examples/{name}`) and answers the
v1 result document, e.g.
`curl -s localhost:8000/v1/examples/chain_catenary | curl -s -X POST
localhost:8000/v1/analyses -H 'Content-Type: application/json' -d @-`.

Large arrays: send `Accept: application/x-npy` (a NumPy .npy structured array, without
the time column: t_n = n·dt) or `Accept: text/csv`.
"""


def _routers() -> list:
    found = []
    for info in sorted(pkgutil.iter_modules(routers.__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{routers.__name__}.{info.name}")
        router = getattr(module, "router", None)
        if router is not None:
            found.append(router)
    return found


def create_app(settings: Settings | None = None) -> FastAPI:
    """Build the stochcable HTTP application.

    Parameters
    ----------
    settings : Settings, optional
        Limits and address; default read from ``STOCHCABLE_*`` environment variables.

    Returns
    -------
    fastapi.FastAPI
        The application (settings in ``app.state.settings``).
    """
    settings = settings if settings is not None else Settings()
    why = insecure_bind_message(settings.host, settings)
    if why is not None:
        raise ValueError(why)
    runtime.configure()  # the service's process settings (stochcable.runtime)
    pool = WorkerPool(
        settings.analysis_workers,
        settings.max_queue,
        settings.memory_budget,
        settings.worker_recycle_bytes,
        start_method=settings.worker_start_method,
    )

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        await anyio.to_thread.run_sync(pool.start)  # warm workers before the first request
        batches.start()  # jobs left unfinished by a former process resume
        try:
            yield
        finally:
            await anyio.to_thread.run_sync(batches.close)
            await anyio.to_thread.run_sync(pool.close)

    app = FastAPI(
        lifespan=lifespan,
        title="stochcable",
        version=__version__,
        summary="Stochastic response of marine cables in random seas",
        description=_DESCRIPTION,
        license_info={"name": "BSD-3-Clause"},
    )
    app.state.settings = settings
    app.state.runner = Runner(settings)
    app.state.pool = pool  # analyses (started by the lifespan, or on first demand)
    batches = BatchService(settings)
    app.state.batches = batches
    install_error_handlers(app)
    for router in _routers():
        # /v1 needs an API key when STOCHCABLE_API_KEYS is set; /health and /version never
        keyed = router.prefix.startswith("/v1")
        app.include_router(router, dependencies=[Depends(get_caller)] if keyed else None)
    app.add_middleware(
        GZipMiddleware,
        minimum_size=GZIP_MINIMUM_BYTES,
        compresslevel=GZIP_LEVEL,
        exclude_content_types=(*DEFAULT_EXCLUDED_CONTENT_TYPES, NPY),
    )
    app.add_middleware(BodySizeLimitMiddleware, max_bytes=settings.max_body_bytes)
    app.add_middleware(ServerTimingMiddleware)
    return app


app = create_app()
