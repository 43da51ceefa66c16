"""The web page at ``/``: a scene in, its result drawn; batch jobs submitted and watched.

The page (``service/ui``: HTML, CSS, JavaScript and the vendored uPlot) runs in the
browser and calls the /v1 API like any client, so it adds no work to analyses.  Every
asset ships in the package (no CDN).  Not part of the HTTP API's schema.
"""

from __future__ import annotations

from functools import cache
from importlib import resources
from typing import Annotated

from fastapi import APIRouter, Path, Request
from starlette.responses import JSONResponse, Response

from service.errors import NotFound

__all__ = ["router", "ASSETS"]

router = APIRouter(include_in_schema=False)

ASSETS = {
    "app.js": "text/javascript; charset=utf-8",
    "app.css": "text/css; charset=utf-8",
    "vendor/uPlot.iife.min.js": "text/javascript; charset=utf-8",
    "vendor/uPlot.min.css": "text/css; charset=utf-8",
    "vendor/uPlot.LICENSE": "text/plain; charset=utf-8",
}
"""The page's files in ``service/ui`` by path, with their media types."""

_SCATTER = "scatter_north_atlantic.csv"  # the bundled scatter diagram (stochcable.examples)


@cache
def _read(name: str) -> bytes:
    return resources.files("service").joinpath("ui", *name.split("/")).read_bytes()


@router.get("/")
def page() -> Response:
    """The page (index.html)."""
    return Response(_read("index.html"), media_type="text/html; charset=utf-8")


@router.get("/ui/config.json")
def config(request: Request) -> JSONResponse:
    """What the page needs before its first /v1 call: whether API keys are on."""
    return JSONResponse({"keys": bool(request.app.state.settings.keys)})


@router.get("/ui/scatter.csv")
def scatter() -> Response:
    """The bundled North Atlantic scatter diagram, as an example batch input."""
    body = resources.files("stochcable.examples").joinpath(_SCATTER).read_bytes()
    return Response(body, media_type="text/csv; charset=utf-8")


@router.get("/ui/{name:path}")
def asset(name: Annotated[str, Path(max_length=64)]) -> Response:
    """A file of the page (only those of :data:`ASSETS`)."""
    if name not in ASSETS:
        raise NotFound(["path", "name"], f"no page asset {name!r}")
    return Response(_read(name), media_type=ASSETS[name], headers={"Cache-Control": "no-cache"})
