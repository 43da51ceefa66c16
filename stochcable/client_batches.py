"""Batch jobs of the stochcable service from Python: the methods of
:class:`stochcable.client.Client` for ``/v1/batches``::

    >>> with Client(api_key=KEY) as c:                          # doctest: +SKIP
    ...     job = c.submit_batch(scene, "scatter.csv", headings=[0, 45, 90],
    ...                          fatigue=LineFatigue("dnv-studless", nominal_diameter=0.076))
    ...     job = c.wait(job, progress=True)
    ...     ds = c.results(job)                                 # an xarray Dataset

A batch runs on the service whether or not the caller waits; its id is enough to come
back later (``c.batch(job_id)``), also after a restart of the service.
"""

from __future__ import annotations

import dataclasses
import sys
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from stochcable.cases import LineFatigue, ScatterDiagram, read_scatter
from stochcable.errors import InputError, PhysicsWarning, StochcableError
from stochcable.results.display import batch_status_html, batch_status_text
from stochcable.scene.model import Scene, load_scene

__all__ = ["BatchJob", "BatchMethods", "BatchTimeout"]

_NETCDF = "application/x-netcdf"


class BatchTimeout(StochcableError):
    """:meth:`BatchMethods.wait` gave up before the batch finished (it still runs)."""


@dataclass(frozen=True)
class BatchJob:
    """A batch job as the service reported it.

    Attributes
    ----------
    id : str
    status : {"queued", "running", "done", "failed", "cancelled"}
    progress : dict
        ``total``, ``done``, ``not_ok``, ``failed``, ``fraction``, ``rate`` [1/s],
        ``eta_seconds`` [s].
    problems : list of dict
        Cases not ok (``index``, ``status``, ``reason``), first ones first.
    error : str or None
        Why the batch failed.
    document : dict
        The whole status document.
    warnings : list of str
        Physics warnings of the set as planned (what load-case sets do not apply).
    """

    id: str
    status: str
    progress: dict[str, Any] = field(default_factory=dict)
    problems: list[dict[str, Any]] = field(default_factory=list)
    error: str | None = None
    document: dict[str, Any] = field(default_factory=dict, repr=False)
    warnings: list[str] = field(default_factory=list)

    def __repr__(self) -> str:
        """One line: id, status, progress, cases not ok, warnings."""
        return batch_status_text(self)

    def _repr_html_(self) -> str:
        """The status table a notebook shows."""
        return batch_status_html(self)

    @property
    def finished(self) -> bool:
        """Whether the batch is done, failed or cancelled."""
        return self.status in ("done", "failed", "cancelled")

    @classmethod
    def from_document(cls, doc: Mapping[str, Any]) -> BatchJob:
        """From the service's status document."""
        return cls(
            str(doc["id"]), str(doc["status"]), dict(doc.get("progress") or {}),
            list(doc.get("problems") or []), doc.get("error"), dict(doc),
            [str(w) for w in doc.get("warnings") or []],
        )  # fmt: skip


def _scatter_document(scatter: Any) -> Any:
    if isinstance(scatter, ScatterDiagram):
        return scatter.to_document()
    if isinstance(scatter, Path) or (isinstance(scatter, str) and scatter.lstrip()[:1] not in "[{"):
        return read_scatter(scatter).to_document()  # a file: read (and checked) here
    return scatter


def _fatigue_document(fatigue: Any) -> Any:
    def one(f: Any, where: str) -> Any:
        if not isinstance(f, LineFatigue):
            return f
        if not isinstance(f.curve, str):
            raise InputError(f"{where}.curve", f.curve, "-", "must be a catalogue name for "
                             "the service (stochcable.design.curve_names())")  # fmt: skip
        return {k: v for k, v in dataclasses.asdict(f).items() if v is not None}

    if isinstance(fatigue, Mapping) and all(isinstance(v, LineFatigue) for v in fatigue.values()):
        return {name: one(f, f"fatigue.{name}") for name, f in fatigue.items()}
    return one(fatigue, "fatigue")


class BatchMethods:
    """``/v1/batches`` methods of :class:`~stochcable.client.Client`."""

    _request: Callable[..., Any]  # the Client's HTTP request (errors as ClientError)

    def submit_batch(
        self,
        scene: Scene | Mapping[str, Any] | str | Path,
        scatter: ScatterDiagram | str | Path | Sequence[Mapping[str, Any]] | Mapping[str, Any],
        *,
        headings: Sequence[float] | None = None,
        fatigue: LineFatigue | Mapping[str, Any] | None = None,
        years: float = 100.0,
        spectrum: str | None = None,
        chunk_size: int | None = None,
    ) -> BatchJob:
        """``POST /v1/batches``: run a scene over a scatter diagram on the service.

        Parameters
        ----------
        scene : Scene, mapping, JSON string or path
            The scene template, validated here first
            (:func:`~stochcable.scene.model.load_scene`).
        scatter : ScatterDiagram, path, or a scatter document
            As :func:`stochcable.cases.read_scatter` reads (a CSV or JSON file is read
            here and sent as rows).
        headings : sequence of float, optional
            Repeat every state for each heading with equal probability. [deg]
        fatigue : LineFatigue, mapping of line name to LineFatigue, or a document
            Fatigue settings (none: no damage).
        years : float
            Return period of the long-term extremes. [years]
        spectrum : {"jonswap", "pierson_moskowitz"}, optional
            Spectrum family (default: the diagram's, else JONSWAP).
        chunk_size : int, optional
            Cases per stored chunk (default chosen by the service).

        Returns
        -------
        BatchJob
            Its id and status (``queued``); its planning warnings are also issued
            here as :class:`~stochcable.errors.PhysicsWarning` (as
            :func:`stochcable.cases.run_cases` issues them).

        Raises
        ------
        ClientError
            422 naming the field (``scatter.rows[3].hs``) or the limit
            (``STOCHCABLE_MAX_BATCH_CASES``, ...); 401 without a valid API key.
        """
        body: dict[str, Any] = {
            "scene": load_scene(scene, allow_files=False).model_dump(
                mode="json", exclude_unset=True
            ),
            "scatter": _scatter_document(scatter),
            "years": years,
        }
        if headings is not None:
            body["headings"] = [float(h) for h in headings]
        if fatigue is not None:
            body["fatigue"] = _fatigue_document(fatigue)
        if spectrum is not None:
            body["spectrum"] = spectrum
        if chunk_size is not None:
            body["chunk_size"] = chunk_size
        job = BatchJob.from_document(self._request("POST", "/v1/batches", json_body=body).json())
        for message in job.warnings:
            warnings.warn(message, PhysicsWarning, stacklevel=2)
        return job

    def batch(self, job: BatchJob | str) -> BatchJob:
        """``GET /v1/batches/{id}``: the batch's status, progress and problem cases."""
        job_id = job.id if isinstance(job, BatchJob) else str(job)
        return BatchJob.from_document(self._request("GET", f"/v1/batches/{job_id}").json())

    def wait(
        self,
        job: BatchJob | str,
        *,
        progress: bool = False,
        poll: float = 0.5,
        timeout: float | None = None,
    ) -> BatchJob:
        """Poll until the batch is done, failed or cancelled.

        Parameters
        ----------
        job : BatchJob or str
        progress : bool
            Show a progress bar (tqdm, on stderr).
        poll : float
            Seconds between status requests. [s]
        timeout : float, optional
            Give up after this long (:class:`BatchTimeout`; the batch goes on). [s]

        Returns
        -------
        BatchJob
            The finished batch (check ``status``).
        """
        start = time.monotonic()
        bar = None
        try:
            while True:
                current = self.batch(job)
                if progress:
                    if bar is None:
                        from tqdm import tqdm

                        bar = tqdm(
                            total=current.progress.get("total"), unit="case", file=sys.stderr
                        )
                    bar.update(int(current.progress.get("done", 0)) - bar.n)
                if current.finished:
                    return current
                if timeout is not None and time.monotonic() - start > timeout:
                    raise BatchTimeout(
                        f"batch {current.id} is still {current.status} after {timeout:g} s "
                        f"({current.progress.get('done')} of {current.progress.get('total')} "
                        "cases); it goes on: wait again or cancel it"
                    )
                time.sleep(poll)
        finally:
            if bar is not None:
                bar.close()

    def results(self, job: BatchJob | str, format: str = "dataset") -> Any:
        """``GET /v1/batches/{id}/results`` of a done batch.

        Parameters
        ----------
        job : BatchJob or str
        format : {"dataset", "json", "csv"}
            An xarray Dataset (from the NetCDF answer), the JSON document (dict), or the
            CSV text.

        Raises
        ------
        ClientError
            409 while the batch is not done.
        """
        job_id = job.id if isinstance(job, BatchJob) else str(job)
        path = f"/v1/batches/{job_id}/results"
        if format == "json":
            return self._request("GET", path).json()
        if format == "csv":
            return self._request("GET", path, accept="text/csv").text
        if format != "dataset":
            raise InputError("format", format, "-", "must be 'dataset', 'json' or 'csv'")
        import tempfile

        import xarray as xr

        content = self._request("GET", path, accept=_NETCDF).content
        with tempfile.NamedTemporaryFile(suffix=".nc") as f:
            f.write(content)
            f.flush()
            return xr.load_dataset(f.name)

    def cancel(self, job: BatchJob | str, *, keep_finished: bool = False) -> BatchJob | None:
        """``DELETE /v1/batches/{id}``: cancel an active batch (its status), or delete a
        finished one and its results (None); ``keep_finished``: only cancel
        (``?cancel_only=true``), a batch that finished meanwhile is left as it is (its
        status: the cancel came too late, its results kept)."""
        job_id = job.id if isinstance(job, BatchJob) else str(job)
        query = "?cancel_only=true" if keep_finished else ""
        resp = self._request("DELETE", f"/v1/batches/{job_id}{query}")
        return None if resp.status_code == 204 else BatchJob.from_document(resp.json())
