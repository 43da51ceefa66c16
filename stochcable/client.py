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
typed accessors named as on the local :class:`~stochcable.results.documents.Result`::

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
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import httpx
import numpy as np

from stochcable.errors import StochcableError
from stochcable.results.documents import ResponseStats
from stochcable.scene.model import G_STANDARD, OmegaGrid, Scene
from stochcable.sea.spectra import SpectrumStatistics

__all__ = [
    "Client",
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


def _array(value: Any) -> np.ndarray:
    return np.asarray(value, dtype=float)


def _response_stats(doc: Mapping[str, Any]) -> ResponseStats:
    """The core's ResponseStats from its ``as_dict()`` (JSON floats round-trip)."""
    from dataclasses import fields

    return ResponseStats(**{f.name: float(doc[f.name]) for f in fields(ResponseStats)})


@dataclass(frozen=True, eq=False)
class LineDocument:
    """One line of an analysis result, named as on
    :class:`~stochcable.results.documents.LineResult`.

    Attributes
    ----------
    name : str
        Line name.
    end_a, end_b : ResponseStats
        Statistics of the end tensions (the core's objects, equal to the local ones). [N]
    end_a_force_std, end_b_force_std : numpy.ndarray
        σ of the x, y, z force on each support, shape (3,). [N]
    s_elements : numpy.ndarray
        Arc length of the element midpoints from end_a. [m]
    tension_mean, tension_std : numpy.ndarray
        Static effective tension and σ of its dynamic part per element. [N]
    s_nodes : numpy.ndarray
        Arc length of the nodes from end_a. [m]
    motion_std : numpy.ndarray
        σ of the x, y, z node displacements, shape (n_nodes, 3). [m]
    omega : numpy.ndarray
        Analysis frequencies. [rad/s]
    channels : tuple of str
        Independent input channels (``"sea"``, ``"end_b.surge"``, ...).
    listed_modes : numpy.ndarray
        Natural frequencies listed in the document. [rad/s]
    n_modes : int or None
        Modes kept by the Foss solve (None for the direct solve). [-]
    linearization : dict
        The line's drag-linearization record (converged, iterations, ...).
    document : dict
        The line's part of the result document.
    """

    name: str
    end_a: ResponseStats
    end_b: ResponseStats
    end_a_force_std: np.ndarray
    end_b_force_std: np.ndarray
    s_elements: np.ndarray
    tension_mean: np.ndarray
    tension_std: np.ndarray
    s_nodes: np.ndarray
    motion_std: np.ndarray
    omega: np.ndarray
    channels: tuple[str, ...]
    listed_modes: np.ndarray
    n_modes: int | None
    linearization: Mapping[str, Any]
    document: Mapping[str, Any]

    def end_tension_spectrum(self, end: str) -> np.ndarray:
        """One-sided spectrum of the tension at ``end`` ("end_a" or "end_b"). [N²·s/rad]"""
        return _array(self.document["spectra"][end]["tension"])

    @property
    def end_b_tension_std(self) -> float:
        """σ of the dynamic tension at end_b (the fairlead, usually). [N]"""
        return self.end_b.std

    @property
    def end_a_tension_std(self) -> float:
        """σ of the dynamic tension at end_a. [N]"""
        return self.end_a.std

    @classmethod
    def from_document(cls, name: str, doc: Mapping[str, Any]) -> LineDocument:
        """Build from the line's part of the result document."""
        tension, motion = doc["tension"], doc["motion"]
        spectra = doc.get("spectra") or {}
        modes = doc.get("modes") or {}
        return cls(
            name=name,
            end_a=_response_stats(doc["end_a"]["tension"]),
            end_b=_response_stats(doc["end_b"]["tension"]),
            end_a_force_std=_array(doc["end_a"].get("force_std", ())),
            end_b_force_std=_array(doc["end_b"].get("force_std", ())),
            s_elements=_array(tension["s"]),
            tension_mean=_array(tension.get("mean", ())),
            tension_std=_array(tension["std"]),
            s_nodes=_array(motion["s"]),
            motion_std=_array(motion["std"]).reshape(-1, 3),
            omega=_array(spectra.get("omega", ())),
            channels=tuple(doc.get("channels", ())),
            listed_modes=_array(modes.get("omega", ())),
            n_modes=modes.get("kept"),
            linearization=doc.get("linearization", {}),
            document=doc,
        )


@dataclass(frozen=True, eq=False)
class TimeSeriesWindow:
    """The time series of an analysis document (a window, or all with ``"full"``).

    Attributes
    ----------
    time : numpy.ndarray
        Sample times, shape (window,). [s]
    elevation : numpy.ndarray or None
        Wave elevation at the origin (None without a sea). [m]
    end_motion : dict of numpy.ndarray
        ``{"line.end_b.surge": series}`` prescribed end motions. [m or rad]
    end_tension : dict
        ``{line: {"end_a": series, "end_b": series}}`` total tensions. [N]
    body_motion : dict
        ``{body: {dof: series}}`` body motions, static pose plus dynamic part (empty
        for scenes without bodies). [m, rad]
    method : str
        ``"dsa"`` or ``"nsa"``.
    seed : int
        Root random seed.
    dt : float
        Time step. [s]
    samples : int
        Length of the whole realization (the window may be shorter). [-]
    """

    time: np.ndarray
    elevation: np.ndarray | None
    end_motion: dict[str, np.ndarray]
    end_tension: dict[str, dict[str, np.ndarray]]
    method: str
    seed: int
    dt: float
    samples: int
    body_motion: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)

    @classmethod
    def from_document(cls, doc: Mapping[str, Any]) -> TimeSeriesWindow:
        """Build from the ``timeseries`` part of the result document."""
        elev = doc.get("elevation")
        return cls(
            time=_array(doc["time"]),
            elevation=None if elev is None else _array(elev),
            end_motion={k: _array(v) for k, v in doc.get("end_motion", {}).items()},
            end_tension={
                line: {end: _array(v["tension"]) for end, v in ends.items()}
                for line, ends in doc.get("lines", {}).items()
            },
            method=str(doc["method"]),
            seed=int(doc["seed"]),
            dt=float(doc["dt"]),
            samples=int(doc["samples"]),
            body_motion={
                name: {dof: _array(v) for dof, v in b.get("motion", {}).items()}
                for name, b in (doc.get("bodies") or {}).items()
            },
        )


class AnalysisDocument(Mapping[str, Any]):
    """The result document of ``POST /v1/analyses`` with typed accessors.

    A read-only mapping equal to ``analyze(scene).to_document(timeseries)`` of the
    local API (apart from the ``timing`` values), plus accessors named as on
    :class:`~stochcable.results.documents.Result`: ``lines[name]`` is a :class:`LineDocument`
    (``.end_b`` the core's :class:`~stochcable.results.documents.ResponseStats`,
    ``.tension_std`` a numpy array, ...), ``timeseries`` a :class:`TimeSeriesWindow`.
    Transfer functions and full response spectra are not in the document: run
    :func:`stochcable.analysis.analyze` locally for those.

    Attributes
    ----------
    document : dict
        The parsed JSON document.
    lines : dict of LineDocument
        Response by line name.
    timeseries : TimeSeriesWindow or None
        The time series, when the scene asks for them and ``timeseries != "none"``.
    warnings : tuple of str
        Warnings of the analysis.
    """

    def __init__(self, document: Mapping[str, Any]) -> None:
        self._doc = dict(document)
        self.lines: dict[str, LineDocument] = {
            name: LineDocument.from_document(name, part)
            for name, part in self._doc["lines"].items()
        }
        ts = self._doc.get("timeseries")
        self.timeseries = None if ts is None else TimeSeriesWindow.from_document(ts)
        self.warnings: tuple[str, ...] = tuple(self._doc.get("warnings", ()))

    # Mapping interface: the document itself
    def __getitem__(self, key: str) -> Any:
        return self._doc[key]

    def __iter__(self):
        return iter(self._doc)

    def __len__(self) -> int:
        return len(self._doc)

    def __repr__(self) -> str:
        return (
            f"AnalysisDocument(lines={list(self.lines)}, converged={self.converged}, "
            f"warnings={len(self.warnings)})"
        )

    @property
    def document(self) -> dict[str, Any]:
        """The parsed JSON result document."""
        return self._doc

    @property
    def converged(self) -> bool:
        """Whether the drag linearization converged on every line."""
        return bool(self._doc["linearization"]["converged"])

    @property
    def linearization(self) -> dict[str, Any]:
        """Aggregate record: converged on all lines, max iterations, max change."""
        return self._doc["linearization"]

    @property
    def statics(self) -> dict[str, Any]:
        """The ``statics`` part: end tensions, touchdown, node positions by line."""
        return self._doc["statics"]

    @property
    def timing(self) -> dict[str, float]:
        """Wall-clock seconds per stage, measured on the server. [s]"""
        return self._doc["timing"]


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


class Client:
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
    """

    def __init__(
        self,
        base_url: str = "http://127.0.0.1:8000",
        timeout: float = 60.0,
        *,
        headers: Mapping[str, str] | None = None,
        transport: httpx.BaseTransport | None = None,
    ) -> None:
        self.base_url = base_url.rstrip("/")
        self._http = httpx.Client(
            base_url=self.base_url,
            timeout=timeout,
            headers=dict(headers or {}),
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
        self, scene: Scene | Mapping[str, Any], timeseries: str = "window"
    ) -> AnalysisDocument:
        """``POST /v1/analyses``: run the analysis of a scene on the service.

        Parameters
        ----------
        scene : Scene or mapping
            The scene document (:class:`~stochcable.scene.model.Scene`, a dict, or
            ``client.example(name)``).
        timeseries : {"window", "full", "none"}
            Time series in the document: the first 2048 samples, all, or none.

        Returns
        -------
        AnalysisDocument
            The result document (equal to ``analyze(scene).to_document(timeseries)``
            apart from timing) with typed accessors.

        Raises
        ------
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
        body = scene.model_dump(mode="json") if isinstance(scene, Scene) else _document(scene)
        resp = self._request("POST", f"/v1/analyses?timeseries={timeseries}", json_body=body)
        return AnalysisDocument(resp.json())
