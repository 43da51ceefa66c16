"""Response encodings: JSON by default, NPY or CSV for large arrays.

Content negotiation on ``Accept``:

* ``application/json`` (default, also for ``*/*`` or no header);
* ``application/x-npy``: one NumPy ``.npy`` file holding a 1-D structured array of
  float64 columns (``numpy.load(io.BytesIO(body))``; field names as the CSV header,
  except that a uniform time column is left out: t_n = n·dt);
* ``text/csv``: a header row with the column names, then one row per sample
  (``%.17g``, round-trips float64);
* ``application/x-netcdf`` (analyses only): the result as a NetCDF-4 file, the Dataset
  of :func:`stochcable.results.datasets.dataset_from_result`.

The column layouts are documented on each endpoint.  Scalars that do not fit in
columns (the statistics) travel in the ``X-Stochcable-Stats`` header as compact JSON
for the binary and CSV encodings.  Large JSON answers are gzip-compressed when the
client accepts it (NPY is never compressed: float noise does not compress and gzip
would cost more than the transfer).
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import orjson
from fastapi import Request
from starlette.exceptions import HTTPException
from starlette.responses import Response

from .schemas import ErrorResponse

__all__ = [
    "JSON",
    "NPY",
    "CSV",
    "NETCDF",
    "STATS_HEADER",
    "negotiate",
    "negotiate_among",
    "json_response",
    "columns_response",
    "array_responses",
    "error_responses",
    "dumps",
    "all_finite",
]

JSON = "application/json"
NPY = "application/x-npy"
CSV = "text/csv"
NETCDF = "application/x-netcdf"
STATS_HEADER = "X-Stochcable-Stats"
_SUPPORTED = (JSON, NPY, CSV)


def negotiate(request: Request) -> str:
    """The media type to answer with (JSON, NPY or CSV), from the request's ``Accept``
    header (a FastAPI dependency).

    Raises a 406 HTTPException when ``Accept`` names only unsupported types.
    """
    return negotiate_among(request, _SUPPORTED)


def negotiate_among(request: Request, supported: tuple[str, ...]) -> str:
    """The media type to answer with among ``supported`` (JSON first), from the
    request's ``Accept`` header; a 406 HTTPException when it names only others."""
    accept = request.headers.get("accept", "")
    if not accept.strip():
        return JSON
    best, best_q = None, 0.0
    for part in accept.split(","):
        fields = [f.strip() for f in part.split(";")]
        media = fields[0].lower()
        q = 1.0
        for param in fields[1:]:
            if param.startswith("q="):
                try:
                    q = float(param[2:])
                except ValueError:
                    q = 0.0
        if media in ("*/*", "application/*", "", "application/json"):
            media = JSON
        elif media == "text/*":
            media = CSV
        if media in supported and q > best_q:
            best, best_q = media, q
    if best is None:
        raise HTTPException(
            406, f"cannot answer with {accept!r}; supported: {', '.join(supported)}"
        )
    return best


def _plain(obj: Any) -> Any:
    """numpy arrays and scalars to JSON types; non-finite scalars (an infinite period)
    to null; a non-finite array entry raises NumericalError."""
    if isinstance(obj, Mapping):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fc" and not np.isfinite(obj).all():
            from .errors import NumericalError

            raise NumericalError("the result contains non-finite values (NaN or inf)")
        return obj.tolist()
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        x = float(obj)
        return x if math.isfinite(x) else None
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def all_finite(obj: Any) -> bool:
    """True when every float in a JSON-ready document (dicts, lists, numbers, strings,
    None) is finite.

    A list of numbers is checked by its sum (finite iff every term is, unless finite
    terms overflow, which then takes the element-wise path): one C loop per list, so
    a 200 kB result document costs ~0.1 ms.
    """
    if isinstance(obj, float):
        return math.isfinite(obj)
    if isinstance(obj, Mapping):
        return all(all_finite(v) for v in obj.values())
    if isinstance(obj, (list, tuple)):
        try:
            if math.isfinite(sum(obj)):
                return True
        except (TypeError, OverflowError):
            pass
        return all(all_finite(v) for v in obj)
    return True


def dumps(obj: Any) -> bytes:
    """Compact JSON bytes of a JSON-ready document (orjson: ~10× the standard
    library's encoder on float lists; shortest round-trip float text, as ``json``).

    Non-finite floats raise NumericalError (orjson would write them as null): the
    service never answers NaN or a silently nulled number.
    """
    if not all_finite(obj):
        from .errors import NumericalError

        raise NumericalError("the result document contains non-finite values (NaN or inf)")
    return orjson.dumps(obj)


def json_response(payload: Mapping[str, Any], status_code: int = 200) -> Response:
    """JSON answer built directly from numpy arrays (skips per-float pydantic checks)."""
    return Response(dumps(_plain(payload)), status_code=status_code, media_type=JSON)


def _stats_header(stats: Mapping[str, Any] | None) -> dict[str, str]:
    if not stats:
        return {}
    return {STATS_HEADER: dumps(_plain(stats)).decode()}


class _NpyResponse(Response):
    """A .npy answer sent as its header then the array's own buffer (no joined copy)."""

    media_type = NPY

    def __init__(self, head: bytes, payload: memoryview, headers: Mapping[str, str]) -> None:
        super().__init__(b"", media_type=NPY, headers=dict(headers))
        self._head, self._payload = head, payload
        self.headers["content-length"] = str(len(head) + payload.nbytes)

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        await send(
            {"type": "http.response.start", "status": self.status_code, "headers": self.raw_headers}
        )
        await send({"type": "http.response.body", "body": self._head, "more_body": True})
        await send({"type": "http.response.body", "body": self._payload, "more_body": False})


def columns_response(
    columns: Mapping[str, np.ndarray],
    media_type: str,
    stats: Mapping[str, Any] | None = None,
    finite: tuple[str, ...] = (),
) -> Response:
    """NPY (structured array) or CSV answer of equal-length float columns.

    ``finite`` names columns the caller has already found finite (their check is
    skipped); every other column is checked and a non-finite value raises
    NumericalError.
    """
    names = list(columns)
    arrays = [np.asarray(columns[n], dtype=np.float64) for n in names]
    if not all(n in finite or np.isfinite(a).all() for n, a in zip(names, arrays)):
        from .errors import NumericalError

        raise NumericalError("the result contains non-finite values (NaN or inf)")
    headers = _stats_header(stats)
    if media_type == NPY:
        dtype = np.dtype([(n, "<f8") for n in names])
        if len(arrays) == 1 and arrays[0].flags.c_contiguous and arrays[0].dtype == "<f8":
            rec = arrays[0].view(dtype)  # one column: the same bytes, no copy
        else:
            rec = np.empty(arrays[0].shape[0], dtype=dtype)
            for n, a in zip(names, arrays):
                rec[n] = a
        head = io.BytesIO()
        np.lib.format.write_array_header_1_0(
            head,
            {
                "descr": np.lib.format.dtype_to_descr(dtype),
                "fortran_order": False,
                "shape": rec.shape,
            },
        )
        return _NpyResponse(head.getvalue(), rec.data.cast("B"), headers)
    buf = io.StringIO()
    buf.write(",".join(names) + "\n")
    np.savetxt(buf, np.column_stack(arrays), delimiter=",", fmt="%.17g")
    return Response(buf.getvalue(), media_type=CSV, headers=headers)


_ERRORS: dict[int, dict[str, Any]] = {
    401: {
        "model": ErrorResponse,
        "description": "No or an unknown API key (when STOCHCABLE_API_KEYS is set): send "
        "Authorization: Bearer KEY",
        "headers": {"WWW-Authenticate": {"description": "Bearer", "schema": {"type": "string"}}},
    },
    409: {
        "model": ErrorResponse,
        "description": "The batch has not finished (type conflict): poll its status",
    },
    404: {"model": ErrorResponse, "description": "Unknown resource"},
    406: {"model": ErrorResponse, "description": "Accept names no supported media type"},
    413: {"model": ErrorResponse, "description": "Request body over STOCHCABLE_MAX_BODY_BYTES"},
    422: {
        "model": ErrorResponse,
        "description": "Invalid input (field path, value, unit, constraint; a body that "
        "is not UTF-8 JSON or is nested too deep to decode: type json_invalid, parameter "
        "body), a size bound exceeded (type limit_exceeded, naming the STOCHCABLE_* "
        "setting) or a solver failure",
    },
    503: {
        "model": ErrorResponse,
        "description": "Every analysis worker busy and STOCHCABLE_MAX_QUEUE requests "
        "waiting (type queue_full), the worker process running the analysis ended by "
        "the system, e.g. out of memory (type worker_lost), or the batch-job database "
        "not available (type store_unavailable); retry after Retry-After seconds",
        "headers": {
            "Retry-After": {
                "description": "Seconds to wait before retrying",
                "schema": {"type": "integer", "minimum": 0},
            }
        },
    },
    504: {
        "model": ErrorResponse,
        "description": "Queueing plus computation over STOCHCABLE_MAX_RUN_SECONDS",
    },
}


def error_responses(*codes: int) -> dict[int | str, Any]:
    """OpenAPI ``responses`` entries for the given error status codes."""
    return {code: _ERRORS[code] for code in codes}


def array_responses(model: Any, layout: str, *codes: int) -> dict[int | str, Any]:
    """OpenAPI ``responses`` of an endpoint answering JSON, NPY or CSV, plus errors."""
    ok = {
        "model": model,
        "description": "JSON by default; with `Accept: application/x-npy` a NumPy .npy "
        "file of a 1-D structured float64 array, with `Accept: text/csv` CSV with a header "
        f"row. {layout}",
        "content": {
            NPY: {"schema": {"type": "string", "format": "binary"}},
            CSV: {"schema": {"type": "string"}},
        },
    }
    return {200: ok, **error_responses(406, *codes)}
