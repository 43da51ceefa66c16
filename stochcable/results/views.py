"""Typed, read-only views of a result document (the JSON of
:meth:`stochcable.results.documents.Result.to_document`, as the service answers it).

:class:`AnalysisDocument` is the document itself (a read-only mapping) with accessors
named as on the local :class:`~stochcable.results.documents.Result`: ``lines[name]`` a
:class:`LineDocument` (the core's :class:`~stochcable.results.records.ResponseStats`,
numpy arrays), ``timeseries`` a :class:`TimeSeriesWindow`.  No HTTP here:
:class:`stochcable.client.Client` returns these, and they read a document from a file
as well.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stochcable.results.display import document_html, document_text
from stochcable.results.records import ResidualRecord, ResponseStats
from stochcable.scene.residual_kinds import RESIDUAL_KINDS

__all__ = ["AnalysisDocument", "LineDocument", "TimeSeriesWindow"]


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
    residuals : dict of ResidualRecord
        The residuals of the linear model by kind, as on ``LineResult`` (without their
        spectral lines: the document's ``corrected_spectra`` hold their densities).
    linear : dict {"end_a", "end_b"} of ResponseStats or None
        The linear model's end statistics where a residual was computed (``end_a`` and
        ``end_b`` carry the residuals), None otherwise.
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
    residuals: dict[str, ResidualRecord] = field(default_factory=dict)
    linear: dict[str, ResponseStats] | None = None

    def linear_end(self, end: str) -> ResponseStats:
        """The linear model's statistics of the tension at ``end``, as on ``LineResult``."""
        return getattr(self, end) if self.linear is None else self.linear[end]

    def end_tension_density(self, end: str) -> tuple[np.ndarray, np.ndarray]:
        """Frequencies [rad/s] and density [N²·s/rad] of the tension at ``end`` the end
        statistics are of (with the residuals where computed), as on ``LineResult``."""
        spec = (self.document.get("corrected_spectra") or {}).get(end)
        if spec is None:
            return self.omega, self.end_tension_spectrum(end)
        return _array(spec["omega"]), _array(spec["tension"])

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
            residuals={k: ResidualRecord.from_document(doc[k]) for k in RESIDUAL_KINDS if k in doc},
            linear=None
            if doc.get("linear") is None
            else {e: _response_stats(v["tension"]) for e, v in doc["linear"].items()},
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
        """A few lines: lines, end-tension σ with units, number of warnings."""
        return document_text(self)

    def _repr_html_(self) -> str:
        """The summary table a notebook shows (:mod:`stochcable.results.display`)."""
        return document_html(self)

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
