"""POST /v1/analyses: run :func:`stochcable.analysis.analyze` on a scene document."""

from __future__ import annotations

import time
from typing import Annotated, Any, Literal

from fastapi import APIRouter, Body, Query, Request
from starlette.responses import Response

from service.dependencies import PoolDep, SettingsDep
from service.encoding import JSON, NETCDF, error_responses, negotiate_among
from service.jobs import analysis_job
from service.limits import check_scene
from service.schemas import AnalysisResponse
from stochcable.scene.model import Scene, load_scene

__all__ = ["router", "WARNINGS_HEADER"]

router = APIRouter(prefix="/v1", tags=["analyses"])

WARNINGS_HEADER = "X-Stochcable-Warnings"
"""Response header: number of entries of the document's ``warnings`` list."""

Timeseries = Literal["window", "full", "none"]


def _body_examples() -> dict[str, dict[str, Any]]:
    """The bundled example scenes as OpenAPI request examples ("Try it out" in /docs)."""
    from stochcable.examples import list_examples, load_example

    out = {}
    for name in list_examples():
        scene = load_example(name)
        out[name] = {
            "summary": name,
            "description": scene.title,
            # the fields the example file sets (exclude_defaults would drop the
            # spectra's discriminator ``type``, whose value is also its default)
            "value": scene.model_dump(mode="json", exclude_unset=True),
        }
    return out


@router.post(
    "/analyses",
    operation_id="run_analysis",
    response_model=AnalysisResponse,
    responses={
        200: {
            "description": "The v1 result document (JSON); with `Accept: "
            "application/x-netcdf` the result as a NetCDF-4 file (save it as `result.nc`; "
            '`xarray.load_dataset("result.nc")`)',
            "content": {NETCDF: {"schema": {"type": "string", "format": "binary"}}},
            "headers": {
                WARNINGS_HEADER: {
                    "description": "Number of warnings in the document's warnings list",
                    "schema": {"type": "integer", "minimum": 0},
                }
            },
        },
        **error_responses(406, 413, 422, 503, 504),
    },
    summary="Analyse a scene: statics, drag linearization, response statistics",
)
async def run_analysis(
    request: Request,
    scene: Annotated[Scene, Body(openapi_examples=_body_examples())],
    settings: SettingsDep,
    pool: PoolDep,
    timeseries: Annotated[
        Timeseries,
        Query(
            description="Time series in the document: the first 2048 samples (window), "
            "all of them (full) or none; only when the scene has analysis.timeseries"
        ),
    ] = "window",
    timeseries_linear: Annotated[
        bool,
        Query(
            description="Also the linear model's end tensions (tension_linear) beside the "
            "time series that carry the residuals' component"
        ),
    ] = False,
) -> Response:
    """The v1 result document of :func:`stochcable.analysis.analyze` (Tuah 1982, ch. 5):
    identical to ``stochcable analyze SCENE.json`` and ``analyze(scene).to_document()``
    apart from the ``timing`` values.

    Bounds checked before solving (422 ``limit_exceeded``): total finite elements
    (``STOCHCABLE_MAX_ELEMENTS``), ``analysis.omega.count``
    (``STOCHCABLE_MAX_FREQUENCIES``), the estimated peak memory
    (``STOCHCABLE_MAX_MEMORY_BYTES``, from frequencies × nodes × channels, the
    residuals' temporaries and the time-series samples), an estimated run time over ten times
    ``STOCHCABLE_MAX_RUN_SECONDS`` and ``analysis.timeseries`` duration/dt
    (``STOCHCABLE_MAX_SAMPLES``).  The analysis runs in a worker process: the run time is
    bounded by ``STOCHCABLE_MAX_RUN_SECONDS`` (504, the worker is ended); every worker
    busy and ``STOCHCABLE_MAX_QUEUE`` requests waiting, or the worker ended by the
    system (out of memory), answer 503 with ``Retry-After``.  An unconverged drag
    linearization or statics answers 422 ``convergence_error`` with the solver's reason (unless
    ``analysis.linearization.allow_unconverged``); other solver failures 422
    ``solver_error``.  The analysis warnings are in the document's ``warnings`` list,
    their number in the ``X-Stochcable-Warnings`` header.

    Try it: ``curl -s localhost:8000/v1/examples/chain_catenary | curl -s -X POST
    localhost:8000/v1/analyses -H 'Content-Type: application/json' -d @-``
    """
    # coefficient files would be read from the server's file system: inline tables only
    media = negotiate_among(request, (JSON, NETCDF))
    load_scene(scene, allow_files=False)
    check_scene(scene, settings)
    limit = settings.max_run_seconds
    body, n_warnings = await pool.run(
        analysis_job,
        scene,
        timeseries,
        media == NETCDF,
        timeseries_linear,
        deadline=time.monotonic() + limit,
        limit=limit,
    )
    return Response(body, media_type=media, headers={WARNINGS_HEADER: str(n_warnings)})
