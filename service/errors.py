"""The service's exceptions and their handlers: every error answer is
``{"detail": [ErrorItem, ...]}``.

The exception types live here, below the modules that raise them
(:mod:`service.limits`, the routers), so no module imports its way back up.

Mapping (never 500 for client input):

=======================================  ======  ==============================
exception                                status  ``type``
=======================================  ======  ==============================
RequestValidationError (bad JSON,        422     pydantic's type (``json_invalid``,
wrong type, NaN, out of bounds)                  ``greater_than``, ...)
a body that is not UTF-8 or is nested    422     ``json_invalid`` (parameter ``body``)
too deep to decode (FastAPI's 400)
:class:`~stochcable.errors.InputError`   422     ``input_error``
:class:`LimitExceeded`                   422     ``limit_exceeded``
ConvergenceError                         422     ``convergence_error``
SolverError, other StochcableError       422     ``solver_error``
FloatingPointError, non-finite result    422     ``numerical_error``
MemoryError (the process or a worker's   422     ``limit_exceeded`` (setting
address-space limit)                             ``STOCHCABLE_MAX_MEMORY_BYTES``)
:class:`BodyTooLarge`                    413     ``body_too_large``
:class:`QueueFull`                       503     ``queue_full`` (Retry-After)
:class:`WorkerLost` (killed, OOM)        503     ``worker_lost`` (Retry-After)
:class:`RunTimeExceeded`                 504     ``run_time_exceeded``
HTTPException (404, 405, 406, ...)       as is   ``http_error`` / ``not_found``
any other exception (a bug)              500     ``internal_error`` (JSON)
=======================================  ======  ==============================

An analysis runs in a worker process (:mod:`service.workers`): its failure is mapped
there by :func:`error_answer` (the same mapping) and travels back as a
:class:`JobFailed` carrying the answer.
"""

from __future__ import annotations

import json
import math
import re
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from pydantic import BaseModel
from sqlalchemy.exc import OperationalError
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.responses import JSONResponse
from starlette.routing import Match

from stochcable.errors import ConvergenceError, InputError, SolverError, StochcableError
from stochcable.scene.model import error_location, field_path_and_unit
from stochcable.scene.units import labels_of_document

from .settings import Settings

__all__ = [
    "install_error_handlers",
    "error_response",
    "NotFound",
    "Conflict",
    "Unauthorized",
    "NumericalError",
    "LimitExceeded",
    "RunTimeExceeded",
    "BodyTooLarge",
    "QueueFull",
    "WorkerLost",
    "JobFailed",
    "StoreUnavailable",
    "error_answer",
    "memory_error",
]


# ------------------------------------------------------------------ exceptions


class LimitExceeded(Exception):
    """A request asks for more work than a configured bound allows (HTTP 422)."""

    def __init__(
        self,
        parameter: str,
        value: Any,
        limit: Any,
        setting: str,
        what: str,
        hint: str = "",
        message: str | None = None,
    ) -> None:
        self.parameter = parameter
        self.value = value
        self.limit = limit
        self.setting = setting
        self.env = Settings.env_name(setting)
        if message is None:
            message = f"{what} exceeds the limit of {limit} ({self.env})"
            message += f"; {hint}" if hint else ""
        super().__init__(message)


class RunTimeExceeded(Exception):
    """Queueing plus computation took longer than ``max_run_seconds`` (HTTP 504)."""

    def __init__(self, limit: float) -> None:
        self.limit = limit
        self.env = Settings.env_name("max_run_seconds")
        super().__init__(
            f"the computation did not finish within the limit of {limit:g} s ({self.env}); "
            "ask for less (shorter duration, fewer samples or frequencies) or retry later"
        )


class BodyTooLarge(StarletteHTTPException):
    """The request body is larger than ``max_body_bytes`` (HTTP 413).

    An HTTPException so that FastAPI re-raises it from its body reader unchanged.
    """

    def __init__(self, size: int | None, limit: int) -> None:
        self.size = size
        self.limit = limit
        self.env = Settings.env_name("max_body_bytes")
        got = f"{size} bytes" if size is not None else "the request body"
        super().__init__(413, f"{got} exceeds the limit of {limit} bytes ({self.env})")

    def __str__(self) -> str:
        return str(self.detail)


class QueueFull(Exception):
    """Every analysis worker is busy and ``max_queue`` analyses already wait (HTTP 503)."""

    def __init__(self, limit: int, retry_after: int) -> None:
        self.limit = limit
        self.retry_after = retry_after
        self.env = Settings.env_name("max_queue")
        super().__init__(
            f"every analysis worker is busy and {limit} analyses are already waiting "
            f"(the limit, {self.env}); retry after {retry_after} s"
        )


class WorkerLost(Exception):
    """The worker process running an analysis ended without an answer (HTTP 503)."""

    def __init__(self, exitcode: int | None) -> None:
        self.exitcode = exitcode
        if exitcode is not None and exitcode < 0:
            import signal

            try:
                name = signal.Signals(-exitcode).name
            except ValueError:
                name = f"signal {-exitcode}"
            how = f"was killed by {name}"
            if -exitcode == signal.SIGKILL:
                how += " (the kernel's out-of-memory killer or an operator)"
        else:
            how = f"exited with code {exitcode}"
        super().__init__(
            f"the worker process running this analysis {how} before answering; the server "
            "has replaced it and other requests are unaffected; retry, and reduce the "
            "analysis (frequencies, elements, time series) if it happens again"
        )


class StoreUnavailable(Exception):
    """The batch-job database cannot be opened or answered an error (HTTP 503)."""

    def __init__(self, url: str, reason: str) -> None:
        self.env = Settings.env_name("jobs_database")
        super().__init__(
            f"the batch-job store {url} ({self.env}) is not available: {reason}; batch "
            "requests wait for it (retry later); analyses are unaffected"
        )


class JobFailed(Exception):
    """The error answer of a computation that failed in a worker process."""

    def __init__(self, status: int, item: dict[str, Any], headers: dict[str, str]) -> None:
        self.status = status
        self.item = item
        self.headers = headers
        super().__init__(item.get("msg", ""))


class NumericalError(Exception):
    """A computation produced non-finite numbers from accepted input (HTTP 422).

    ``parameter``: the input part whose results are non-finite, when known
    (``lines[2]``, ``bodies[0]``).
    """

    def __init__(self, message: str, parameter: str | None = None) -> None:
        self.parameter = parameter
        super().__init__(message)


class NotFound(StarletteHTTPException):
    """A resource (an example name) that does not exist (HTTP 404)."""

    def __init__(self, loc: list[str | int], message: str) -> None:
        self.loc = loc
        super().__init__(404, message)


class Conflict(StarletteHTTPException):
    """The resource is not in a state that allows the request (HTTP 409): the results
    of a batch that has not finished."""

    def __init__(self, loc: list[str | int], message: str) -> None:
        self.loc = loc
        super().__init__(409, message)


class Unauthorized(StarletteHTTPException):
    """No or an unknown API key (HTTP 401, ``WWW-Authenticate: Bearer``)."""

    def __init__(self, message: str) -> None:
        self.loc = ["header", "authorization"]
        super().__init__(401, message, headers={"WWW-Authenticate": "Bearer"})


_HTTP_TYPES = {401: "unauthorized", 404: "not_found", 409: "conflict"}


def _json_safe(value: Any) -> bool:
    if value is None or isinstance(value, (bool, int, str)):
        return not isinstance(value, str) or len(value) <= 200
    if isinstance(value, float):
        return math.isfinite(value)
    return False


def error_response(
    status: int,
    loc: list[str | int],
    msg: str,
    type_: str,
    headers: dict[str, str] | None = None,
    **extra: Any,
) -> JSONResponse:
    """A ``{"detail": [item]}`` JSON answer with one error item."""
    item = {"loc": loc, "msg": msg, "type": type_}
    item.update({k: v for k, v in extra.items() if v is not None})
    return JSONResponse({"detail": [item]}, status_code=status, headers=headers)


# ------------------------------------------------------------ field paths and units

_TOKEN = re.compile(r"([^.\[\]]+)|\[(\d+)\]")


def _loc_from_parameter(parameter: str) -> list[str | int]:
    """'lines[0].segments[1].ea' -> ['lines', 0, 'segments', 1, 'ea']."""
    out: list[str | int] = []
    for name, index in _TOKEN.findall(parameter):
        out.append(int(index) if index else name)
    return out


def _body_model(request: Request) -> type[BaseModel] | None:
    route = request.scope.get("route")
    field = getattr(route, "body_field", None)
    annotation = getattr(getattr(field, "field_info", None), "annotation", None)
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    return None


# ------------------------------------------------------------- the mapping

_MEMORY_ENV = Settings.env_name("max_memory_bytes")


def memory_error(exc: MemoryError, hint: str = "") -> LimitExceeded:
    """A MemoryError as the limit it hit (``STOCHCABLE_MAX_MEMORY_BYTES``)."""
    what = str(exc).splitlines()[0] if str(exc) else "MemoryError"
    extra = f"; {hint}" if hint else ""
    return LimitExceeded(
        "body",
        None,
        None,
        "max_memory_bytes",
        "",
        message=f"the computation ran out of memory ({what}) under the memory limit "
        f"({_MEMORY_ENV}){extra}",
    )


def error_answer(exc: BaseException) -> tuple[int, dict[str, Any], dict[str, str]]:
    """The status, error item and headers of an exception (the handlers' mapping).

    Used by the handlers below and by the worker processes, which cannot send the
    exception itself back (custom exception types do not all pickle).
    """
    if isinstance(exc, MemoryError):
        exc = memory_error(exc)
    if isinstance(exc, InputError):
        value = exc.value if _json_safe(exc.value) else None
        return (
            422,
            _item(
                ["body", *_loc_from_parameter(exc.parameter)],
                str(exc),
                "input_error",
                parameter=exc.parameter,
                unit=exc.unit or None,
                input=value,
            ),
            {},
        )
    if isinstance(exc, LimitExceeded):
        value = exc.value if _json_safe(exc.value) else None
        return (
            422,
            _item(
                ["body", *_loc_from_parameter(exc.parameter)],
                str(exc),
                "limit_exceeded",
                parameter=exc.parameter,
                input=value,
                limit=exc.limit,
                setting=exc.env,
            ),
            {},
        )
    if isinstance(exc, ConvergenceError):
        residual = exc.residual if _json_safe(float(exc.residual)) else None
        return (
            422,
            _item(
                ["body"],
                str(exc),
                "convergence_error",
                solver=exc.solver,
                iterations=exc.iterations,
                residual=residual,
                tolerance=exc.tolerance,
            ),
            {},
        )
    if isinstance(exc, StochcableError):
        return 422, _item(["body"], str(exc), "solver_error"), {}
    if isinstance(exc, (NumericalError, FloatingPointError)):
        parameter = getattr(exc, "parameter", None)
        loc = ["body", *_loc_from_parameter(parameter)] if parameter else ["body"]
        msg = f"{exc}: {_NUMERICAL_HINT}"
        return 422, _item(loc, msg, "numerical_error", parameter=parameter), {}
    if isinstance(exc, RunTimeExceeded):
        return 504, _item([], str(exc), "run_time_exceeded", limit=exc.limit, setting=exc.env), {}
    if isinstance(exc, QueueFull):
        return (
            503,
            _item([], str(exc), "queue_full", limit=exc.limit, setting=exc.env),
            {"Retry-After": str(exc.retry_after)},
        )
    if isinstance(exc, WorkerLost):
        return 503, _item([], str(exc), "worker_lost", exitcode=exc.exitcode), {"Retry-After": "1"}
    if isinstance(exc, OperationalError):  # the job database went away mid-request
        exc = StoreUnavailable("database", str(exc.orig or exc).splitlines()[0])
    if isinstance(exc, StoreUnavailable):
        return 503, _item([], str(exc), "store_unavailable", setting=exc.env), {"Retry-After": "5"}
    if isinstance(exc, JobFailed):
        return exc.status, exc.item, exc.headers
    return 500, _item([], f"internal error ({type(exc).__name__}: {exc})", "internal_error"), {}


def _item(loc: list[str | int], msg: str, type_: str, **extra: Any) -> dict[str, Any]:
    item: dict[str, Any] = {"loc": loc, "msg": msg, "type": type_}
    item.update({k: v for k, v in extra.items() if v is not None})
    return item


async def _mapped_handler(request: Request, exc: Exception) -> JSONResponse:
    status, item, headers = error_answer(exc)
    return JSONResponse({"detail": [item]}, status_code=status, headers=headers or None)


# ------------------------------------------------------------------ handlers


def _scene_of(body: Any) -> Any:
    """The scene document inside a request body (the body itself, or its ``scene``)."""
    if isinstance(body, dict) and "environment" not in body and isinstance(body.get("scene"), dict):
        return body["scene"]
    return body


async def _validation_handler(request: Request, exc: RequestValidationError) -> JSONResponse:
    model = _body_model(request)
    labels = labels_of_document(_scene_of(getattr(exc, "body", None)))
    items = []
    for err in exc.errors():
        loc = list(error_location(err))  # a scene-level check may name its field
        item: dict[str, Any] = {
            "loc": loc,
            "msg": str(err.get("msg", "invalid")),
            "type": str(err.get("type", "value_error")),
        }
        if err.get("type") == "json_invalid":
            item["parameter"] = "body"  # loc[1] is the character offset
        elif loc and loc[0] == "body":
            parameter, unit = field_path_and_unit(model, loc[1:])
            item["parameter"] = parameter or "body"
            if unit:
                item["unit"] = labels.convert(unit)
        elif loc:
            item["parameter"] = ".".join(str(p) for p in loc[1:]) or str(loc[0])
        if "input" in err and _json_safe(err["input"]):
            item["input"] = err["input"]
        ctx = err.get("ctx")
        if isinstance(ctx, dict):
            item["ctx"] = {k: (v if _json_safe(v) else str(v)) for k, v in ctx.items()}
        items.append(item)
    return JSONResponse({"detail": items}, status_code=422)


_NUMERICAL_HINT = (
    "an input is outside the range the model handles numerically (check "
    "magnitudes and units: periods, heights, frequencies, depth)"
)


async def _body_too_large_handler(request: Request, exc: BodyTooLarge) -> JSONResponse:
    return error_response(
        413, ["body"], str(exc), "body_too_large", limit=exc.limit, setting=exc.env
    )


_FASTAPI_BODY_ERROR = "There was an error parsing the body"


def _undecodable_body(exc: StarletteHTTPException) -> str | None:
    """Why a request body could not be decoded, when ``exc`` is FastAPI's 400 "There
    was an error parsing the body" (raised from the decoding error), else None."""
    cause = exc.__cause__
    if exc.status_code != 400 or cause is None or exc.detail != _FASTAPI_BODY_ERROR:
        return None
    if isinstance(cause, UnicodeDecodeError):
        return (
            f"the request body is not UTF-8 JSON: byte {cause.object[cause.start]:#04x} at "
            f"offset {cause.start} cannot be decoded ({cause.reason}); send the JSON "
            "document encoded as UTF-8"
        )
    if isinstance(cause, RecursionError):
        return (
            "the request body is JSON nested too deeply to decode (arrays or objects "
            "nested beyond the JSON parser's recursion limit); the documents of this API "
            "are nested a few levels deep"
        )
    return f"the request body could not be decoded as JSON ({type(cause).__name__}: {cause})"


def _allowed_methods(request: Request) -> list[str]:
    """The methods some route of the application answers at the request's path."""
    found = []
    for method in ("GET", "POST", "PUT", "PATCH", "DELETE"):
        scope = {**request.scope, "method": method}
        if any(r.matches(scope)[0] == Match.FULL for r in request.app.router.routes):
            found.append(method)
    return found


async def _http_handler(request: Request, exc: StarletteHTTPException) -> JSONResponse:
    why = _undecodable_body(exc)
    if why is not None:
        # an undecodable body is invalid input like malformed JSON: 422 json_invalid
        return error_response(422, ["body"], why, "json_invalid", parameter="body")
    loc = getattr(exc, "loc", [])
    type_ = _HTTP_TYPES.get(exc.status_code, "http_error")
    detail = exc.detail if isinstance(exc.detail, str) else json.dumps(exc.detail)
    headers = dict(exc.headers) if exc.headers else None
    if exc.status_code == 405:  # every method of the path, not only the first route's
        headers = {**(headers or {}), "Allow": ", ".join(_allowed_methods(request))}
    return error_response(exc.status_code, loc, detail, type_, headers=headers)


def install_error_handlers(app: FastAPI) -> None:
    """Register the handlers on ``app`` (the most specific exception classes win)."""
    app.add_exception_handler(RequestValidationError, _validation_handler)
    for exc_type in (
        InputError,
        LimitExceeded,
        ConvergenceError,
        SolverError,
        StochcableError,
        NumericalError,
        FloatingPointError,
        MemoryError,
        RunTimeExceeded,
        QueueFull,
        WorkerLost,
        JobFailed,
        StoreUnavailable,
        OperationalError,
    ):
        app.add_exception_handler(exc_type, _mapped_handler)
    app.add_exception_handler(BodyTooLarge, _body_too_large_handler)
    app.add_exception_handler(StarletteHTTPException, _http_handler)
    # a bug answers JSON too (Starlette's ServerErrorMiddleware calls it, then logs)
    app.add_exception_handler(Exception, _mapped_handler)
