"""POST /v1/analyses: run :func:`stochcable.analysis.analyze` on a scene document."""

from __future__ import annotations

import threading
import time
from collections.abc import Mapping
from typing import Annotated, Any, Literal

from fastapi import APIRouter, Body, Query
from starlette.responses import Response

from service.dependencies import RunnerDep, SettingsDep
from service.encoding import JSON, dumps, error_responses
from service.errors import RunTimeExceeded
from service.limits import check_scene
from service.schemas import AnalysisResponse
from stochcable.scene.model import Scene, load_scene

__all__ = ["router", "WARNINGS_HEADER"]

router = APIRouter(prefix="/v1", tags=["analyses"])

WARNINGS_HEADER = "X-Stochcable-Warnings"
"""Response header: number of entries of the document's ``warnings`` list."""

# One analysis at a time per process: analyze() collects its warnings with
# warnings.catch_warnings, which swaps process-global state (warnings.filters and the
# show-warning hook) and is not thread-safe before Python 3.14; two overlapping
# analyses would exchange or lose their warnings and could leave the process-wide
# filters altered.  Analyses queue on the Runner's "analysis" gate before taking a
# concurrency slot (so waiting analyses never block the other endpoints) within the
# run-time bound; this lock is the guarantee at the thread level.
_ANALYSIS_LOCK = threading.Lock()

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
            "value": scene.model_dump(mode="json", exclude_defaults=True),
        }
    return out


@router.post(
    "/analyses",
    operation_id="run_analysis",
    response_model=AnalysisResponse,
    responses={
        200: {
            "headers": {
                WARNINGS_HEADER: {
                    "description": "Number of warnings in the document's warnings list",
                    "schema": {"type": "integer", "minimum": 0},
                }
            }
        },
        **error_responses(413, 422, 504),
    },
    summary="Analyse a scene: statics, drag linearization, response statistics",
)
async def run_analysis(
    scene: Annotated[Scene, Body(openapi_examples=_body_examples())],
    settings: SettingsDep,
    runner: RunnerDep,
    timeseries: Annotated[
        Timeseries,
        Query(
            description="Time series in the document: the first 2048 samples (window), "
            "all of them (full) or none; only when the scene has analysis.timeseries"
        ),
    ] = "window",
) -> Response:
    """The v1 result document of :func:`stochcable.analysis.analyze` (seed 001 ch. 5):
    identical to ``stochcable analyze SCENE.json`` and ``analyze(scene).to_document()``
    apart from the ``timing`` values.

    Bounds checked before solving (422 ``limit_exceeded``): total finite elements
    (``STOCHCABLE_MAX_ELEMENTS``), ``analysis.omega.count``
    (``STOCHCABLE_MAX_FREQUENCIES``) and ``analysis.timeseries`` duration/dt
    (``STOCHCABLE_MAX_SAMPLES``); the run time is bounded by
    ``STOCHCABLE_MAX_RUN_SECONDS`` (504).  An unconverged drag linearization or statics
    answers 422 ``convergence_error`` with the solver's reason (unless
    ``analysis.linearization.allow_unconverged``); other solver failures 422
    ``solver_error``.  The analysis warnings are in the document's ``warnings`` list,
    their number in the ``X-Stochcable-Warnings`` header.

    Try it: ``curl -s localhost:8000/v1/examples/chain_catenary | curl -s -X POST
    localhost:8000/v1/analyses -H 'Content-Type: application/json' -d @-``
    """
    # coefficient files would be read from the server's file system: inline tables only
    load_scene(scene, allow_files=False)
    check_scene(scene, settings)
    deadline = time.monotonic() + settings.max_run_seconds
    body, n_warnings = await runner.run(
        _analysis,
        scene,
        timeseries,
        deadline,
        settings.max_run_seconds,
        strict_fp=False,
        exclusive="analysis",
    )
    return Response(body, media_type=JSON, headers={WARNINGS_HEADER: str(n_warnings)})


class _Abandoned(Exception):
    """Raised inside an analysis whose request already answered 504: stops the work."""


def _analysis(scene: Scene, timeseries: str, deadline: float, limit: float) -> tuple[bytes, int]:
    """Run the analysis (one at a time) and encode the result document.

    Past ``deadline`` (``limit`` seconds after the request arrived) the work stops
    with RunTimeExceeded; the Runner has normally answered 504 already.
    """
    from stochcable.analysis import analyze

    def progress(stage: str, info: Mapping[str, Any]) -> None:
        # called at every stage and linearization iteration: an analysis whose request
        # timed out stops at the next call instead of holding its slot to the end
        if time.monotonic() > deadline:
            raise _Abandoned(stage)

    with _ANALYSIS_LOCK:
        if time.monotonic() > deadline:
            raise RunTimeExceeded(limit)
        try:
            result = analyze(scene, progress=progress)
        except _Abandoned:
            raise RunTimeExceeded(limit) from None
    doc = result.to_document(timeseries=timeseries)
    # NumericalError for non-finite values (never NaN or a nulled number in a 200)
    return dumps(doc), len(doc.get("warnings", ()))
