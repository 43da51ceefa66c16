"""Response models of a body's part of the result document (``bodies.<body>``):
documentation only, as the other parts of the result document (:mod:`service.schemas`;
docs/BODIES.md)."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field

__all__ = ["BodyCorrectedSpectrum", "BodyDocument"]


def _f(description: str, unit: str, **kw: Any) -> Any:
    """Field whose description ends with the unit in brackets (as service.schemas')."""
    return Field(description=f"{description} [{unit}]", json_schema_extra={"unit": unit}, **kw)


class _Open(BaseModel):
    # parts of the result document: more fields may be added (DESIGN.md v1 contract)
    model_config = ConfigDict(frozen=True, extra="allow")


class BodyCorrectedSpectrum(_Open):
    """A body DOF's spectral density with the residuals' spectra."""

    omega: list[float] = _f("The analysis grid and the residual lines outside it", "rad/s")
    motion: list[float] = _f(
        "One-sided density; its area is the DOF's σ²",
        "m²·s/rad or rad²·s/rad",
    )


class BodyDocument(_Open):
    """Motion of one body: per DOF the statistics, the spectra, the coupled modes; a
    free body's motion carries its lines' residuals of the linear model by default."""

    prescribed: bool = Field(description="True for a vessel whose motion is its RAO")
    dofs: list[str] = Field(description="DOF names in order (surge, sway, heave, ...)")
    motion: dict[str, dict[str, Any]] = Field(
        description="Statistics per DOF (mean = static pose; rotations in rad with std_deg); "
        "std_linear, the linear model's σ, where the motion carries the residuals"
    )
    spectra: dict[str, list[float]] = Field(
        description="omega [rad/s] and the linear model's one-sided spectrum of each DOF "
        "[m²·s/rad or rad²·s/rad]"
    )
    corrected_spectra: dict[str, BodyCorrectedSpectrum] | None = Field(
        default=None,
        description="Where the motion carries the residuals: each DOF's spectral density "
        "with them {surge: {omega, motion}, ...}, which its statistics are of",
    )
    channels: list[str] = Field(description="Input channels of the body's coupled group")
    drag: dict[str, Any] | None = Field(
        default=None,
        description="Linearized drag at the drag point: sigma [m/s], coefficient [N·s/m]",
    )
    modes: dict[str, Any] | None = Field(
        default=None, description="Natural modes of the coupled group (null for a vessel)"
    )
