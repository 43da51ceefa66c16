"""Python client of the stochcable HTTP service (httpx).

>>> from stochcable.client import Client
>>> with Client("http://127.0.0.1:8000") as c:            # doctest: +SKIP
...     res = c.spectrum({"type": "pierson_moskowitz", "hs": 6.0, "tp": 10.0})
...     res.stats.hs
5.997...

Methods return the objects of the local API where one exists
(:class:`~stochcable.sea.spectra.SpectrumStatistics`, :class:`~stochcable.scene.model.Scene`,
:class:`~stochcable.results.documents.ResponseStats`) and small frozen dataclasses of numpy
arrays otherwise.  :meth:`Client.analyze` returns an :class:`AnalysisDocument`: the
result document (a read-only mapping, exactly ``analyze(scene).to_document()``) with
typed accessors named as on the local :class:`~stochcable.results.documents.Result`
(the views :class:`AnalysisDocument`, :class:`LineDocument` and :class:`TimeSeriesWindow`
are defined in :mod:`stochcable.results.views` and re-exported here)::

    >>> with Client() as c:                                    # doctest: +SKIP
    ...     res = c.analyze(c.example("chain_catenary"))
    ...     res.lines["leg1"].end_b.std, res.lines["leg1"].tension_std.max()

An HTTP failure raises
:class:`ClientError` (4xx: the request was refused; the message names the field,
value, unit and constraint) or :class:`ServiceError` (5xx, or the service cannot be
reached), both :class:`~stochcable.errors.StochcableError`.
"""

from __future__ import annotations

import io
import json
import math
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import httpx
import numpy as np

from stochcable.client_batches import BatchJob, BatchMethods
from stochcable.errors import StochcableError
from stochcable.results.views import AnalysisDocument, LineDocument, TimeSeriesWindow
from stochcable.scene.model import G_STANDARD, OmegaGrid, Scene, load_scene
from stochcable.sea.spectra import SpectrumStatistics

__all__ = [
    "Client",
    "BatchJob",
    "ServiceError",
    "ClientError",
    "SpectrumResult",
    "RealizationResult",
    "ExampleInfo",
    "AnalysisDocument",
    "LineDocument",
    "TimeSeriesWindow",
]

_NPY = "application/x-npy"
_STATS_HEADER = "X-Stochcable-Stats"
_WARNINGS_HEADER = "X-Stochcable-Warnings"


class ServiceError(StochcableError):
    """The service failed (5xx) or could not be reached (``status`` None).

    Attributes
    ----------
    status : int or None
        HTTP status code.
    message : str
        Human-readable reason (the service's messages joined by '; ').
    detail : list of dict
        The error items of the answer (``loc``, ``msg``, ``type``, ``parameter``, ...).
    """

    def __init__(
        self, status: int | None, message: str, detail: Sequence[Mapping[str, Any]] = ()
    ) -> None:
        self.status = status
        self.message = message
        self.detail = [dict(d) for d in detail]
        prefix = f"HTTP {status}: " if status is not None else ""
        super().__init__(prefix + message)


class ClientError(ServiceError):
    """The service refused the request (4xx): invalid input, a limit, an unknown name."""


@dataclass(frozen=True, eq=False)
class SpectrumResult:
    """A spectrum sampled by the service.

    Attributes
    ----------
    omega : numpy.ndarray
        Angular frequencies. [rad/s]
    density : numpy.ndarray
        One-sided spectral density. [unit²·s/rad]
    stats : SpectrumStatistics
        The core's statistics (infinite periods come back as ``inf``).
    """

    omega: np.ndarray
    density: np.ndarray
    stats: SpectrumStatistics


@dataclass(frozen=True, eq=False)
class RealizationResult:
    """A sea realization computed by the service.

    Attributes
    ----------
    elevation : numpy.ndarray
        Surface elevation, shape (N_t,). [m]
    dt : float
        Time step. [s]
    variance : float
        Mean square of the elevation. [m²]
    m0 : float
        Target variance Σ S(ω_m)Δω over the simulated lines. [m²]
    velocity : numpy.ndarray or None
        Wave velocity at the points, shape (n_points, 3, N_t). [m/s]
    acceleration : numpy.ndarray or None
        Wave acceleration at the points, shape (n_points, 3, N_t). [m/s²]
    time : numpy.ndarray
        Sample times t_n = n·dt, shape (N_t,), computed on first access (as
        :attr:`stochcable.sea.realization.SeaRealization.time`). [s]
    """

    elevation: np.ndarray
    dt: float
    variance: float
    m0: float
    velocity: np.ndarray | None = None
    acceleration: np.ndarray | None = None

    @cached_property
    def time(self) -> np.ndarray:
        """Sample times t_n = n·dt. [s]"""
        return self.dt * np.arange(self.elevation.shape[-1])


@dataclass(frozen=True)
class ExampleInfo:
    """Name and title of an example scene."""

    name: str
    title: str


_WIDE_READ_BYTES = 4 << 20


@contextmanager
def _wide_reads(resp: httpx.Response) -> Iterator[None]:
    """While reading ``resp``'s body, read the socket 4 MiB at a time.

    httpcore reads HTTP/1.1 bodies 64 KiB at a time and h11 copies its buffer on every
    read: an 8 MiB .npy answer then costs about 40 ms of client CPU, against 5-10 ms
    with 1-4 MiB reads (docs/BENCHMARKS.md "Service").  The size is set on the
    connection object carrying this response only, and restored afterwards (small
    answers keep small reads); when httpx/httpcore internals differ, nothing changes.
    """
    conn: Any = resp.stream
    for attr in ("_stream", "_httpcore_stream", "_stream", "_connection"):
        conn = getattr(conn, attr, None)
        if conn is None:
            break
    before = getattr(conn, "READ_NUM_BYTES", None)
    if not isinstance(before, int):
        yield
        return
    conn.READ_NUM_BYTES = max(before, _WIDE_READ_BYTES)
    try:
        yield
    finally:
        conn.READ_NUM_BYTES = before


def _load_npy(content: bytes) -> np.ndarray:
    """A .npy payload as a read-only array viewing the bytes (no copy, no pickle)."""
    fh = io.BytesIO(content)
    version = np.lib.format.read_magic(fh)
    if version == (1, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
    else:
        shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
    if dtype.hasobject or fortran:
        raise ServiceError(None, "unexpected .npy layout in the service's answer")
    count = int(np.prod(shape))
    return np.frombuffer(content, dtype=dtype, count=count, offset=fh.tell()).reshape(shape)


def _document(obj: Any) -> Any:
    """A pydantic model as its JSON document (unset optional fields left out)."""
    if hasattr(obj, "model_dump"):
        return obj.model_dump(mode="json", exclude_none=True)
    return obj


def _message(detail: Any, fallback: str) -> tuple[str, list[dict[str, Any]]]:
    if isinstance(detail, str):
        return detail, [{"msg": detail}]
    if isinstance(detail, list) and detail:
        items = [d for d in detail if isinstance(d, Mapping)]
        parts = []
        for d in items:
            msg = str(d.get("msg", ""))
            param = d.get("parameter")
            # InputError/limit messages already start with the parameter
            if (
                param
                and d.get("type") not in ("input_error", "limit_exceeded")
                and not msg.startswith(str(param))
            ):
                unit = f" [{d['unit']}]" if d.get("unit") else ""
                msg = f"{param}{unit}: {msg}"
            parts.append(msg)
        return "; ".join(parts) or fallback, items
    return fallback, []


class Client(BatchMethods):
    """Synchronous client of the stochcable service.

    Parameters
    ----------
    base_url : str, default "http://127.0.0.1:8000"
        Address of the service.
    timeout : float, default 60.0
        Timeout of each request (connect, read, write). [s]
    headers : mapping, optional
        Extra headers sent with every request.
    transport : httpx.BaseTransport, optional
        Custom transport (tests, proxies).
    api_key : str, optional
        Sent as ``Authorization: Bearer`` (a service with ``STOCHCABLE_API_KEYS``).
    """

    def __init__(
        self,
        base_url: str = "http://127.0.0.1:8000",
        timeout: float = 60.0,
        *,
        headers: Mapping[str, str] | None = None,
        transport: httpx.BaseTransport | None = None,
        api_key: str | None = None,
    ) -> None:
        self.base_url = base_url.rstrip("/")
        sent = dict(headers or {})
        if api_key is not None:
            sent["Authorization"] = f"Bearer {api_key}"
        self._http = httpx.Client(
            base_url=self.base_url,
            timeout=timeout,
            headers=sent,
            transport=transport,
        )

    # ---------------------------------------------------------------- plumbing

    def close(self) -> None:
        """Close the connection pool."""
        self._http.close()

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _request(
        self, method: str, path: str, *, json_body: Any = None, accept: str = "application/json"
    ) -> httpx.Response:
        headers = {"Accept": accept}
        if accept == _NPY:
            headers["Accept-Encoding"] = "identity"  # float noise does not compress
        try:
            request = self._http.build_request(method, path, json=json_body, headers=headers)
            resp = self._http.send(request, stream=True)
            try:
                if accept == _NPY:
                    with _wide_reads(resp):
                        resp.read()
                else:
                    resp.read()
            finally:
                resp.close()
        except httpx.TimeoutException as exc:
            raise ServiceError(None, f"{method} {self.base_url}{path} timed out ({exc})") from None
        except httpx.TransportError as exc:
            raise ServiceError(None, f"cannot reach {self.base_url} ({exc})") from None
        if resp.status_code >= 400:
            try:
                detail = resp.json().get("detail")
            except (ValueError, AttributeError):
                detail = None
            fallback = resp.text.strip()[:500] or resp.reason_phrase
            message, items = _message(detail, fallback)
            cls = ClientError if resp.status_code < 500 else ServiceError
            raise cls(resp.status_code, message, items)
        return resp

    # ----------------------------------------------------------------- methods

    def health(self) -> dict[str, Any]:
        """``GET /health``: ``{"status": "ok"}``."""
        return self._request("GET", "/health").json()

    def version(self) -> dict[str, Any]:
        """``GET /version``: ``{"stochcable": ..., "api": "v1"}``."""
        return self._request("GET", "/version").json()

    def spectrum(
        self,
        spectrum: Any,
        omega: OmegaGrid | Mapping[str, Any] | None = None,
        g: float = G_STANDARD,
    ) -> SpectrumResult:
        """``POST /v1/spectra``: sample a spectrum document and get its statistics.

        Parameters
        ----------
        spectrum : Spectrum model or mapping
            Spectrum document, e.g. ``{"type": "jonswap", "hs": 6.0, "tp": 10.0}``.
        omega : OmegaGrid or mapping, optional
            ``{"min", "max", "count"}`` [rad/s]; default from the spectrum's peak.
        g : float, default 9.80665
            Gravitational acceleration. [m/s²]
        """
        body: dict[str, Any] = {"spectrum": _document(spectrum), "g": g}
        if omega is not None:
            body["omega"] = _document(omega)
        data = self._request("POST", "/v1/spectra", json_body=body).json()
        stats = {k: (math.inf if v is None else float(v)) for k, v in data["stats"].items()}
        return SpectrumResult(
            np.asarray(data["omega"], dtype=float),
            np.asarray(data["density"], dtype=float),
            SpectrumStatistics(**stats),
        )

    def realization(
        self,
        spectrum: Any,
        duration: float = 600.0,
        dt: float = 0.25,
        method: str = "dsa",
        seed: int = 1,
        g: float = G_STANDARD,
        points: Sequence[Sequence[float]] | np.ndarray | None = None,
        heading: float = 0.0,
        depth: float | None = None,
        binary: bool = True,
    ) -> RealizationResult:
        """``POST /v1/sea/realizations``: a DSA/NSA sea realization and its kinematics.

        Parameters
        ----------
        spectrum : Spectrum model or mapping
            Sea spectrum document.
        duration, dt : float
            Record length and time step; duration/dt must be an even integer. [s]
        method : {"dsa", "nsa"}
            Spectral amplitude model.
        seed : int
            Random seed (numpy PCG64); the same seed gives the same record as
            :func:`stochcable.sea.realization.simulate_sea` locally.
        g : float
            Gravitational acceleration. [m/s²]
        points : array_like, optional
            Points (x, y, z) for the wave kinematics. [m]
        heading : float
            Wave heading from +x toward +y. [deg]
        depth : float, optional
            Water depth; None for deep water. [m]
        binary : bool, default True
            Transfer as NumPy .npy (fast, exact) instead of JSON.
        """
        body: dict[str, Any] = {
            "spectrum": _document(spectrum),
            "duration": duration,
            "dt": dt,
            "method": method,
            "seed": seed,
            "g": g,
            "heading": heading,
            "depth": depth,
        }
        if points is not None:
            body["points"] = np.asarray(points, dtype=float).reshape(-1, 3).tolist()
        accept = _NPY if binary else "application/json"
        resp = self._request("POST", "/v1/sea/realizations", json_body=body, accept=accept)
        if binary:
            rec = _load_npy(resp.content)
            stats = json.loads(resp.headers[_STATS_HEADER])
            vel = acc = None
            if points is not None:
                n = len(body["points"])
                vel = np.array([[rec[f"velocity_{p}_{a}"] for a in "xyz"] for p in range(n)])
                acc = np.array([[rec[f"acceleration_{p}_{a}"] for a in "xyz"] for p in range(n)])
            # the .npy answer has no time column: t_n = n·dt (RealizationResult.time)
            elevation = np.ascontiguousarray(rec["elevation"])  # a view for one column
            return RealizationResult(
                elevation, float(dt), float(stats["variance"]), float(stats["m0"]), vel, acc
            )
        data = resp.json()
        kin = data.get("kinematics")
        return RealizationResult(
            np.asarray(data["elevation"], dtype=float),
            float(dt),
            float(data["stats"]["variance"]),
            float(data["stats"]["m0"]),
            None if kin is None else np.asarray(kin["velocity"], dtype=float),
            None if kin is None else np.asarray(kin["acceleration"], dtype=float),
        )

    def examples(self) -> list[ExampleInfo]:
        """``GET /v1/examples``: names and titles of the example scenes."""
        return [
            ExampleInfo(d["name"], d["title"]) for d in self._request("GET", "/v1/examples").json()
        ]

    def example(self, name: str) -> Scene:
        """``GET /v1/examples/{name}``: the example scene, validated locally."""
        from urllib.parse import quote

        data = self._request("GET", f"/v1/examples/{quote(name, safe='')}").json()
        return Scene.model_validate(data)

    def analyze(
        self,
        scene: Scene | Mapping[str, Any] | str | Path,
        timeseries: str = "window",
        timeseries_linear: bool = False,
    ) -> AnalysisDocument:
        """``POST /v1/analyses``: run the analysis of a scene on the service.

        Parameters
        ----------
        scene : Scene, mapping, JSON string or path
            The scene document (:class:`~stochcable.scene.model.Scene`, a dict,
            ``client.example(name)``, JSON text or a file), validated here first by
            :func:`~stochcable.scene.model.load_scene` (bodies' hydrodynamics inline:
            the service reads no files).
        timeseries : {"window", "full", "none"}
            Time series in the document: the first 2048 samples, all, or none.
        timeseries_linear : bool
            Also the linear model's end tensions beside the series that carry the
            residuals' component (``timeseries.end_tension_linear``).

        Returns
        -------
        AnalysisDocument
            The result document (equal to ``analyze(scene).to_document(timeseries)``
            apart from timing) with typed accessors.

        Raises
        ------
        InputError
            An invalid scene, found here before any request.
        ClientError
            422: invalid scene (field path, unit, constraint), a size bound exceeded,
            or the solver failed (e.g. the drag linearization did not converge: the
            message says why and what to change).
        ServiceError
            504 when the analysis exceeds the service's run-time bound, 5xx, timeout
            or unreachable service.
        """
        if timeseries not in ("window", "full", "none"):
            from stochcable.errors import InputError

            raise InputError("timeseries", timeseries, "-", "must be 'window', 'full' or 'none'")
        body = load_scene(scene, allow_files=False).model_dump(mode="json")
        query = f"timeseries={timeseries}" + (
            "&timeseries_linear=true" if timeseries_linear else ""
        )
        resp = self._request("POST", f"/v1/analyses?{query}", json_body=body)
        return AnalysisDocument(resp.json())
