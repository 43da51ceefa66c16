"""POST /v1/scenes/moordyn: a MoorDyn input file (v1 or v2) as a scene document."""

from __future__ import annotations

import json
import warnings

from fastapi import APIRouter, Request
from starlette.responses import Response

from service.encoding import error_responses
from service.errors import error_response
from stochcable.io import MoorDynInputError, read_moordyn
from stochcable.scene.model import Scene

router = APIRouter(prefix="/v1", tags=["scenes"])

_BODY = {
    "requestBody": {
        "required": True,
        "description": "The MoorDyn input file, as text (UTF-8)",
        "content": {"text/plain": {"schema": {"type": "string"}}},
    }
}


@router.post(
    "/scenes/moordyn",
    operation_id="import_moordyn",
    response_model=Scene,
    responses=error_responses(413, 422),
    openapi_extra=_BODY,
    summary="Read a MoorDyn input file as a scene document",
)
async def import_moordyn(request: Request) -> Response:
    """The scene a MoorDyn input file describes (:func:`stochcable.io.read_moordyn`;
    docs/manual/moordyn.md): lines joined at free points, clump weights and buoys,
    point bodies, the Coupled/Vessel points as the fairleads of a prescribed body with
    a zero motion RAO.  The scene has no sea: add one (and the vessel's RAO) before
    ``POST /v1/analyses``.  The reader's warnings (options MoorDyn uses for its own
    time stepping, properties with no counterpart) are in the ``X-Stochcable-Warnings``
    header as a JSON list.  A bad file is a 422 whose item names the file's ``line``
    and ``column``."""
    raw = await request.body()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        return error_response(
            422, ["body"], f"the file is not UTF-8 text (byte {exc.start})", "input_error"
        )
    if "\n" not in text and "\r" not in text:
        text += "\n"  # one line: text, never a path on the server
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            scene = read_moordyn(text)
        except MoorDynInputError as exc:
            return error_response(
                422,
                ["body", f"line {exc.line}", f"column {exc.column}"],
                str(exc),
                "input_error",
                line=exc.line,
                column=exc.column,
                section=exc.section or None,
            )
    body = scene.model_dump_json(exclude_none=True)
    notes = [str(w.message) for w in caught]
    headers = {"X-Stochcable-Warnings": json.dumps(notes, ensure_ascii=True)} if notes else None
    return Response(body, media_type="application/json", headers=headers)
