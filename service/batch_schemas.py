"""Request and status documents of batch jobs (``/v1/batches``).

The request is the same set of documents as the Python API and the CLI take: the scene
(:class:`stochcable.scene.model.Scene`), the scatter diagram in one of the forms of
:func:`stochcable.cases.read_scatter` (a list of rows, ``{"rows": [...]}`` or an
occurrence matrix), the headings of ``stochcable cases --headings``, the fatigue
settings of :class:`stochcable.cases.LineFatigue` (one for every line, or per line) and
the return period.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag

from stochcable.scene.model import Scene

__all__ = [
    "ScatterRow",
    "ScatterTable",
    "ScatterMatrix",
    "LineFatigueDocument",
    "BatchRequest",
    "BatchProgress",
    "CaseProblem",
    "BatchStatus",
    "BatchList",
    "JOB_STATUSES",
]

JOB_STATUSES = ("queued", "running", "done", "failed", "cancelled")
Family = Literal["jonswap", "pierson_moskowitz"]


def _f(description: str, unit: str, **kw: Any) -> Any:
    return Field(description=f"{description} [{unit}]", json_schema_extra={"unit": unit}, **kw)


class _Doc(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False, strict=True)


class ScatterRow(_Doc):
    """One sea state: Hs, Tp or Tz, optional γ, heading, probability or hours."""

    hs: float = _f("Significant wave height", "m", gt=0)
    tp: float | None = _f("Peak period (give tp or tz)", "s", gt=0, default=None)
    tz: float | None = _f("Mean zero up-crossing period (give tp or tz)", "s", gt=0, default=None)
    gamma: float | None = _f(
        "JONSWAP peak enhancement; default from Hs and Tp (DNV-RP-C205)", "-", default=None
    )
    heading: float = _f("Direction the waves travel toward, from +x toward +y", "deg", default=0)
    probability: float | None = _f(
        "Probability of occurrence (give probability or hours)", "-", ge=0, default=None
    )
    hours: float | None = _f("Hours of occurrence (normalized)", "h", ge=0, default=None)


class ScatterTable(_Doc):
    """A scatter diagram as a table of rows."""

    rows: list[ScatterRow] = Field(min_length=1, description="One row per sea state")
    spectrum: Family | None = Field(default=None, description="Spectrum family")
    source: str = Field(default="", max_length=1000, description="Where the diagram comes from")


class ScatterMatrix(_Doc):
    """A scatter diagram as an occurrence matrix (rows Hs, columns Tp or Tz) and a
    heading distribution."""

    hs: list[float] = Field(min_length=1, description="Hs class midpoints [m]")
    tp: list[float] | None = Field(default=None, description="Tp class midpoints [s]")
    tz: list[float] | None = Field(default=None, description="Tz class midpoints [s]")
    occurrence: list[list[float]] = Field(
        min_length=1, description="Counts or probabilities per Hs row and period column [-]"
    )
    headings: dict[str, float] | None = Field(
        default=None, description="Heading [deg] → probability [-]; default all at 0°"
    )
    spectrum: Family | None = Field(default=None, description="Spectrum family")
    source: str = Field(default="", max_length=1000, description="Where the diagram comes from")


def _scatter_form(value: Any) -> str | None:
    if isinstance(value, list):
        return "rows"
    if isinstance(value, dict):
        return "matrix" if "occurrence" in value else "table"
    if isinstance(value, (ScatterTable, ScatterMatrix)):
        return "matrix" if isinstance(value, ScatterMatrix) else "table"
    return None


Scatter = Annotated[
    Annotated[list[ScatterRow], Tag("rows")]
    | Annotated[ScatterTable, Tag("table")]
    | Annotated[ScatterMatrix, Tag("matrix")],
    Discriminator(_scatter_form),
]


class LineFatigueDocument(_Doc):
    """How a line's fatigue is assessed (:class:`stochcable.cases.LineFatigue`)."""

    curve: str = Field(default="dnv-studless", description="Fatigue curve name")
    nominal_diameter: float | None = _f("Nominal chain bar diameter", "m", gt=0, default=None)
    nominal_area: float | None = _f("Nominal area of the stress", "m²", gt=0, default=None)
    mbs: float | None = _f("Minimum breaking strength", "force unit", gt=0, default=None)
    mean_load_ratio: float | None = _f(
        "Mean tension / MBS of the API wire-rope curves", "-", gt=0, default=None
    )
    method: Literal["narrow_band", "wirsching_light", "dirlik", "benasciutti_tovo"] = Field(
        default="dirlik", description="Spectral fatigue method"
    )
    design_factor: float = _f("Design fatigue factor", "-", ge=1, default=1.0)


class BatchRequest(_Doc):
    """A load-case set to run as a batch job."""

    scene: Scene = Field(description="The scene template (its sea is each state's)")
    scatter: Scatter = Field(
        description="The scatter diagram: rows, {rows: [...]} or an occurrence matrix"
    )
    spectrum: Family | None = Field(
        default=None, description="Spectrum family (default: the diagram's, else jonswap)"
    )
    headings: list[float] | None = Field(
        default=None,
        min_length=1,
        max_length=360,
        description="Every sea state repeated for each heading with equal probability "
        "[deg] (the diagram's headings are then ignored)",
    )
    fatigue: LineFatigueDocument | dict[str, LineFatigueDocument] | None = Field(
        default=None, description="One setting for every line, or per line name"
    )
    years: float = _f("Return period of the long-term extremes", "years", gt=0, default=100.0)
    chunk_size: int | None = Field(
        default=None,
        ge=1,
        le=10_000,
        description="Cases per chunk (stored and resumed as a unit); default from the "
        "number of cases and workers [-]",
    )


class BatchProgress(BaseModel):
    """How far a batch is."""

    total: int = Field(description="Cases of the batch [-]")
    done: int = Field(description="Cases finished (any status) [-]")
    not_ok: int = Field(description="Finished cases that are not ok [-]")
    failed: int = Field(description="Finished cases without a response [-]")
    fraction: float = Field(description="done / total [-]")
    rate: float | None = Field(description="Cases per second since (re)started [1/s]")
    eta_seconds: float | None = Field(description="Estimated time to finish [s]")


class CaseProblem(BaseModel):
    """A case that is not ok."""

    index: int = Field(description="Position in the scatter diagram (with headings) [-]")
    status: Literal["flagged", "not_converged", "failed"]
    reason: str


class BatchStatus(BaseModel):
    """A batch job: its state, progress and the cases that are not ok."""

    id: str
    status: Literal["queued", "running", "done", "failed", "cancelled"]
    created: str = Field(description="ISO 8601 time of submission (UTC)")
    started: str | None = Field(description="ISO 8601 time work first started (UTC)")
    finished: str | None = Field(description="ISO 8601 time it finished (UTC)")
    progress: BatchProgress
    problems: list[CaseProblem] = Field(description="Cases not ok, first ones first")
    problems_total: int = Field(description="Number of cases not ok [-]")
    error: str | None = Field(description="Why the batch failed")
    chunk_size: int = Field(description="Cases per chunk [-]")
    results: str = Field(description="Where the results are (when done)")
    warnings: list[str] = Field(
        default_factory=list,
        description="Physics warnings of the set as planned (e.g. a residual of the "
        "scene that load-case sets do not apply; threshold and fix in each message)",
    )


class BatchList(BaseModel):
    """The caller's batches, newest first."""

    batches: list[BatchStatus]
