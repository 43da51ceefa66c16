"""Result objects of :func:`stochcable.analysis.analyze` and the v1 result document.

Everything is a frozen dataclass holding numpy arrays; :meth:`Result.to_document`
returns the JSON-ready result document of DESIGN.md ("Scene and result documents",
v1 contract) plus extra keys.  Transfer functions and response spectra live on the
Python objects (:class:`LineResult`); the document carries statistics, the end-tension
spectra and a window of the time series.  The records they carry (:class:`ResponseStats`,
:class:`LinearizationRecord`, :class:`LineIndicators`, :func:`stats_from_spectrum`)
live in :mod:`stochcable.results.records` and are re-exported here.

Conventions (DESIGN.md): SI, ω in rad/s, one-sided spectra S(ω) [unit²·s/rad],
harmonic quantities Re{X e^{iωt}}, transfer functions per unit input of each channel
(metre of wave amplitude for the sea, metre of end motion for an end-motion
spectrum channel).  Channels are mutually independent, so a response spectrum is
S_x(ω) = Σ_i |H_{x,i}(ω)|² S_i(ω).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stochcable.line.strumming.screen import StrummingTable
from stochcable.results.records import (
    THREE_HOURS,
    LinearizationRecord,
    LineIndicators,
    ResidualRecord,
    ResponseStats,
    stats_from_spectrum,
    stats_from_spectrum_unchecked,
    stats_from_validated,  # noqa: F401  (former name, kept importable)
)
from stochcable.results.time_series import DOCUMENT_WINDOW, TimeSeries  # noqa: F401
from stochcable.scene.residual_kinds import RESIDUAL_KINDS
from stochcable.scene.units import unit_labels

__all__ = [
    "FormedOnAccess",
    "THREE_HOURS",
    "ResponseStats",
    "LinearizationRecord",
    "LineIndicators",
    "LineResult",
    "BodyResult",
    "TimeSeries",
    "Result",
    "stats_from_spectrum",
    "stats_from_spectrum_unchecked",
]


class FormedOnAccess:
    """A dataclass field (no default) holding an array, or a zero-argument callable
    that forms it: called on the first access, its array then kept (the node motion
    and element tension transfers of :class:`LineResult`, formed only when read)."""

    def __set_name__(self, owner: type, name: str) -> None:
        self._key = "_" + name

    def __get__(self, obj: Any, objtype: Any = None) -> Any:
        if obj is None:
            raise AttributeError(self._key[1:])  # (the dataclass field has no default)
        val = obj.__dict__[self._key]
        if callable(val):
            val = val()
            obj.__dict__[self._key] = val
        return val

    def __set__(self, obj: Any, value: Any) -> None:
        obj.__dict__[self._key] = value


@dataclass(frozen=True, eq=False)
class LineResult:
    """Frequency-domain response of one line.

    Attributes
    ----------
    name : str
        Line name.
    omega : ndarray, shape (n_omega,)
        Analysis frequencies. [rad/s]
    channels : tuple of str
        Names of the independent input channels (``"sea"``, ``"end_b.surge"``, …).
    input_spectra : ndarray, shape (n_ch, n_omega)
        One-sided input spectrum of each channel. [m²·s/rad]
    s_nodes : ndarray, shape (n_nodes,)
        Unstretched arc length of the nodes from end_a. [m]
    s_elements : ndarray, shape (n_el,)
        Unstretched arc length of the element midpoints. [m]
    positions : ndarray, shape (n_nodes, 3)
        Static node positions. [m]
    motion_transfer : ndarray, complex, shape (n_ch, n_nodes, 3, n_omega)
        Total node displacement (prescribed end motion + response) per unit input,
        formed from the kept response on first access (the analysis itself reads it
        block by block; a zero-argument callable may be given for it). [m/m]
    tension_transfer : ndarray, complex, shape (n_ch, n_el, n_omega)
        Dynamic effective tension of each element per unit input, formed from the kept
        response on first access (as ``motion_transfer``). [N/m]
    end_tension_transfer : dict {"end_a", "end_b"} of ndarray (n_ch, n_omega)
        Dynamic change of the magnitude of the force on each support per unit input
        (from the reaction rows of the finite-element equations). [N/m]
    end_force_transfer : dict {"end_a", "end_b"} of ndarray (n_ch, 3, n_omega)
        Dynamic force of the line on each support, global x, y, z, per unit input. [N/m]
    tension_mean : ndarray, shape (n_el,)
        Static effective tension per element. [N]
    tension_std : ndarray, shape (n_el,)
        σ of the dynamic effective tension per element. [N]
    motion_std : ndarray, shape (n_nodes, 3)
        σ of the x, y, z node displacements. [m]
    end_a, end_b : ResponseStats
        Statistics of the end tensions. [N]
    linearization : LinearizationRecord
    modes_omega : ndarray
        Natural frequencies computed for the line about its static shape (with added
        mass, in the model's plane for a 2-D model). [rad/s]
    modes_listed : int
        How many of them the document lists (those up to 2.5·ω_max, at least 10). [-]
    n_modes : int or None
        Modes kept by the Foss solve (None for the direct solve). [-]
    statics, model, modes : objects
        The statics result of the line, its finite-element model and modes (for
        inspection and re-use).
    indicators : LineIndicators or None
        Quality indicators of the linear model (None when not computed).
    strumming : StrummingTable or None
        Strumming screening of the line in the current (None without current;
        docs/strumming.md).
    residuals : dict of ResidualRecord
        The residuals of the linear model asked for, by kind
        (:mod:`stochcable.scene.residual_kinds`, in registry order; a kind not asked
        for is absent).  Each is also an attribute: ``drag_residual`` (the end-tension
        variance the drag linearization drops), ``geometric_residual`` (that of the
        second-order geometric forces), None when not asked for.  With a zero-mean
        flow the residuals are uncorrelated: their variances add.
    linear : dict {"end_a", "end_b"} of ResponseStats or None
        Where a residual was computed, ``end_a`` and ``end_b`` are the statistics with
        the residuals (their spectra's moments added:
        :mod:`stochcable.dynamics.residuals.corrected`) and these the linear model's
        alone; None otherwise (``end_a`` and ``end_b`` are the linear model's).
    corrected_spectra : dict {"end_a", "end_b"} of CorrectedSpectrum or None
        Where a residual was computed, the end tensions' spectral densities with the
        residuals' spectra (``omega``, ``density``: the analysis grid extended by the
        residual lines outside it;
        :mod:`stochcable.dynamics.residuals.corrected_spectrum`), whose area is the
        corrected σ²; None otherwise (:meth:`end_tension_density`).
    tension_std_linear : ndarray, shape (n_el,) or None
        Where the residuals were computed along the line (``along_line.computed``),
        ``tension_std`` is σ of the element tensions with the residuals and this the
        linear model's alone; None otherwise (``tension_std`` is the linear model's).
    along_line : AlongLineResidual or None
        The residuals' variance lines of every element tension
        (:mod:`stochcable.dynamics.residuals.along_line`; ``computed`` False with the
        reason where a residual applied at the ends is not covered along the line);
        None where no residual was applied.
    motion_std_linear : ndarray, shape (n_nodes, 3) or None
        Where the residuals were computed in the node motions
        (``motion_residual.computed``), ``motion_std`` is σ of the node displacements
        with the residuals and this the linear model's alone; None otherwise.
    motion_residual : MotionResidual or None
        The residuals' variance lines of every node's displacement
        (:mod:`stochcable.dynamics.residuals.along_line_motion`); None where no residual
        was applied.
    """

    name: str
    omega: np.ndarray
    channels: tuple[str, ...]
    input_spectra: np.ndarray
    s_nodes: np.ndarray
    s_elements: np.ndarray
    positions: np.ndarray
    motion_transfer: np.ndarray = FormedOnAccess()  # type: ignore[assignment]
    tension_transfer: np.ndarray = FormedOnAccess()  # type: ignore[assignment]
    end_tension_transfer: dict[str, np.ndarray]
    end_force_transfer: dict[str, np.ndarray]
    tension_mean: np.ndarray
    tension_std: np.ndarray
    motion_std: np.ndarray
    end_a: ResponseStats
    end_b: ResponseStats
    linearization: LinearizationRecord
    modes_omega: np.ndarray
    modes_listed: int
    n_modes: int | None
    statics: Any = None
    model: Any = None
    modes: Any = None
    indicators: LineIndicators | None = None
    strumming: StrummingTable | None = None
    residuals: dict[str, ResidualRecord] = field(default_factory=dict)
    linear: dict[str, ResponseStats] | None = None
    corrected_spectra: dict[str, Any] | None = None
    tension_std_linear: np.ndarray | None = None
    along_line: Any = None
    motion_std_linear: np.ndarray | None = None
    motion_residual: Any = None

    def __getattr__(self, name: str) -> ResidualRecord | None:
        """A registered residual kind's record by its name (None when not asked for)."""
        if name in RESIDUAL_KINDS:
            return self.__dict__.get("residuals", {}).get(name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def linear_end(self, end: str) -> ResponseStats:
        """The linear model's statistics of the tension at ``end`` ("end_a" or
        "end_b"): the end's own without residuals, ``linear[end]`` with them."""
        return getattr(self, end) if self.linear is None else self.linear[end]

    def with_strumming(self, strumming: StrummingTable | None) -> LineResult:
        """This result with ``strumming`` (a shallow copy: the transfer functions stay
        unformed until read)."""
        out = object.__new__(LineResult)
        out.__dict__.update(self.__dict__)
        object.__setattr__(out, "strumming", strumming)
        return out

    def __getstate__(self) -> dict[str, Any]:
        """Pickled with the transfer functions formed (no callable)."""
        _ = self.motion_transfer, self.tension_transfer
        return dict(self.__dict__)

    @property
    def listed_modes(self) -> np.ndarray:
        """The natural frequencies the document lists. [rad/s]"""
        return np.asarray(self.modes_omega)[: self.modes_listed]

    # ---------------------------------------------------------------- spectra
    def _spectrum(self, transfer: np.ndarray) -> np.ndarray:
        """Σ_i |H_i|² S_i over the channel axis (axis 0)."""
        s = self.input_spectra.reshape(
            (self.input_spectra.shape[0],) + (1,) * (transfer.ndim - 2) + (-1,)
        )
        return np.sum(np.abs(transfer) ** 2 * s, axis=0)

    def end_tension_density(self, end: str) -> tuple[np.ndarray, np.ndarray]:
        """The frequencies [rad/s] and one-sided spectral density [N²·s/rad] of the
        tension at ``end`` that the end statistics are of: with the residuals' spectra
        where they were computed (``corrected_spectra``), else the linear
        :meth:`end_tension_spectrum` on ``omega``."""
        if self.corrected_spectra is None:
            return self.omega, self.end_tension_spectrum(end)
        spec = self.corrected_spectra[end]
        return spec.omega, spec.density

    def end_force_std(self, end: str) -> np.ndarray:
        """σ of the x, y, z force on the support at ``end``, shape (3,). [N]"""
        dens = self._spectrum(self.end_force_transfer[end])
        return np.sqrt(np.trapezoid(dens, self.omega, axis=-1))

    def end_tension_spectrum(self, end: str) -> np.ndarray:
        """One-sided spectrum of the tension at ``end`` ("end_a" or "end_b"). [N²·s/rad]"""
        return self._spectrum(self.end_tension_transfer[end])

    @property
    def tension_spectrum(self) -> np.ndarray:
        """Spectrum of the element effective tensions, shape (n_el, n_omega). [N²·s/rad]"""
        return self._spectrum(self.tension_transfer)

    @property
    def motion_spectrum(self) -> np.ndarray:
        """Spectrum of the node displacements, shape (n_nodes, 3, n_omega). [m²·s/rad]"""
        return self._spectrum(self.motion_transfer)

    def to_document(self) -> dict[str, Any]:
        """The line's part of the result document."""
        return {
            "end_a": {
                "tension": self.end_a.as_dict(),
                "force_std": self.end_force_std("end_a").tolist(),
            },
            "end_b": {
                "tension": self.end_b.as_dict(),
                "force_std": self.end_force_std("end_b").tolist(),
            },
            "tension": {
                "s": self.s_elements.tolist(),
                "std": self.tension_std.tolist(),
                "mean": self.tension_mean.tolist(),
                **(
                    {}
                    if self.tension_std_linear is None
                    else {"std_linear": self.tension_std_linear.tolist()}
                ),
            },
            "motion": {
                "s": self.s_nodes.tolist(),
                "std": self.motion_std.tolist(),
                **(
                    {}
                    if self.motion_std_linear is None
                    else {"std_linear": self.motion_std_linear.tolist()}
                ),
            },
            "spectra": {
                "omega": self.omega.tolist(),
                "end_a": {"tension": self.end_tension_spectrum("end_a").tolist()},
                "end_b": {"tension": self.end_tension_spectrum("end_b").tolist()},
            },
            "channels": list(self.channels),
            "linearization": self.linearization.as_dict(),
            "modes": {"omega": self.listed_modes.tolist(), "kept": self.n_modes},
            "indicators": None if self.indicators is None else self.indicators.as_dict(),
            **({} if self.strumming is None else {"strumming": self.strumming.as_dict()}),
            **{k: r.as_dict() for k, r in self.residuals.items()},
            **(
                {}
                if self.linear is None
                else {"linear": {e: {"tension": s.as_dict()} for e, s in self.linear.items()}}
            ),
            **(
                {}
                if self.corrected_spectra is None
                else {
                    "corrected_spectra": {
                        e: {"omega": c.omega.tolist(), "tension": c.density.tolist()}
                        for e, c in self.corrected_spectra.items()
                    }
                }
            ),
        }


@dataclass(frozen=True, eq=False)
class BodyResult:
    """Frequency-domain motion of one rigid body (docs/BODIES.md).

    Attributes
    ----------
    name : str
        Body name.
    dofs : tuple of str
        DOF names in order: ``("surge", "sway", "heave", "roll", "pitch", "yaw")``, or
        ``("surge", "heave", "pitch")`` for a planar body (pitch about +y).
    omega : ndarray, shape (n_omega,)
        Analysis frequencies. [rad/s]
    channels : tuple of str
        Input channels (the coupled group's: ``"sea"`` — a short-crested sea's
        ``"sea@<deg>"`` per direction —, ``"<line>.<end>.<dof>"``).
    input_spectra : ndarray, shape (n_ch, n_omega)
        One-sided input spectrum of each channel. [m²·s/rad]
    motion_transfer : ndarray, complex, shape (n_ch, d, n_omega)
        Motion of the reference point per unit input: translations [m/m], small
        rotations about the global axes [rad/m].
    motion : dict of str to ResponseStats
        Statistics per DOF; mean = the static pose (position [m], rotation [rad]).
    prescribed : bool
        True for a vessel whose motion is its RAO (not solved for).
    drag_sigma : ndarray or None, shape (3,)
        σ of the relative velocity at the drag point along x, y, z. [m/s]
    drag_coefficient : ndarray or None, shape (3,)
        Linear drag coefficient per direction at the drag point. [N·s/m]
    modes : CoupledModes or None
        Natural modes of the coupled group the body belongs to.
    motion_linear : dict of str to ResponseStats or None
        A free body whose motions carry the lines' residuals
        (:mod:`stochcable.dynamics.residuals.body_motion`): the linear model's
        statistics per DOF (``motion`` then holds the corrected ones); else None.
    corrected_spectra : dict of str to CorrectedSpectrum or None
        Where ``motion_linear`` is given: each DOF's spectral density with the
        residuals' spectra (``omega``, ``density``: the analysis grid extended by the
        residual lines outside it;
        :mod:`stochcable.dynamics.residuals.corrected_spectrum`), whose area is the
        corrected σ² of ``motion``; None otherwise (:meth:`motion_density`).
    """

    name: str
    dofs: tuple[str, ...]
    omega: np.ndarray
    channels: tuple[str, ...]
    input_spectra: np.ndarray
    motion_transfer: np.ndarray
    motion: dict[str, ResponseStats]
    prescribed: bool = False
    drag_sigma: np.ndarray | None = None
    drag_coefficient: np.ndarray | None = None
    modes: Any = None
    motion_linear: dict[str, ResponseStats] | None = None
    corrected_spectra: dict[str, Any] | None = None

    @property
    def motion_spectrum(self) -> np.ndarray:
        """Linear model's spectrum of each DOF, shape (d, n_omega) (with the residuals:
        :meth:`motion_density`). [m²·s/rad, rad²·s/rad]"""
        return np.einsum("cdw,cw->dw", np.abs(self.motion_transfer) ** 2, self.input_spectra)

    def motion_density(self, dof: str) -> tuple[np.ndarray, np.ndarray]:
        """The frequencies [rad/s] and one-sided spectral density [m²·s/rad, rad²·s/rad]
        of ``dof`` that its statistics ``motion[dof]`` are of: with the residuals'
        spectra where they were computed (``corrected_spectra``), else the linear
        :attr:`motion_spectrum` on ``omega``."""
        if self.corrected_spectra is None:
            return self.omega, self.motion_spectrum[self.dofs.index(dof)]
        spec = self.corrected_spectra[dof]
        return spec.omega, spec.density

    @property
    def motion_std(self) -> np.ndarray:
        """σ of each DOF, shape (d,). [m, rad]"""
        return np.array([self.motion[k].std for k in self.dofs])

    def to_document(self) -> dict[str, Any]:
        """The body's part of the result document: per DOF the statistics (rotations
        in rad, plus ``std_deg`` in degrees), the linear spectra (and the densities with
        the residuals, ``corrected_spectra``), the modes."""
        motion = {}
        for k in self.dofs:
            d = self.motion[k].as_dict()
            if self.motion_linear is not None:
                d["std_linear"] = self.motion_linear[k].std
            if k in ("roll", "pitch", "yaw"):
                d["std_deg"] = math.degrees(d["std"])
            motion[k] = d
        return {
            "prescribed": bool(self.prescribed),
            "dofs": list(self.dofs),
            "motion": motion,
            "spectra": {
                "omega": self.omega.tolist(),
                **{k: s.tolist() for k, s in zip(self.dofs, self.motion_spectrum)},
            },
            **(
                {}
                if self.corrected_spectra is None
                else {
                    "corrected_spectra": {
                        k: {"omega": c.omega.tolist(), "motion": c.density.tolist()}
                        for k, c in self.corrected_spectra.items()
                    }
                }
            ),
            "channels": list(self.channels),
            "drag": None
            if self.drag_sigma is None
            else {
                "sigma": self.drag_sigma.tolist(),
                "coefficient": (
                    None if self.drag_coefficient is None else self.drag_coefficient.tolist()
                ),
            },
            "modes": None if self.modes is None else self.modes.as_dict(),
        }


@dataclass(frozen=True, eq=False)
class Result:
    """Result of :func:`stochcable.analysis.analyze`.

    Attributes
    ----------
    scene : Scene
        The analysed scene.
    statics : StaticsResult
        Static equilibrium of every line.
    lines : dict of LineResult
        Frequency-domain response per line name.
    timeseries : TimeSeries or None
        Present when ``analysis.timeseries`` is set.
    timing : dict of float
        Wall-clock seconds per stage (``total_s``, ``statics_s``, ``model_s``,
        ``modes_s``, ``linearization_s``, ``solve_s``, ``outputs_s``,
        ``timeseries_s``). [s]
    warnings : tuple of str
        Messages of the warnings raised during the analysis.
    fidelity : FidelityPlan or None
        The settings chosen by adaptive fidelity (``analysis.fidelity``), with their
        reasons and error estimates; ``scene`` is then the scene they produced.
    bodies : dict of BodyResult
        Motion of every rigid body by name (empty without bodies).
    """

    scene: Any
    statics: Any
    lines: dict[str, LineResult]
    timeseries: TimeSeries | None
    timing: dict[str, float]
    warnings: tuple[str, ...] = field(default_factory=tuple)
    fidelity: Any = None
    bodies: dict[str, BodyResult] = field(default_factory=dict)

    def __repr__(self) -> str:
        """A few lines: title, lines, end-tension σ with units, number of warnings."""
        from stochcable.results.display import result_text  # (shown, not computed)

        return result_text(self)

    def _repr_html_(self) -> str:
        """The summary table a notebook shows (:mod:`stochcable.results.display`)."""
        from stochcable.results.display import result_html

        return result_html(self)

    @property
    def converged(self) -> bool:
        """Whether the drag linearization converged on every line."""
        return all(r.linearization.converged for r in self.lines.values())

    @property
    def linearization(self) -> dict[str, Any]:
        """Aggregate record: converged on all lines, max iterations, max change."""
        recs = [r.linearization for r in self.lines.values()]
        return {
            "converged": all(r.converged for r in recs),
            "iterations": max((r.iterations for r in recs), default=0),
            "relative_change": max((r.relative_change for r in recs), default=0.0),
        }

    def to_xarray(self, timeseries_linear: bool = False) -> Any:
        """The result as an :class:`xarray.Dataset` (:mod:`stochcable.results.datasets`;
        ``timeseries_linear``: with the linear model's end-tension series)."""
        from stochcable.results.datasets import dataset_from_result

        return dataset_from_result(self, timeseries_linear=timeseries_linear)

    def to_netcdf(self, path: Any, timeseries_linear: bool = False) -> Any:
        """Write :meth:`to_xarray` as a NetCDF-4 file; returns its path."""
        from stochcable.results.datasets import write_netcdf

        return write_netcdf(self.to_xarray(timeseries_linear), path)

    def to_document(
        self, timeseries: str = "window", timeseries_linear: bool = False
    ) -> dict[str, Any]:
        """The v1 result document (DESIGN.md), JSON-ready.

        Parameters
        ----------
        timeseries : {"window", "full", "none"}
            Put the first 2048 samples of the time series, all of them, or none.
        timeseries_linear : bool
            Put the linear model's end tensions (``tension_linear``) beside the series
            that carry the residuals' component.

        Notes
        -----
        ``units`` names the scene's consistent unit system and its labels
        (:func:`stochcable.scene.units.unit_labels` of ``environment.g``: SI, or ft, slug,
        lbf for the seeds' imperial examples); every number is in that system.
        """
        if hasattr(self.statics, "to_document"):
            statics_doc = self.statics.to_document()
        else:  # pragma: no cover - statics always has it
            statics_doc = {}
        first = next(iter(self.lines.values()))
        doc: dict[str, Any] = {
            "statics": statics_doc,
            "modes": {
                "omega": first.listed_modes.tolist(),
                "lines": {k: v.listed_modes.tolist() for k, v in self.lines.items()},
            },
            "linearization": {
                **self.linearization,
                "lines": {k: v.linearization.as_dict() for k, v in self.lines.items()},
            },
            "lines": {k: v.to_document() for k, v in self.lines.items()},
            "timing": {k: float(v) for k, v in self.timing.items()},
            "warnings": list(self.warnings),
        }
        env = getattr(self.scene, "environment", None)
        if env is not None:
            # the labels of the scene's consistent unit system (SI or ft/slug/lbf,
            # read off g): the numbers above are in these units
            doc["units"] = unit_labels(env.g).as_dict()
        if self.fidelity is not None:
            doc["fidelity"] = self.fidelity.to_document()
        if self.bodies:
            doc["bodies"] = {k: v.to_document() for k, v in self.bodies.items()}
        if self.timeseries is not None and timeseries != "none":
            doc["timeseries"] = self.timeseries.to_document(
                full=timeseries == "full", linear=timeseries_linear
            )
        return doc
