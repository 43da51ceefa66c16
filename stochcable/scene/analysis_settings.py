"""Analysis settings of the scene: frequency grid, solver, modes, drag linearization,
structural damping, adaptive fidelity and time series.

References
----------
Tuah, H. (1982), Cable dynamics in an ocean environment, PhD thesis, Oregon State University.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import ConfigDict, Field, model_validator

from stochcable.scene.base import _Doc, _f
from stochcable.scene.residual_kinds import residual_switch

__all__ = [
    "OmegaGrid",
    "LinearizationSettings",
    "TimeSeriesSettings",
    "StructuralDamping",
    "FidelitySettings",
    "AnalysisSettings",
]


class OmegaGrid(_Doc):
    """Frequency grid of the analysis."""

    min: float = _f("Lowest frequency", "rad/s", gt=0, default=0.05)
    max: float = _f("Highest frequency", "rad/s", gt=0, default=2.0)
    count: int = _f("Number of frequencies", "-", ge=2, le=100_000, default=200)
    spacing: Literal["linear", "log"] = Field(default="linear", description="Grid spacing")

    @model_validator(mode="after")
    def _order(self) -> OmegaGrid:
        if self.max <= self.min:
            raise ValueError(f"max ({self.max} rad/s) must exceed min ({self.min} rad/s)")
        return self

    def values(self) -> np.ndarray:
        """The grid. [rad/s]"""
        if self.spacing == "log":
            return np.geomspace(self.min, self.max, self.count)
        return np.linspace(self.min, self.max, self.count)


class LinearizationSettings(_Doc):
    """Statistical drag linearization and its fixed-point iteration (Tuah (1982), §5.2)."""

    method: Literal["seed", "vector", "harmonic"] = Field(
        default="seed",
        description="seed: scalar sqrt(8/pi) form (eq. 5.2.2); vector: exact normal-plane "
        "Gaussian form; harmonic: 8/(3 pi) regular-wave form",
    )
    tolerance: float = _f(
        "Relative change of every sigma at convergence", "-", gt=0, lt=1, default=1e-4
    )
    max_iterations: int = _f("Iteration limit", "-", ge=1, le=10_000, default=100)
    relaxation: float = _f(
        "Under-relaxation factor of the plain iteration", "-", gt=0, le=1, default=0.5
    )
    acceleration: Literal["anderson", "none"] = Field(
        default="anderson", description="Fixed-point accelerator"
    )
    allow_unconverged: bool = Field(
        default=False,
        description="Return a flagged partial result instead of an error when the "
        "iteration does not converge",
    )
    # the residual kinds' switches (stochcable.scene.residual_kinds: one line a kind)
    drag_residual: bool = residual_switch("drag_residual")
    geometric_residual: bool = residual_switch("geometric_residual")


class TimeSeriesSettings(_Doc):
    """Time series synthesized from the response spectra (Tuah (1982), §5.1)."""

    model_config = ConfigDict(defer_build=False)  # (:class:`_Doc`: an HTTP body extends it)
    method: Literal["dsa", "nsa"] = Field(default="dsa", description="Spectral amplitude model")
    duration: float = _f("Record length", "s", gt=0, le=1.0e7, default=600.0)
    dt: float = _f("Time step", "s", gt=0, default=0.25)
    seed: int = Field(default=1, ge=0, description="Random seed (numpy PCG64)")


class StructuralDamping(_Doc):
    """Rayleigh structural damping C_s = alpha·M + beta·K (added to the drag damping)."""

    alpha: float = _f("Mass-proportional coefficient", "1/s", ge=0, default=0.0)
    beta: float = _f("Stiffness-proportional coefficient", "s", ge=0, default=0.0)


class FidelitySettings(_Doc):
    """Adaptive fidelity: the engine chooses elements, frequencies, modes and tolerance."""

    target_error: float = _f(
        "Target relative error of the response standard deviations",
        "-",
        gt=0,
        le=0.5,
        default=0.01,
    )


class AnalysisSettings(_Doc):
    """How to solve: frequencies, solver, modes, linearization, time series."""

    omega: OmegaGrid = Field(default_factory=OmegaGrid)
    solver: Literal["foss", "direct"] = Field(
        default="foss", description="Modal Foss or direct solve"
    )
    modes: Literal["auto"] | Annotated[int, Field(ge=1)] = Field(
        default="auto", description="Number of modes kept, or auto from the frequency content"
    )
    linearization: LinearizationSettings = Field(default_factory=LinearizationSettings)
    structural_damping: StructuralDamping = Field(default_factory=StructuralDamping)
    fidelity: FidelitySettings | None = Field(
        default=None,
        description="When set, the engine chooses elements, frequency grid, modes and "
        "tolerance itself for this target error (the other settings are replaced); the "
        "choices and their error estimates are reported under 'fidelity'",
    )
    timeseries: TimeSeriesSettings | None = None
    duration: float = _f("Storm duration for extreme-value statistics", "s", gt=0, default=10800.0)
