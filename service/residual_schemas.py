"""Response models of the residuals of the linear model in a line's result document
(``lines.<line>.<kind>``, ``lines.<line>.corrected_spectra``): documentation only, as
the other parts of the result document (:mod:`service.schemas`).

One field per registered residual kind (:data:`stochcable.scene.residual_kinds.RESIDUAL_KINDS`),
so a new kind is documented here without an edit.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field, create_model

from stochcable.scene.residual_kinds import RESIDUAL_KINDS

__all__ = ["ResidualEnd", "ResidualDocument", "CorrectedSpectrum", "ResidualParts"]


def _f(description: str, unit: str, **kw: Any) -> Any:
    """Field whose description ends with the unit in brackets (as service.schemas')."""
    return Field(description=f"{description} [{unit}]", json_schema_extra={"unit": unit}, **kw)


class _Open(BaseModel):
    # parts of the result document: more fields may be added (DESIGN.md v1 contract)
    model_config = ConfigDict(frozen=True, extra="allow")


class ResidualEnd(_Open):
    """What one residual adds to the tension at one end."""

    variance: float = _f("End-tension variance the residual adds (negative: lowers it)", "N²")
    in_band: float = _f("Its part on the analysis band", "N²")
    std_linear: float = _f("σ of the linear model", "N")
    std: float = _f("σ with this residual alone", "N")
    ratio: float = _f("std / std_linear", "-")


class ResidualDocument(_Open):
    """One closed-form residual of the linear model on one line
    (stochcable.results.records.ResidualRecord)."""

    computed: bool = Field(description="False where the line is outside its scope")
    reason: str = Field(description="Why not computed (empty when computed)")
    order: int = _f("Highest order kept (Hermite order of the drag; 2 geometric)", "-")
    panels: int = _f("Element groups it was evaluated on", "-")
    end_a: ResidualEnd
    end_b: ResidualEnd


class CorrectedSpectrum(_Open):
    """An end tension's spectral density with the residuals' spectra."""

    omega: list[float] = _f("The analysis grid and the residual lines outside it", "rad/s")
    tension: list[float] = _f("One-sided density; its area is the end's σ²", "N²·s/rad")


_KINDS: dict[str, Any] = {
    name: (
        ResidualDocument | None,
        Field(
            default=None,
            description=f"The residual {name} (analysis.linearization.{name}, default true; "
            "absent when false)",
        ),
    )
    for name in RESIDUAL_KINDS
}

ResidualParts = create_model(
    "ResidualParts",
    __base__=_Open,
    __doc__="The residuals' parts of a line's result document.",
    corrected_spectra=(
        dict[str, CorrectedSpectrum] | None,
        Field(
            default=None,
            description="Where a residual was computed: the end tensions' spectral "
            "densities with the residuals {end_a: {omega, tension}, end_b: ...}, which the "
            "end statistics, spectral fatigue and load-case sets are of",
        ),
    ),
    **_KINDS,
)
