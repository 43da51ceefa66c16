"""/v1/batches: load-case sets (a scene over a scatter diagram) as background jobs that
survive a restart of the service (:mod:`service.batches`)."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Body, Path, Query, Request, Response

from service.batch_schemas import BatchList, BatchRequest, BatchStatus
from service.dependencies import BatchesDep, CallerDep
from service.encoding import CSV, JSON, NETCDF, error_responses, negotiate_among

__all__ = ["router"]

router = APIRouter(prefix="/v1", tags=["batches"])

JobId = Annotated[str, Path(max_length=64, description="The id POST /v1/batches answered")]


def _example() -> dict[str, Any]:
    from stochcable.examples import load_example

    scene = load_example("chain_catenary").model_dump(mode="json", exclude_unset=True)
    rows = [
        {"hs": hs, "tp": tp, "heading": 0, "probability": p}
        for hs, tp, p in ((1.0, 7.0, 0.3), (2.0, 9.0, 0.4), (4.0, 11.0, 0.2), (6.0, 13.0, 0.1))
    ]
    return {
        "chain": {
            "summary": "chain example over a 4-state diagram, two headings",
            "value": {
                "scene": scene,
                "scatter": {"rows": rows, "spectrum": "jonswap"},
                "headings": [0, 30],
                "fatigue": {"curve": "dnv-studless", "nominal_diameter": 0.076},
                "years": 100,
            },
        }
    }


@router.post(
    "/batches",
    operation_id="submit_batch",
    status_code=202,
    response_model=BatchStatus,
    responses={
        202: {"headers": {"Location": {"description": "The batch", "schema": {"type": "string"}}}},
        **error_responses(401, 413, 422, 503),
    },
    summary="Submit a load-case set as a batch job",
)
def submit_batch(
    request: Annotated[BatchRequest, Body(openapi_examples=_example())],
    batches: BatchesDep,
    caller: CallerDep,
    response: Response,
) -> BatchStatus:
    """Validate and store a batch (the scene's limits as for ``POST /v1/analyses``, and
    ``STOCHCABLE_MAX_BATCH_CASES``, ``STOCHCABLE_MAX_QUEUED_BATCHES``,
    ``STOCHCABLE_MAX_RESULT_BYTES``: 422 ``limit_exceeded``) and answer 202 with its
    status and ``Location``.  The batch runs in the background, chunk by chunk; each
    finished chunk is stored, so a restart of the service resumes the batch where it
    was.  Results: ``GET /v1/batches/{id}/results`` when its status is ``done``.
    """
    job = batches.submit(request, caller)
    response.headers["Location"] = f"/v1/batches/{job.id}"
    return batches.status(job)


@router.get(
    "/batches",
    operation_id="list_batches",
    response_model=BatchList,
    responses=error_responses(401, 503),
    summary="The caller's batches, newest first",
)
def list_batches(batches: BatchesDep, caller: CallerDep) -> BatchList:
    """The most recent 100 batches of the caller (of every caller without API keys)."""
    jobs = batches.store.list(caller or None)
    return BatchList(batches=[batches.status(j) for j in jobs])


@router.get(
    "/batches/{job_id}",
    operation_id="get_batch",
    response_model=BatchStatus,
    responses=error_responses(401, 404, 503),
    summary="Status and progress of a batch",
)
def get_batch(job_id: JobId, batches: BatchesDep, caller: CallerDep) -> BatchStatus:
    """Status (queued, running, done, failed, cancelled), progress (cases done, rate,
    estimated time left) and the cases that are not ok with their reasons."""
    return batches.status(batches.get(job_id, caller))


@router.get(
    "/batches/{job_id}/results",
    operation_id="get_batch_results",
    responses={
        200: {
            "description": "The result table: JSON (cases with their statistics and "
            "damage, totals per line), `Accept: text/csv` (one row per case) or `Accept: "
            "application/x-netcdf` (the Dataset of stochcable.cases.case_dataset)",
            "content": {
                JSON: {"schema": {"type": "object"}},
                CSV: {"schema": {"type": "string"}},
                NETCDF: {"schema": {"type": "string", "format": "binary"}},
            },
        },
        **error_responses(401, 404, 406, 409, 503),
    },
    summary="Results of a finished batch",
)
def get_batch_results(
    job_id: JobId, request: Request, batches: BatchesDep, caller: CallerDep
) -> Response:
    """The results of a ``done`` batch; 409 ``conflict`` before."""
    media = negotiate_among(request, (JSON, CSV, NETCDF))
    job = batches.get(job_id, caller)
    return Response(batches.results(job, media), media_type=media)


@router.delete(
    "/batches/{job_id}",
    operation_id="cancel_batch",
    status_code=200,
    responses={
        204: {"description": "A finished batch was deleted"},
        **error_responses(401, 404, 503),
    },
    response_model=BatchStatus,
    summary="Cancel a batch (or delete a finished one)",
)
def cancel_batch(
    job_id: JobId,
    batches: BatchesDep,
    caller: CallerDep,
    cancel_only: Annotated[
        bool,
        Query(
            description="Only cancel: a batch that has already finished is left as it is "
            "(200 with its status), so a cancel that arrives after the last chunk never "
            "deletes the results"
        ),
    ] = False,
) -> Response | BatchStatus:
    """A queued or running batch is cancelled (200 with its status; the chunks in flight
    finish, nothing more starts); a finished batch is deleted with its results (204), or
    with ``cancel_only`` left as it is (200 with its status: the cancel came too late).
    A batch that finishes while its cancel is on the way stays finished (200 with its
    status)."""
    job = batches.get(job_id, caller)
    after = batches.cancel(job, delete_finished=not cancel_only)
    return Response(status_code=204) if after is None else batches.status(after)
