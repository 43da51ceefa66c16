"""GET /health and GET /version."""

from __future__ import annotations

from fastapi import APIRouter

from service.schemas import HealthResponse, VersionResponse
from stochcable import __version__

router = APIRouter(tags=["service"])


@router.get(
    "/health", operation_id="get_health", response_model=HealthResponse, summary="Liveness check"
)
async def get_health() -> HealthResponse:
    """Answers ``{"status": "ok"}`` while the server runs (never waits for computations)."""
    return HealthResponse()


@router.get(
    "/version",
    operation_id="get_version",
    response_model=VersionResponse,
    summary="Library and API versions",
)
async def get_version() -> VersionResponse:
    """The stochcable version and the HTTP API version (``v1``)."""
    return VersionResponse(stochcable=__version__)
