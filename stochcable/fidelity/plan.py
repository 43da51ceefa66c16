"""The fidelity plan: the settings chosen for a target error, each with its reason and
its error estimate (:func:`stochcable.fidelity.planner.choose_fidelity` makes it,
:func:`stochcable.fidelity.planner.apply_fidelity` applies it)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["Choice", "FidelityPlan"]


@dataclass(frozen=True)
class Choice:
    """One setting of a plan.

    Attributes
    ----------
    setting : str
        Scene path of the setting ("analysis.omega.max", "lines[leg].segments[0].elements").
    value : Any
        The value chosen.
    reason : str
        Rule and numbers that gave it.
    error : float
        Estimated relative error of σ this setting leaves. [-]
    """

    setting: str
    value: Any
    reason: str
    error: float = 0.0

    def to_document(self) -> dict[str, Any]:
        return {
            "setting": self.setting,
            "value": _plain(self.value),
            "reason": self.reason,
            "error": float(self.error),
        }


@dataclass(frozen=True)
class FidelityPlan:
    """Settings chosen for a target error, each with its reason.

    Attributes
    ----------
    target_error : float
        Target relative error of the response σ. [-]
    omega_min, omega_max : float
        Frequency band. [rad/s]
    omega_count : int
        Points of the linear grid (finest spacing needed anywhere). [-]
    omega_values : tuple of float
        Non-uniform grid: base linear grid plus refinements around lightly damped
        modes. [rad/s]
    segments : dict of str to tuple
        Per line, the new segments as (source segment index, length [m], elements).
    solver : str
        "foss" or "direct".
    modes : "auto" or int
        Kept modes (Foss).
    tolerance : float
        Linearization tolerance. [-]
    choices : tuple of Choice
        Every choice with its reason and error estimate.
    error_estimate : dict of str to float
        Estimate per part of the discretization ("band", "grid", "elements", "modes",
        "linearization": the fixed point's tolerance), "discretization" (their sum),
        "linearization_model" (the model's own error against the nonlinear time
        domain, which no fidelity removes; with the residuals computed, what they
        leave of it: :mod:`stochcable.fidelity.model_error`) and
        "total" (discretization + model). [-]
    cost : dict of str to float
        "elements", "frequencies" (of the grid applied) and "elements_x_frequencies".
    omega_response : float
        ω₂ = √(m₂/m₀) of the pilot's response spectra (largest), used by the
        element rule. [rad/s]
    tail_bounded : bool
        False when a response spectrum still decays slower than ω⁻¹·²⁵ at the pilot's
        top: σ then depends on the band and the band estimate is a lower bound.
    pilot : dict
        The pilot analysis: elements, band, count, wall time [s].
    grid_resolved : bool
        False when a limit of the scene model (``analysis.omega.count``) kept the grid
        from resolving some lightly damped modes of the band; their estimated share is
        ``error_estimate["grid_unresolved"]``.
    limits : tuple of str
        Every limit of the scene model the plan hit, with what it leaves unmet (empty
        when the target was met within them).
    model_error_basis : str
        Which line and term give ``error_estimate["linearization_model"]``: the σ
        change of the computed residuals, or the source of its calibration.
    """

    target_error: float
    omega_min: float
    omega_max: float
    omega_count: int
    omega_values: tuple[float, ...]
    segments: dict[str, tuple[tuple[int, float, int], ...]]
    solver: str
    modes: Any
    tolerance: float
    choices: tuple[Choice, ...]
    error_estimate: dict[str, float]
    cost: dict[str, float]
    tail_bounded: bool = True
    omega_response: float = 0.0
    pilot: dict[str, Any] = field(default_factory=dict)
    grid_resolved: bool = True
    limits: tuple[str, ...] = ()
    model_error_basis: str = ""

    def to_document(self) -> dict[str, Any]:
        """Plain JSON-ready form (for the result document's "fidelity")."""
        doc = {
            "target_error": self.target_error,
            "omega": {
                "min": self.omega_min,
                "max": self.omega_max,
                "count": self.omega_count,
                "values_count": len(self.omega_values),
            },
            "segments": {k: [list(s) for s in v] for k, v in self.segments.items()},
            "solver": self.solver,
            "modes": self.modes,
            "tolerance": self.tolerance,
            "choices": [c.to_document() for c in self.choices],
            "error_estimate": dict(self.error_estimate),
            "model_error_basis": self.model_error_basis,
            "cost": dict(self.cost),
            "tail_bounded": self.tail_bounded,
            "omega_response": self.omega_response,
            "pilot": _plain(self.pilot),
        }
        if self.limits:  # only when a limit was hit (documents of met targets unchanged)
            doc["grid_resolved"] = self.grid_resolved
            doc["limits"] = list(self.limits)
        # plain Python numbers throughout (numpy scalars are not JSON for every encoder:
        # the service's answered 500 on the band error's numpy float)
        return _plain(doc)


def _plain(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    return x
