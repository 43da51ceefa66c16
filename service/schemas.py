"""Request and response wrappers of the HTTP API (v1).

Thin wrappers only: the spectrum documents are the core's models
(:data:`stochcable.scene.model.Spectrum`, a discriminated union on ``type``), the frequency
grid is :class:`stochcable.scene.model.OmegaGrid`, the time-series settings are
:class:`stochcable.scene.model.TimeSeriesSettings` and the example documents are
:class:`stochcable.scene.model.Scene` - one schema for the Python API, the CLI and the
service.  Every field carries its unit in brackets in its description.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from service.body_schemas import BodyDocument
from service.residual_schemas import ResidualParts
from stochcable.scene import model as sc
from stochcable.scene.model import G_STANDARD, OmegaGrid, Spectrum, TimeSeriesSettings

__all__ = [
    "peak_period",
    "ErrorItem",
    "ErrorResponse",
    "HealthResponse",
    "VersionResponse",
    "SpectrumRequest",
    "SpectrumStats",
    "SpectrumResponse",
    "RealizationRequest",
    "RealizationStats",
    "Kinematics",
    "RealizationResponse",
    "ExampleSummary",
    "TensionStatistics",
    "EndResult",
    "LineLinearization",
    "LineDocument",
    "TimeSeriesDocument",
    "AnalysisResponse",
    "default_omega",
    "DEFAULT_OMEGA_COUNT",
]

DEFAULT_OMEGA_COUNT = 200
"""Size of the default frequency grid of ``POST /v1/spectra``. [-]"""


def _f(description: str, unit: str, **kw: Any) -> Any:
    """Field whose description ends with the unit in brackets (as the scene models)."""
    return Field(description=f"{description} [{unit}]", json_schema_extra={"unit": unit}, **kw)


class _Request(BaseModel):
    # the scene models' policy: immutable, unknown fields rejected, NaN/inf rejected
    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)


class _Response(BaseModel):
    model_config = ConfigDict(frozen=True)


class _Open(BaseModel):
    # parts of the result document: more fields may be added (DESIGN.md v1 contract)
    model_config = ConfigDict(frozen=True, extra="allow")


# ---------------------------------------------------------------------- errors


class ErrorItem(BaseModel):
    """One error, in the shape of FastAPI's validation errors plus a few fields."""

    model_config = ConfigDict(extra="allow")

    loc: list[str | int] = Field(
        description="Where: 'body', 'path' or 'query', then the field path"
    )
    msg: str = Field(description="What is wrong and what the constraint is")
    type: str = Field(
        description="Error kind: a pydantic error type, or input_error, "
        "limit_exceeded, body_too_large, run_time_exceeded, queue_full, worker_lost, "
        "convergence_error, solver_error, numerical_error, not_found, unauthorized, "
        "store_unavailable, "
        "conflict, http_error, "
        "internal_error"
    )
    parameter: str | None = Field(
        default=None, description="Dotted field path (or core parameter name)"
    )
    unit: str | None = Field(default=None, description="Unit of the parameter")


class ErrorResponse(BaseModel):
    """Every error answer: a list of errors under ``detail``."""

    detail: list[ErrorItem]


# ---------------------------------------------------------------------- health


class HealthResponse(_Response):
    """Liveness answer."""

    status: Literal["ok"] = "ok"


class VersionResponse(_Response):
    """Versions of the library and of the HTTP API."""

    stochcable: str = Field(description="Version of the stochcable package")
    api: Literal["v1"] = Field(default="v1", description="Version of the HTTP API")


# --------------------------------------------------------------------- spectra

_G_FIELD = _f(
    "Gravitational acceleration (used by the wind-speed Pierson-Moskowitz form)",
    "m/s²",
    gt=0,
    default=G_STANDARD,
)


class SpectrumRequest(_Request):
    """A spectrum document and the grid to sample it on."""

    spectrum: Spectrum = Field(description="Spectrum document (DESIGN.md 'Wave spectra')")
    omega: OmegaGrid | None = Field(
        default=None,
        description="Frequency grid; by default 200 frequencies up to 6 times the peak "
        "frequency (the table's own range for a table spectrum)",
    )
    g: float = _G_FIELD

    def omega_values(self) -> np.ndarray:
        """The frequency grid of the request. [rad/s]"""
        if self.omega is not None:
            return self.omega.values()
        return default_omega(self.spectrum, self.g)

    def omega_count(self) -> int:
        """Number of frequencies the request asks for. [-]"""
        return self.omega.count if self.omega is not None else DEFAULT_OMEGA_COUNT


def peak_period(spectrum: Any, g: float) -> float:
    """Shortest peak period of a spectrum document (a table: its largest density). [s]"""
    from stochcable.sea import spectra

    if isinstance(spectrum, sc.PiersonMoskowitz):
        if spectrum.tp is not None:
            return spectrum.tp
        if spectrum.omega_p is not None:
            return 2.0 * math.pi / spectrum.omega_p
        # S ∝ ω⁻⁵ exp[−0.74 (g/Uω)⁴] peaks at ω = (4·0.74/5)^(1/4) g/U
        return 2.0 * math.pi * spectrum.wind_speed / ((4.0 * 0.74 / 5.0) ** 0.25 * g)
    if isinstance(spectrum, sc.Issc):
        return spectrum.t1 / spectra.PM_TM01_OVER_TP  # ISSC has the PM shape
    if isinstance(spectrum, sc.OchiHubble):
        return min(spectrum.tp1, spectrum.tp2)
    if isinstance(spectrum, sc.TableSpectrum):
        w = spectrum.omega[int(np.argmax(spectrum.density))]
        return 2.0 * math.pi / w if w > 0 else math.inf
    return float(spectrum.tp)


def default_omega(spectrum: Any, g: float = G_STANDARD) -> np.ndarray:
    """Default grid of a spectrum document: :func:`stochcable.sea.spectra.omega_grid` of its
    (shortest) peak period, or 200 points over a table's range. [rad/s]"""
    from stochcable.sea import spectra

    if isinstance(spectrum, sc.TableSpectrum):
        return np.linspace(spectrum.omega[0], spectrum.omega[-1], DEFAULT_OMEGA_COUNT)
    return spectra.omega_grid(peak_period(spectrum, g), DEFAULT_OMEGA_COUNT)


_INF_NOTE = "; null when infinite (a moment is zero on the grid)"


class SpectrumStats(_Response):
    """Moments (trapezoid rule on the grid) and derived statistics of the spectrum."""

    m0: float = _f("Zeroth moment, the variance", "unit²")
    m1: float = _f("First moment", "unit²·rad/s")
    m2: float = _f("Second moment", "unit²·(rad/s)²")
    m3: float = _f("Third moment", "unit²·(rad/s)³")
    m4: float = _f("Fourth moment", "unit²·(rad/s)⁴")
    hs: float = _f("Significant height 4·sqrt(m0)", "unit")
    tz: float | None = _f("Mean zero-upcrossing period 2π·sqrt(m0/m2)" + _INF_NOTE, "s")
    tm01: float | None = _f("Mean period 2π·m0/m1" + _INF_NOTE, "s")
    tp: float | None = _f("Peak period 2π/ω at the largest density on the grid" + _INF_NOTE, "s")
    bandwidth: float = _f("Cartwright–Longuet-Higgins bandwidth sqrt(1 − m2²/(m0·m4))", "-")


class SpectrumResponse(_Response):
    """The sampled spectrum and its statistics."""

    omega: list[float] = _f("Angular frequencies", "rad/s")
    density: list[float] = _f("One-sided spectral density", "unit²·s/rad")
    stats: SpectrumStats


# ------------------------------------------------------------------------- sea

Point = Annotated[
    tuple[float, float, float],
    Field(description="Point (x, y, z), z up from the still-water level [m]"),
]


class RealizationRequest(TimeSeriesSettings):
    """A random sea realization (Tuah 1982, §5.1) and, optionally, its wave kinematics.

    ``method``, ``duration``, ``dt`` and ``seed`` are those of the scene's
    ``analysis.timeseries``.  The number of samples is duration/dt.
    """

    spectrum: Spectrum = Field(description="Sea spectrum document")
    g: float = _f("Gravitational acceleration", "m/s²", gt=0, default=G_STANDARD)
    points: list[Point] | None = Field(
        default=None,
        min_length=1,
        description="Points (x, y, z) where the wave velocity and acceleration are "
        "wanted; points above z = 0 get zero kinematics [m]",
    )
    heading: float = _f(
        "Direction the waves travel toward, from +x toward +y",
        "deg",
        ge=-360.0,
        le=360.0,
        default=0.0,
    )
    depth: float | None = _f("Water depth; null or absent for deep water", "m", gt=0, default=None)

    def depth_or_inf(self) -> float:
        """Water depth, ``inf`` for deep water. [m]"""
        return math.inf if self.depth is None else self.depth


class RealizationStats(_Response):
    """Statistics of the realization against the spectrum."""

    variance: float = _f("Variance of the simulated elevation (mean square about 0)", "m²")
    m0: float = _f(
        "Variance the simulation targets: the sum of S(ω_m)·Δω over the "
        "simulation frequencies (DSA reproduces it exactly)",
        "m²",
    )


class Kinematics(_Response):
    """Wave particle velocity and acceleration time series at the requested points."""

    velocity: list[list[list[float]]] = _f(
        "Velocity, indexed [point][component x, y, z][sample]", "m/s"
    )
    acceleration: list[list[list[float]]] = _f(
        "Acceleration, indexed [point][component x, y, z][sample]", "m/s²"
    )


class RealizationResponse(_Response):
    """A sea surface elevation time series (and kinematics when points were given)."""

    time: list[float] = _f("Sample times t_n = n·dt", "s")
    elevation: list[float] = _f("Surface elevation η(t_n)", "m")
    stats: RealizationStats
    kinematics: Kinematics | None = None


# -------------------------------------------------------------------- examples


class ExampleSummary(_Response):
    """An example scene shipped with stochcable."""

    name: str = Field(description="Name to use in GET /v1/examples/{name}")
    title: str = Field(description="The scene's title")


# -------------------------------------------------------------------- analyses
#
# The result document is built by the core (stochcable.results.documents.Result.to_document);
# these models only document it (the route serializes the core's dict directly).
# Every part allows extra fields: the v1 contract lets the core add fields, never
# rename them.  Keyed by line name where the structure is dynamic.


class TensionStatistics(_Open):
    """Statistics of an end's effective tension: static mean plus Gaussian dynamic part
    (Tuah 1982, §5.3; stochcable.results.documents.ResponseStats)."""

    mean: float = _f("Static (mean) effective tension", "N")
    std: float = _f("Standard deviation σ = √m0 of the dynamic tension", "N")
    tz: float = _f("Mean zero-upcrossing period 2π√(m0/m2); 0 for a zero process", "s")
    mpm_3h: float = _f(
        "mean + Rayleigh most probable maximum of the dynamic part over "
        "three hours, σ√(2 ln(10800/Tz))",
        "N",
    )
    significant: float | None = _f("Significant value 2σ", "N", default=None)
    m0: float | None = _f("Zeroth spectral moment", "N²", default=None)
    m1: float | None = _f("First spectral moment", "N²·rad/s", default=None)
    m2: float | None = _f("Second spectral moment", "N²·(rad/s)²", default=None)
    m4: float | None = _f("Fourth spectral moment", "N²·(rad/s)⁴", default=None)
    bandwidth: float | None = _f("Spectral bandwidth √(1 − m2²/(m0·m4))", "-", default=None)
    mpm: float | None = _f("mean + most probable maximum over analysis.duration", "N", default=None)
    expected_max: float | None = _f(
        "mean + expected maximum over analysis.duration", "N", default=None
    )


class EndResult(_Open):
    """Dynamic response at one end (support) of a line."""

    tension: TensionStatistics
    force_std: list[float] | None = _f("σ of the x, y, z force on the support", "N", default=None)


class TensionAlongLine(_Open):
    """Effective tension along the line, per element."""

    s: list[float] = _f("Unstretched arc length of the element midpoints from end_a", "m")
    std: list[float] = _f(
        "σ of the dynamic effective tension (with the residuals of the linear model "
        "where std_linear is present)",
        "N",
    )
    mean: list[float] | None = _f("Static effective tension", "N", default=None)
    std_linear: list[float] | None = _f(
        "σ of the dynamic effective tension of the linear model alone; present where the "
        "residuals were computed along the line",
        "N",
        default=None,
    )


class MotionAlongLine(_Open):
    """Node motions along the line."""

    s: list[float] = _f("Unstretched arc length of the nodes from end_a", "m")
    std: list[list[float]] = _f(
        "σ of the x, y, z node displacements, per node (with the residuals of the linear "
        "model where std_linear is present)",
        "m",
    )
    std_linear: list[list[float]] | None = _f(
        "σ of the x, y, z node displacements of the linear model alone; present where the "
        "residuals were computed in the motions",
        "m",
        default=None,
    )


class LineLinearization(_Open):
    """Drag-linearization fixed point of one line (Tuah 1982, §5.3 steps 5–13)."""

    converged: bool = Field(description="Whether every σ changed less than the tolerance")
    iterations: int = _f("Number of response evaluations", "-")
    relative_change: float = _f("Final largest relative change of the σ", "-")
    method: str | None = Field(default=None, description="seed, vector or harmonic")
    tolerance: float | None = _f("Tolerance asked for", "-", default=None)
    history: list[float] | None = _f("Relative change after each iteration", "-", default=None)


class LineModes(_Open):
    """Natural frequencies of one line about its static shape."""

    omega: list[float] = _f("Natural frequencies listed (with added mass)", "rad/s")
    kept: int | None = _f(
        "Modes kept by the Foss solve; null for the direct solve", "-", default=None
    )


class LineDocument(ResidualParts):
    """Frequency-domain response of one line: statistics, distributions, spectra; with
    the residuals of the linear model by default (the end statistics carry them)."""

    end_a: EndResult
    end_b: EndResult
    tension: TensionAlongLine
    motion: MotionAlongLine
    spectra: dict[str, Any] | None = Field(
        default=None,
        description="omega [rad/s] and the one-sided end-tension spectra "
        "{end_a: {tension: [...]}, end_b: ...} [N²·s/rad]",
    )
    channels: list[str] | None = Field(
        default=None, description="Independent input channels (sea, end_b.surge, ...)"
    )
    linearization: LineLinearization | None = None
    modes: LineModes | None = None
    linear: dict[str, EndResult] | None = Field(
        default=None, description="The linear model's end statistics where a residual was "
        "computed {end_a: {tension}, end_b: ...} (end_a and end_b carry the residuals)"
    )  # fmt: skip


class ModesSummary(_Open):
    """Natural frequencies: of the first line, and by line name."""

    omega: list[float] = _f("Natural frequencies of the first line", "rad/s")
    lines: dict[str, list[float]] | None = _f(
        "Natural frequencies by line name", "rad/s", default=None
    )


class LinearizationSummary(_Open):
    """Aggregate drag-linearization record over the lines."""

    converged: bool = Field(description="Whether the linearization converged on every line")
    iterations: int = _f("Largest number of iterations of a line", "-")
    relative_change: float = _f("Largest final relative change", "-")
    lines: dict[str, LineLinearization] | None = None


class StaticsDocument(_Open):
    """Static equilibrium by line name: end tensions and forces [N], touchdown arc
    length [m] (null when the line does not touch the seabed), node positions [m]."""

    lines: dict[str, dict[str, Any]]


class TimeSeriesDocument(_Open):
    """A window (or all) of one realization of the sea and of the responses."""

    method: str = Field(description="dsa or nsa")
    seed: int = Field(description="Root random seed")
    dt: float = _f("Time step", "s")
    samples: int = _f("Length of the whole realization", "-")
    window: int = _f("Samples in this document", "-")
    time: list[float] = _f("Sample times", "s")
    elevation: list[float] | None = _f("Wave elevation at the origin; null without a sea", "m")
    end_motion: dict[str, list[float]] = _f(
        "Prescribed end motions by channel (line.end_b.surge, ...)", "m or rad"
    )
    lines: dict[str, dict[str, dict[str, list[float]]]] = _f(
        "Total end tensions {line: {end_a: {tension: [...]}, end_b: ...}}, with the "
        "residuals' Gaussian component where they were applied; with the query "
        "timeseries_linear, the linear model's beside them (tension_linear)",
        "N",
    )
    bodies: dict[str, dict[str, dict[str, list[float]]]] | None = Field(
        default=None,
        description="Body motions {body: {motion: {surge: [...], ...}}}, "
        "static pose plus dynamic part, for scenes with bodies. [m, rad]",
    )


class AnalysisResponse(_Open):
    """The v1 result document (DESIGN.md "Scene and result documents"), identical to
    ``stochcable analyze SCENE.json`` and to ``analyze(scene).to_document()``."""

    statics: StaticsDocument
    modes: ModesSummary
    linearization: LinearizationSummary
    lines: dict[str, LineDocument] = Field(description="Response by line name")
    timing: dict[str, float] = _f("Wall-clock time per stage (total_s, statics_s, ...)", "s")
    warnings: list[str] = Field(
        description="Physics and resolution warnings of the "
        "analysis (threshold and fix in each message)"
    )
    timeseries: TimeSeriesDocument | None = Field(
        default=None,
        description="Present when the scene has analysis.timeseries and the "
        "timeseries query parameter is not none",
    )
    units: dict[str, str] | None = Field(
        default=None,
        description="Unit labels of the scene's consistent unit system, read "
        "off environment.g (stochcable.scene.units): system (SI, foot-slug-second or "
        "consistent), length, mass, force, time",
    )
    bodies: dict[str, BodyDocument] | None = Field(
        default=None,
        description="Motion of each body (scenes with bodies): per DOF the "
        "statistics and spectra (with the residuals' where computed), plus the coupled "
        "modes (docs/BODIES.md)",
    )
