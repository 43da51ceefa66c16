"""The FastAPI application: ``create_app(settings)`` and the module-level ``app``.

Run it with ``stochcable serve`` or ``uvicorn service.app:app``.  Routers are the
modules of :mod:`service.routers` exposing ``router`` (one per resource), mounted in
name order; error handlers map domain errors (:mod:`service.errors`); limits come from
:class:`service.settings.Settings` (``STOCHCABLE_*`` environment variables).
"""

from __future__ import annotations

import importlib
import pkgutil

from fastapi import FastAPI
from starlette.middleware.gzip import DEFAULT_EXCLUDED_CONTENT_TYPES, GZipMiddleware

from stochcable import __version__

from . import routers
from .encoding import NPY
from .errors import install_error_handlers
from .limits import BodySizeLimitMiddleware, Runner
from .settings import Settings

__all__ = ["create_app", "app", "GZIP_MINIMUM_BYTES"]

GZIP_MINIMUM_BYTES = 16 * 1024
"""JSON/CSV answers larger than this are gzip-compressed for clients accepting gzip. [bytes]"""

_DESCRIPTION = """\
Frequency-domain stochastic response of marine cables in random seas (stochcable).

Conventions: SI units, angular frequency ω in rad/s, one-sided spectra
(m_n = ∫ ωⁿ S dω, Hs = 4√m0), headings in degrees from +x toward +y, z up from the
still-water level.  Every field states its unit in brackets.

Errors answer `{"detail": [{"loc": [...], "msg": ..., "type": ..., "parameter": ...,
"unit": ...}]}`: 422 for invalid input, exceeded size limits (`limit_exceeded`,
naming the `STOCHCABLE_*` setting) and solver failures; 413 for bodies over
`STOCHCABLE_MAX_BODY_BYTES`; 504 when queueing plus computation exceed
`STOCHCABLE_MAX_RUN_SECONDS`.

Large arrays: send `Accept: application/x-npy` (a NumPy .npy structured array) or
`Accept: text/csv`.
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
    app = FastAPI(
        title="stochcable",
        version=__version__,
        summary="Stochastic response of marine cables in random seas",
        description=_DESCRIPTION,
        license_info={"name": "BSD-3-Clause"},
    )
    app.state.settings = settings
    app.state.runner = Runner(settings)
    install_error_handlers(app)
    for router in _routers():
        app.include_router(router)
    app.add_middleware(
        GZipMiddleware, minimum_size=GZIP_MINIMUM_BYTES, compresslevel=5,
        exclude_content_types=(*DEFAULT_EXCLUDED_CONTENT_TYPES, NPY),
    )
    app.add_middleware(BodySizeLimitMiddleware, max_bytes=settings.max_body_bytes)
    return app


app = create_app()
